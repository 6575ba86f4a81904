"""Sensorimotor delays (``AgentConfig.delays``): a sense delayed by k control steps observes at
step t exactly what the undelayed sense read at t - k (the reset reading before that), with the
physics untouched; a motor delay of k steps applies the controls given k steps before, for every
actuation model; "developmental" follows the published table by age; None is today's env; a
pickled copy continues identically; bad values are named."""

from __future__ import annotations

import pickle

import mujoco
import numpy as np
import pytest

from mimo_social.body.actuation import MODELS as ACTUATION_MODELS
from mimo_social.core.config import AgentConfig, ConfigError
from mimo_social.core.delays import delay_steps
from mimo_social.envs import free_play_v0
from mimo_social.senses.delays import CHANNELS, delay_table, developmental_delays

T = 40          # control steps per run
K = 3           # delay in steps (30 ms at the default 10 ms control step)


def _env(delays=None, **kw):
    kw = {"n_agents": 1, "touch": True, "expressions": False, "max_steps": 10_000, **kw}
    return free_play_v0.parallel_env(delays=delays, **kw)


def _actions(env, n, seed=1):
    sp = env.action_space("infant_0")
    rng = np.random.default_rng(seed)
    return [rng.uniform(sp.low, sp.high) for _ in range(n)]


def _run(env, actions):
    """Observations (agent 0) and qpos after reset and after each step."""
    obs, _ = env.reset(seed=0)
    out, qpos = [obs["infant_0"]], [env.world.data.qpos.copy()]
    for a in actions:
        obs, *_ = env.step({"infant_0": a})
        out.append(obs["infant_0"])
        qpos.append(env.world.data.qpos.copy())
    return out, qpos


@pytest.fixture(scope="module")
def undelayed():
    env = _env()
    actions = _actions(env, T)
    obs, qpos = _run(env, actions)
    return actions, obs, qpos


@pytest.mark.parametrize("channel", ["proprioception", "vestibular", "touch"])
def test_a_delayed_sense_reads_k_steps_back_exactly(undelayed, channel):
    actions, base, base_q = undelayed
    env = _env({channel: K * 10.0})
    assert env.delay_steps("infant_0") == {c: K if c == channel else 0 for c in CHANNELS}
    obs, qpos = _run(env, actions)
    for t in range(T + 1):
        assert np.array_equal(qpos[t], base_q[t]), f"physics changed at step {t}"
        assert np.array_equal(obs[t][channel], base[max(t - K, 0)][channel]), \
            f"{channel} at step {t} is not the undelayed reading of step {max(t - K, 0)}"
        for other in base[t]:
            if other != channel:
                assert np.array_equal(obs[t][other], base[t][other]), f"{other} changed"


def test_the_reset_reading_is_repeated_as_copies(undelayed):
    _, base, _ = undelayed
    env = _env({"proprioception": K * 10.0})
    obs, _ = _run(env, _actions(env, K + 1))
    firsts = [o["proprioception"] for o in obs[:K + 1]]
    assert all(np.array_equal(f, base[0]["proprioception"]) for f in firsts)
    assert len({id(f) for f in firsts}) == K + 1, "an array was handed out twice"
    obs[0]["proprioception"][:] = 99.0          # the caller's array is its own
    assert not np.array_equal(obs[1]["proprioception"], obs[0]["proprioception"])


def test_vision_is_delayed_exactly():
    vision = {"width": 16, "height": 16}
    base_env, env = _env(vision=vision), _env({"vision": 20.0}, vision=vision)
    actions = _actions(env, 8)
    (base, _), (obs, _) = _run(base_env, actions), _run(env, actions)
    assert env.delay_steps("infant_0")["vision"] == 2
    for t in range(len(obs)):
        for eye in ("eye_left", "eye_right"):
            assert np.array_equal(obs[t][eye], base[max(t - 2, 0)][eye])
    for e in (base_env, env):
        e.close()


@pytest.mark.parametrize("actuation", ["spring_damper", "muscle", "positional"])
def test_a_motor_delay_applies_the_controls_of_k_steps_before(actuation):
    if actuation not in ACTUATION_MODELS:
        pytest.skip(f"no {actuation} actuation model here")
    delayed = _env({"motor": K * 10.0}, touch=False, actuation=actuation)
    shifted = _env(touch=False, actuation=actuation)
    actions = _actions(delayed, T)
    obs, qpos = [], []
    for env, acts in ((delayed, actions), (shifted, [np.zeros_like(actions[0])] * K + actions[:-K])):
        o, q = _run(env, acts)
        obs.append(o)
        qpos.append(q)
        if env is delayed:   # the controls applied at the last step: those given K steps before
            given = np.clip(actions[-1 - K], env.actuation[0].control_low,
                            env.actuation[0].control_high)
            assert np.array_equal(env.controls[0], given)
    for t in range(T + 1):
        assert np.array_equal(qpos[0][t], qpos[1][t]), f"trajectories differ at step {t}"
        for key in obs[0][t]:    # proprioception's actuation part: the applied controls too
            assert np.array_equal(obs[0][t][key], obs[1][t][key]), f"{key} differs at step {t}"


def test_developmental_delays_follow_the_table_and_shorten_with_age():
    table = delay_table()
    for channel, t in table.items():
        for age, ms in zip(t["ages"], t["ms"]):
            assert developmental_delays(age)[channel] == pytest.approx(ms)
        assert developmental_delays(None)[channel] == t["adult"]
        by_age = [developmental_delays(a)[channel] for a in (0, 1, 3, 6, 12, 24)]
        assert all(a >= b for a, b in zip(by_age, by_age[1:])), f"{channel} grows with age"
    newborn, six, adult = (developmental_delays(a) for a in (0, 6, None))
    assert newborn["vision"] > 2 * six["vision"] and newborn["touch"] > six["touch"]
    assert six["vision"] == adult["vision"] and six["touch"] == adult["touch"]
    # in control steps of 10 ms: the newborn's eyes lag 26 steps, the 18-month-old's 10
    steps = delay_steps(AgentConfig(age_months=0, delays="developmental"), 0.01)
    assert steps == {"proprioception": 4, "vestibular": 1, "touch": 4, "vision": 26,
                     "audition": 30, "faces": 29, "motor": 2}
    adult = delay_steps(AgentConfig(body="adult", delays="developmental"), 0.01)
    toddler = delay_steps(AgentConfig(delays="developmental"), 0.01)
    # 18 months = adult rows, but for hearing: the auditory P1 matures into the teens
    assert (adult.pop("audition"), toddler.pop("audition")) == (5, 25)
    # and for faces: the infant N290 (290 ms) against the adult N170 (170 ms)
    assert (adult.pop("faces"), toddler.pop("faces")) == (17, 29)
    assert adult == toddler
    env = _env("developmental", touch=False)                            # the published infant
    assert env.delay_steps("infant_0") == {"proprioception": 2, "vestibular": 1, "touch": 2,
                                           "vision": 10, "audition": 25, "faces": 29,
                                           "motor": 2}


def test_milliseconds_round_to_whole_steps():
    def k(ms, dt=0.01):
        return delay_steps(AgentConfig(delays={"touch": ms}), dt)["touch"]
    assert (k(0), k(4.9), k(5), k(14.9), k(15), k(100), k(1000)) == (0, 0, 1, 1, 2, 10, 100)
    assert k(100, dt=0.004) == 25
    env = _env({"touch": 4.0})          # below half a step: undelayed, no buffer
    assert env.delay_steps("infant_0")["touch"] == 0


def test_no_delays_is_todays_env(undelayed):
    _, base, base_q = undelayed
    env = _env(None)
    assert env.world.model.nhistory == 0 and not env.world.model.sensor_delay.any()
    assert not any(r for rings in env._sense_delays for r in rings)
    obs, qpos = _run(env, undelayed[0])
    zero = _env(dict.fromkeys(CHANNELS, 0.0))
    obs0, _ = _run(zero, undelayed[0])
    for t in range(T + 1):
        assert np.array_equal(qpos[t], base_q[t])
        for key in base[t]:
            assert np.array_equal(obs[t][key], base[t][key])
            assert np.array_equal(obs0[t][key], base[t][key])


def test_a_pickled_env_with_delays_continues_identically():
    delays = {"proprioception": 30.0, "vestibular": 50.0, "touch": 20.0, "motor": 40.0}
    env = free_play_v0.parallel_env(n_agents=2, touch=True, expressions=False,
                                    per_agent=[{"delays": delays}, {"delays": "developmental"}])
    env.reset(seed=0)
    sp = env.action_space("infant_0")
    rng = np.random.default_rng(2)
    actions = [{a: rng.uniform(sp.low, sp.high) for a in env.agents} for _ in range(24)]
    for a in actions[:7]:
        env.step(a)
    copy = pickle.loads(pickle.dumps(env))
    for a in actions[7:]:
        one, two = env.step(a), copy.step(a)
        for agent in one[0]:
            for key in one[0][agent]:
                assert np.array_equal(one[0][agent][key], two[0][agent][key]), (agent, key)
            assert one[4][agent]["cost"] == two[4][agent]["cost"]
        assert np.array_equal(env.world.data.qpos, copy.world.data.qpos)


@pytest.mark.parametrize("delays, words", [
    ({"vision": -5}, ["infant_0", "vision", "-5", "0", "1000"]),
    ({"vision": 5000}, ["infant_0", "vision", "5000", "1000"]),
    ({"smell": 10}, ["infant_0", "smell", "proprioception", "motor"]),
    ("fast", ["infant_0", "delays", "fast", "developmental"]),
    ({"touch": "soon"}, ["infant_0", "touch", "soon"]),
])
def test_bad_delays_are_named(delays, words):
    with pytest.raises(ConfigError) as err:
        free_play_v0.parallel_env(n_agents=2, per_agent=[{}, {"delays": delays}])
    message = str(err.value).replace("infant_1", "infant_0")
    for word in words:
        assert word in message, f"{word!r} not in {message!r}"


def test_a_delay_of_more_steps_than_the_cap_is_refused_when_the_env_is_made():
    """The buffers grow with delay / control step: at the finest control step (0.1 ms) the
    largest delay in milliseconds (1 s) would be 10 000 steps of touch readings. A channel that
    is on may span at most MAX_DELAY_STEPS steps: beyond, a ConfigError names the agent, the
    channel, the delay, its steps and the most allowed; at the cap the env is made."""
    fine = {"timestep": 0.0001, "frame_skip": 1}          # a 0.1 ms control step
    cases = [({"touch": 1000.0}, ["touch", "1000 ms", "10000 control steps"]),
             ({"motor": 100.1}, ["motor", "100.1 ms", "1001 control steps"]),
             ("developmental", ["delays='developmental'", "(0 months)", "vision 260 ms",
                                "2600 control steps"])]
    for delays, words in cases:
        with pytest.raises(ConfigError) as err:
            _env(delays, physics=fine, age_months=0, vision={"width": 8, "height": 8})
        for word in ["agent infant_0", *words, "at most 1000 steps",
                     "100 ms at this control step", "1 ms or more allows the full 1000 ms"]:
            assert word in str(err.value), f"{word!r} not in {str(err.value)!r}"
    from mimo_social.core.delays import MAX_DELAY_STEPS
    assert MAX_DELAY_STEPS == 1000
    # at the cap the rings are built; a sense that is off has nothing to delay (no error)
    env = _env({"motor": 100.0, "vision": 1000.0}, physics=fine)
    assert env.delay_steps("infant_0")["motor"] == MAX_DELAY_STEPS
    # the same delay at a 1 ms control step is 1000 steps: allowed
    env = _env({"touch": 1000.0}, physics={"timestep": 0.001, "frame_skip": 1})
    assert env.delay_steps("infant_0")["touch"] == MAX_DELAY_STEPS


@pytest.mark.slow
def test_mujocos_vestibular_delay_is_exact_over_ten_thousand_steps():
    """MuJoCo's own delay, set as k * dt - timestep / 2 with zero-order hold, reads the wanted
    sample at every one of 10 000 steps; set as exactly k * dt it picks a neighbour now and then
    (the sample times are sums of floats)."""
    n = 10_000
    base, env = _env(touch=False), _env({"vestibular": 70.0}, touch=False)
    actions = _actions(env, n)
    reads = []
    for e in (base, env):
        obs, _ = e.reset(seed=0)
        got = [obs["infant_0"]["vestibular"]]
        for a in actions:
            obs, _, term, _, info = e.step({"infant_0": a})
            assert not term["infant_0"], info
            got.append(obs["infant_0"]["vestibular"])
        reads.append(np.array(got))
    assert np.array_equal(reads[1][7:], reads[0][:-7]) and (reads[1][:8] == reads[0][0]).all()
    # the same delay set as exactly k * dt in a small model misses some steps
    misses = []
    for delay in (0.01, 0.01 - 0.0025):
        spec = mujoco.MjSpec()
        spec.option.timestep = 0.005
        body = spec.worldbody.add_body()
        body.add_freejoint()
        body.add_geom(size=[0.1, 0, 0])
        body.add_site(name="s")
        sensor = spec.add_sensor(type=mujoco.mjtSensor.mjSENS_GYRO,
                                 objtype=mujoco.mjtObj.mjOBJ_SITE, objname="s")
        sensor.delay, sensor.nsample = delay, 4
        m = spec.compile()
        d, ref = mujoco.MjData(m), mujoco.MjData(m)
        m0 = mujoco.MjModel.from_xml_string(spec.to_xml().replace(f'delay="{delay}"', ""))
        rng = np.random.default_rng(0)
        seen, want = [], []
        for _ in range(2000):
            d.xfrc_applied[1] = ref.xfrc_applied[1] = rng.normal(size=6)
            for _ in range(2):
                mujoco.mj_step(m, d)
                mujoco.mj_step(m0, ref)
            seen.append(d.sensordata.copy())
            want.append(ref.sensordata.copy())
        misses.append(int(np.any(np.array(seen[1:]) != np.array(want[:-1]), axis=1).sum()))
    print(f"steps (of 1999) reading a wrong sample, delay k dt: {misses[0]}, k dt - timestep/2: "
          f"{misses[1]}")
    assert misses[0] > 0 and misses[1] == 0, misses
