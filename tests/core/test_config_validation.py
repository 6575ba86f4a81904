"""Settings that were accepted silently (and wrong) or failed with raw TypeError / numpy /
MuJoCo errors: each is now a ConfigError (a ValueError) naming its owner, the setting, the
value and what is allowed, or is accepted and stored as a canonical Python value."""

import numpy as np
import pytest

from mimo_social.core.config import AgentConfig, ConfigError, PhysicsConfig
from mimo_social.envs import catch_v0, free_play_v0, reach_v0, social_touch_v0
from mimo_social.envs.catalog import entry
from mimo_social.partners import HandOffer
from mimo_social.partners.expression import ExpressionShow
from mimo_social.partners.gaze import GazeAtTarget


@pytest.mark.parametrize("make, pattern", [
    # silently accepted before: wrong behaviour or a crash much later
    (lambda: free_play_v0.parallel_env(task_options={"props": "no"}),
     r"free_play: task option props='no' not allowed; allowed: True or False"),
    (lambda: reach_v0.parallel_env(task_options={"success_reward": "abc"}),
     r"reach: task option success_reward='abc'.*any finite number"),
    (lambda: free_play_v0.parallel_env(physics={"gravity": (0, 0, float("nan"))}),
     r"physics: gravity=\(0, 0, nan\) not allowed.*m/s\^2"),
    (lambda: free_play_v0.parallel_env(physics={"tolerance": -1e-8}),
     r"physics: tolerance=-1e-08 not allowed; allowed: a number from 0 to 0.001"),
    (lambda: free_play_v0.parallel_env(n_agents=True), r"n_agents=True"),
    (lambda: free_play_v0.parallel_env(touch={"normal_only": "false"}),
     r"infant_0: touch: normal_only='false'.*True or False"),
    (lambda: free_play_v0.parallel_env(vision={"depth": "yes"}),
     r"infant_0: vision: depth='yes'.*True or False"),
    (lambda: free_play_v0.parallel_env(touch={"exclude": "head"}),
     r"infant_0: touch: exclude='head'.*list of distinct body part names"),
    (lambda: free_play_v0.parallel_env(max_steps=1.5), r"max_steps=1.5.*an integer"),
    # raw TypeError / numpy / MuJoCo errors before
    (lambda: free_play_v0.parallel_env(position="ab"), r"infant_0: position='ab'.*\(x, y\)"),
    (lambda: free_play_v0.parallel_env(per_agent=[{}, {"facing": [None, 1]}]),
     r"infant_1: facing=\[None, 1\].*point \(x, y\)"),
    (lambda: free_play_v0.parallel_env(clothes_rgba="red"),
     r"clothes_rgba='red'.*\(red, green, blue, alpha\), each from 0 to 1"),
    (lambda: free_play_v0.parallel_env(clothes_rgba=(1, 2)), r"clothes_rgba=\(1, 2\)"),
    (lambda: free_play_v0.parallel_env(render_size=5), r"render_size=5.*\(height, width\)"),
    (lambda: free_play_v0.parallel_env(max_steps="10"), r"max_steps='10'"),
    (lambda: free_play_v0.parallel_env(physics={"timestep": "0.005"}),
     r"physics: timestep='0.005'.*0.0001 to 0.006"),
    (lambda: free_play_v0.parallel_env(physics={"iterations": 1.5}),
     r"physics: iterations=1.5.*an integer from 10 to 1000"),
    (lambda: free_play_v0.parallel_env(touch={"density": "1"}), r"touch: density='1'"),
    (lambda: free_play_v0.parallel_env(proprioception={"limit_margin_deg": "5"}),
     r"proprioception: limit_margin_deg='5'"),
    (lambda: free_play_v0.parallel_env(proprioception={"components": 5}),
     r"proprioception: components=5.*non-empty list"),
    (lambda: free_play_v0.parallel_env(per_agent=5), r"per_agent must be a list of 2"),
    (lambda: catch_v0.parallel_env(task_options={"mass": (0.5, 0.1)}),
     r"catch: task option mass=\(0.5, 0.1\).*low <= high"),
    (lambda: catch_v0.parallel_env(task_options={"mass": ("0.1", 0.2)}), r"catch.*mass="),
    (lambda: entry("mirror").scripted_env(task_options=5), r"mirror: task_options=5"),
])
def test_bad_settings_are_config_errors(make, pattern):
    with pytest.raises(ConfigError, match=pattern):
        make()


def test_accepted_settings_are_stored_canonical():
    env = free_play_v0.parallel_env(
        n_agents=np.int64(2), max_steps=np.int32(7), render_size=[np.int64(48), 64],
        clothes_rgba=[1, 0.5, np.float32(0.25), 1], expressions=np.bool_(True),
        physics={"frame_skip": np.int64(3), "gravity": np.array([0.0, 0.0, -9.81])},
        per_agent=[{"position": np.array([-0.5, 0.0]), "facing": (0, 0)},
                   {"position": (0.5, 0), "vision": {"width": np.int64(32), "height": 32}}])
    assert (env.max_steps, env.render_size) == (7, (48, 64))
    assert type(env.max_steps) is int and all(type(v) is int for v in env.render_size)
    cfg0, cfg1 = env.agent_configs
    assert cfg0.clothes_rgba == (1.0, 0.5, 0.25, 1.0) and cfg0.expressions is True
    assert cfg0.position == (-0.5, 0.0) and type(cfg0.position[0]) is float
    assert cfg1.vision.width == 32 and type(cfg1.vision.width) is int
    assert env.physics.frame_skip == 3 and type(env.physics.frame_skip) is int
    assert env.physics.gravity == (0.0, 0.0, -9.81)
    env.reset(seed=0)


def test_sense_switches_given_to_agent_config_directly_are_parsed():
    cfg = AgentConfig(touch=True, vision={"width": 16, "height": 16}, vestibular=False)
    assert cfg.touch is not None and cfg.vision.width == 16 and cfg.vestibular is None
    with pytest.raises(ConfigError, match=r"touch='yes'"):
        AgentConfig(touch="yes")
    with pytest.raises(ConfigError, match=r"physics: gravity=\(0, 0\)"):
        PhysicsConfig(gravity=(0, 0))


def test_overlapping_agents_name_both():
    with pytest.raises(ConfigError, match=r"agents infant_0 .* and infant_1 .* overlap: placed "
                                          r"at \(0, 0\) and \(0.01, 0\) m.*cm.*position"):
        free_play_v0.parallel_env(per_agent=[{"position": (0, 0)}, {"position": (0.01, 0)}])
    with pytest.raises(ConfigError, match=r"infant_1 .* and infant_2 .* overlap"):
        free_play_v0.parallel_env(n_agents=3, per_agent=[{"position": (-1, 0)},
                                                         {"position": (1, 0)},
                                                         {"position": (1.05, 0.02)}])
    # a bigger body that the task places is fine (the task's circle grows with scale)
    free_play_v0.parallel_env(n_agents=4, scale=2.2)


def _lying_pair(y):
    return free_play_v0.parallel_env(
        posture="lying", per_agent=[{"position": (0.0, -y), "facing": (1.0, -y)},
                                    {"position": (0.0, y), "facing": (-1.0, y)}])


def test_any_part_inside_another_agents_part_is_refused():
    """Not only trunks: any part of one agent more than 1 cm inside any part of another (a
    forearm in the other's thigh, toes in toes) is refused when the env is made, naming both
    agents, both parts and the depth; a touch within 1 cm is fine."""
    with pytest.raises(ConfigError, match=r"agents infant_0 \(body='infant', posture='lying'"
                                          r".* and infant_1 .* overlap: placed at \(0, -0.09\) "
                                          r"and \(0, 0.09\) m, the left_lower_arm of infant_0 is "
                                          r"4.9 cm inside the left_upper_leg of infant_1 at the "
                                          r"start \(allowed: at most 1 cm"):
        _lying_pair(0.09)
    _lying_pair(0.14)            # side by side, the fingertips within 1 cm: allowed
    # two held bodies (hips fixed, every joint held: MuJoCo makes no contact between them, so
    # a check of contacts alone misses them): the toes of two standing infants 0.22 m apart
    with pytest.raises(ConfigError, match=r"the left_toes of infant_0 is 1.9 cm inside the "
                                          r"right_toes of infant_1 at the start"):
        entry("mirror").parallel_env(vision=False, per_agent=[{"position": (-0.11, 0.0)},
                                                              {"position": (0.11, 0.0)}])


def test_agents_a_task_places_inside_each_other_at_reset_are_refused():
    """The check runs again after every reset (the task may place agents there): a task that
    moves infant_1 onto infant_0 at reset gets a ConfigError naming both, 'after reset'."""
    from mimo_social.core.env import MimoParallelEnv
    from mimo_social.tasks.free_play import FreePlay

    class Onto(FreePlay):
        def reset(self, env, rng):
            w = env.world
            m, d = w.model, w.data
            roots = [int(m.jnt_qposadr[m.body_jntadr[a.root_body]]) for a in w.agents]
            d.qpos[roots[1]:roots[1] + 2] = d.qpos[roots[0]:roots[0] + 2] + (0.05, 0.0)

    env = MimoParallelEnv(Onto(2))
    with pytest.raises(ConfigError, match=r"agents infant_0 .* and infant_1 .* overlap: .* cm "
                                          r"inside the .* after reset"):
        env.reset(seed=0)


def test_facing_its_own_position_is_an_error():
    with pytest.raises(ConfigError, match=r"infant_0: facing=\(0.5, 0\) is its own position"):
        free_play_v0.parallel_env(n_agents=1, position=(0.5, 0), facing=(0.5, 0))


@pytest.mark.parametrize("seed", [-1, 1.5, "0", True, np.float64(3.0), [1, 2]])
def test_bad_seeds_name_seed(seed):
    e = entry("social_touch")
    for env in (e.parallel_env(), e.scripted_env(), entry("reach").gym_env()):
        with pytest.raises(ConfigError, match=r"reset: seed=.* not allowed; allowed: None or an "
                                              r"integer >= 0"):
            env.reset(seed=seed)


def test_numpy_integer_seeds_work_like_ints():
    env = social_touch_v0.scripted_env()
    a, _ = env.reset(seed=np.int64(5))
    b, _ = env.reset(seed=5)
    for k in a:
        for key in a[k]:
            np.testing.assert_array_equal(a[k][key], b[k][key])
    gym_env = entry("reach").gym_env()
    o1, _ = gym_env.reset(seed=np.uint32(3))
    o2, _ = gym_env.reset(seed=3)
    for key in o1:
        np.testing.assert_array_equal(o1[key], o2[key])


@pytest.mark.parametrize("make, pattern", [
    (lambda: HandOffer(release=np.zeros(2)), r"HandOffer: release=array"),
    (lambda: HandOffer(palm_tilt=object()), r"HandOffer: palm_tilt="),
    (lambda: HandOffer(hold_parts=2.0), r"HandOffer: hold_parts=2.0.*integer"),
    (lambda: ExpressionShow(hold_s=("1", "2")), r"ExpressionShow: hold_s=\('1', '2'\)"),
    (lambda: ExpressionShow(expressions=[10**30, 1]), r"expressions=.*unknown expression"),
    (lambda: GazeAtTarget(head_share="0.5"), r"GazeAtTarget: head_share='0.5'"),
    (lambda: GazeAtTarget(omega=np.nan), r"GazeAtTarget: omega=nan"),
])
def test_partner_settings_name_the_argument(make, pattern):
    with pytest.raises(ConfigError, match=pattern):
        make()
