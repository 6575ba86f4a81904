"""What clients read from the env itself: observation bounds (SuperSuit's normalize_obs needs
finite ones, Gymnasium's checker and PettingZoo's tests compare observations with them),
render() as RLlib and PettingZoo call it, ``max_cycles``, and FlattenParallel's answers to bad
actions (finite values beyond float32 clipped; non-numbers named by agent and field)."""

import mujoco
import numpy as np
import pytest

from client_envs import SHORT, bang_bang, entries, parallel
from mimo_social.core.wrappers import FlattenParallel
from mimo_social.envs import catch_v0, high_five_v0, mirror_v0, reach_v0
from mimo_social.senses.proprioception import JOINT_OVERSHOOT
from mimo_social.util.checks import ConfigError


# -- observation bounds ---------------------------------------------------------------------------
@pytest.mark.parametrize("entry", entries())
def test_observations_stay_within_their_declared_bounds_under_bang_bang_actions(entry):
    env = parallel(entry, max_steps=40)
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(0)
    while True:
        for a, o in obs.items():
            space = env.observation_space(a)
            for key, sub in space.spaces.items():
                assert sub.contains(o[key]), (a, key, o[key].min(), o[key].max())
        if not env.agents:
            break
        obs = env.step(bang_bang(env, rng))[0]


def test_bounded_proprioception_parts_give_a_finite_box():
    """Joint angles, limit sensors and the spring-damper state have finite bounds (were all
    (-inf, inf)); velocities and torques stay unbounded."""
    env = reach_v0.parallel_env(proprioception={"components": ["qpos", "limits", "actuation"]})
    box = env.observation_space("infant_0")["proprioception"]
    assert np.all(np.isfinite(box.low)) and np.all(np.isfinite(box.high))
    sense = next(s for s in env.senses[0] if s.name == "proprioception")
    agent = env.world.agents[0]
    q = sense.slices["qpos"]
    np.testing.assert_allclose(box.low[q], agent.joint_range[:, 0] - JOINT_OVERSHOOT, rtol=1e-6)
    np.testing.assert_allclose(box.high[q], agent.joint_range[:, 1] + JOINT_OVERSHOOT, rtol=1e-6)
    act = sense.slices["actuation"]                      # spring-damper: [u, torque]
    motors = env.actuation[0]
    k = len(motors.joints)
    assert np.all(box.low[act][:k] == -1.0) and np.all(box.high[act][:k] == 1.0)
    np.testing.assert_allclose(box.high[act][k:], motors.torque_pos, rtol=1e-6)
    n = len(agent.joint_names)
    full = reach_v0.parallel_env().observation_space("infant_0")["proprioception"]
    qvel = slice(n, 2 * n)                               # the documented order: qpos, qvel ...
    assert np.all(np.isinf(full.low[qvel])) and np.all(np.isinf(full.high[qvel]))


def test_a_joint_far_past_its_range_reads_at_the_widened_bound():
    env = reach_v0.parallel_env(proprioception={"components": ["qpos", "limits"]})
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    agent = env.world.agents[0]
    sense = next(s for s in env.senses[0] if s.name == "proprioception")
    d.qpos[agent.qpos_adr[0]] = agent.joint_range[0, 1] + 3.0        # a diverged joint
    d.qpos[agent.qpos_adr[1]] = agent.joint_range[1, 0] - 3.0
    mujoco.mj_forward(m, d)
    out = {}
    sense.observe(m, d, out)
    p = out["proprioception"]
    assert p[0] == np.float32(agent.joint_range[0, 1] + JOINT_OVERSHOOT)
    assert p[1] == np.float32(agent.joint_range[1, 0] - JOINT_OVERSHOOT)
    assert env.observation_space("infant_0")["proprioception"].contains(p)


def test_normal_touch_forces_are_bounded_below_by_zero():
    env = catch_v0.parallel_env(max_steps=SHORT)                 # its skin: normal forces only
    box = env.observation_space("infant_0")["touch"]
    assert np.all(box.low == 0.0) and np.all(np.isinf(box.high))
    vectors = high_five_v0.parallel_env(touch=high_five_v0.hand_touch(normal_only=False))
    assert np.all(np.isinf(vectors.observation_space("infant_0")["touch"].low))


# -- render ---------------------------------------------------------------------------------------
def test_render_takes_the_mode_rllib_passes():
    env = reach_v0.parallel_env(render_mode="rgb_array", render_size=(24, 32))
    env.reset(seed=0)
    for mode in (None, "rgb_array"):
        assert env.render(mode).shape == (24, 32, 3)
    assert FlattenParallel(env).render("rgb_array").shape == (24, 32, 3)
    plain = reach_v0.parallel_env(render_size=(24, 32))
    plain.reset(seed=0)
    assert plain.render() is None and plain.render(None) is None
    assert plain.render("rgb_array").shape == (24, 32, 3)    # asked for: drawn anyway
    with pytest.raises(ValueError, match="render\\(mode='ansi'\\).*allowed"):
        plain.render("ansi")


def test_render_mode_human_is_accepted_and_says_it_has_no_window():
    env = reach_v0.parallel_env(render_mode="human")
    env.reset(seed=0)
    with pytest.raises(RuntimeError, match="rgb_array"):
        env.render()
    with pytest.raises(ConfigError, match="render_mode"):
        reach_v0.parallel_env(render_mode="window")


def test_max_cycles_is_max_steps():
    assert mirror_v0.parallel_env(max_cycles=5).max_steps == 5
    assert mirror_v0.parallel_env(max_cycles=5, max_steps=5).max_steps == 5
    with pytest.raises(ConfigError, match="max_cycles=5 and max_steps=6"):
        mirror_v0.parallel_env(max_cycles=5, max_steps=6)


# -- FlattenParallel's bad input --------------------------------------------------------------------
def _flat(**kwargs):
    env = FlattenParallel(high_five_v0.parallel_env(max_steps=SHORT, **kwargs))
    env.reset(seed=0)
    return env


def test_finite_float64_beyond_float32_is_clipped_not_made_inf():
    env = _flat(expressions=False)
    n = env.action_space("infant_0").shape[0]
    big = np.full(n, 1e39)
    big[1] = -1e300
    env.step({"infant_0": big, "infant_1": np.zeros(n)})
    u = env.unwrapped.controls[0]
    assert u[0] == 1.0 and u[1] == -1.0 and np.all(np.isfinite(u))
    with_faces = _flat()
    m = with_faces.action_space("infant_0").shape[0]
    act = np.zeros(m)
    act[:n] = 1e39
    act[-1] = 1e300                                        # the last logit wins, beyond float32
    with_faces.step({"infant_0": act, "infant_1": np.zeros(m)})
    assert with_faces.unwrapped.controls[0][0] == 1.0
    assert with_faces.unwrapped._expression[0] == 6


@pytest.mark.parametrize("bad", ["abc", "0.5", [[1.0, 2.0], [3.0]], {"motors": [0.0]}, None,
                                 [True] * 8])
def test_non_numbers_name_the_agent_and_the_field(bad):
    env = _flat(expressions=False)
    n = env.action_space("infant_1").shape[0]
    with pytest.raises(ValueError, match="infant_1: action field 'action'.*allowed"):
        env.step({"infant_0": np.zeros(n), "infant_1": bad})


def test_flat_actions_take_what_the_env_takes_and_refuse_the_rest_naming_the_field():
    """FlattenParallel reads actions as the env does (one reader of numbers): masked entries,
    tensors that need a gradient and a wrong shape are refused naming the agent and the field;
    Python ints beyond 64 bits and long doubles beyond float64 are numbers, clipped."""
    import torch
    env = _flat(expressions=False)
    n = env.action_space("infant_1").shape[0]
    masked = np.ma.masked_array(np.zeros(n), mask=[True] + [False] * (n - 1))
    for bad, why in ((masked, "masked entries"), (torch.zeros(n, requires_grad=True), "grad"),
                     (np.zeros(n + 1), "shape")):
        with pytest.raises(ValueError, match=f"(?s)infant_1: action field 'action'.*{why}"):
            env.step({"infant_0": np.zeros(n), "infant_1": bad})
    huge = [2 ** 70] + [-(2 ** 70)] + [0] * (n - 2)
    env.step({"infant_0": np.zeros(n), "infant_1": huge})
    assert list(env.unwrapped.controls[1][:2]) == [1.0, -1.0]


def test_expression_only_agents_and_logits_name_the_field():
    env = FlattenParallel(mirror_v0.parallel_env(max_steps=SHORT, vision=False))
    env.reset(seed=0)
    follower = [a for a in env.possible_agents if env.action_space(a).shape == ()][0]
    other = [a for a in env.possible_agents if a != follower][0]
    other_act = np.zeros(env.action_space(other).shape)
    if env.action_space(other).shape == ():
        other_act = 0
    for bad in ("3", 2.5, np.nan, [1, 2]):
        with pytest.raises(ValueError, match=f"{follower}: action field 'expression'"):
            env.step({follower: bad, other: other_act})
    env.step({follower: np.int64(3), other: other_act})
    logits = _flat()
    m = logits.action_space("infant_0").shape[0]
    act = np.zeros(m)
    act[-2] = np.nan
    with pytest.raises(ValueError, match="infant_0: action field 'expression logits'"):
        logits.step({"infant_0": act, "infant_1": np.zeros(m)})


def test_the_gymnasium_flat_action_names_the_agent_and_clips():
    import gymnasium as gym

    import mimo_social  # noqa: F401  (registers the Gymnasium ids)
    from mimo_social.core.wrappers import FlatActionWrapper
    env = FlatActionWrapper(gym.make("mimo_social/FreePlay-v0", max_steps=SHORT))
    env.reset(seed=0)
    with pytest.raises(ValueError, match="infant_0: action field 'action' = 'abc'"):
        env.step("abc")
    env.step(np.full(env.action_space.shape, 1e39))
    assert np.all(env.unwrapped.parallel.controls[0] == 1.0)
