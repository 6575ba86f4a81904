"""An infant's age changed at reset without compiling (``env.set_age``, ``reset(options=...)``):
the change writes the body of the new ages into the live model and equals a fresh build at those
ages (masses, inertia tensors, geoms, bodies, joints, motors, the start pose, and the motion under
the same actions); no compile happens and it is cheap; a pickled copy continues identically, a
seeded reset repeats, every delay buffer starts from the reset reading, bad input is named."""

from __future__ import annotations

import pickle
import statistics
import time

import mujoco
import numpy as np
import pytest

from mimo_social.body.inertia import quat_matrices
from mimo_social.core.config import ConfigError
from mimo_social.core.gym_adapter import SingleAgentEnv
from mimo_social.envs import free_play_v0, high_five_v0, still_face_v0
from mimo_social.envs.catalog import CATALOG, entry
from mimo_social.senses.skin import GRID_CELL, SHAPES, signed_distance

STEPS = 100


def _tensors(m, bodies):
    R = quat_matrices(m.body_iquat[bodies])
    return np.einsum("nij,nj,nkj->nik", R, m.body_inertia[bodies], R)


def _same_model(a, b, tol=1e-9):
    """Every age-dependent model value of the agents of ``a`` equal to ``b``'s."""
    ma, mb = a.world.model, b.world.model
    for ag_a, ag_b in zip(a.world.agents, b.world.agents):
        bodies, geoms = ag_a.body_ids, ag_a.geom_ids
        assert np.array_equal(bodies, ag_b.body_ids) and np.array_equal(geoms, ag_b.geom_ids)
        for field in ("body_mass", "body_pos", "body_ipos", "body_subtreemass"):
            np.testing.assert_allclose(getattr(ma, field)[bodies], getattr(mb, field)[bodies],
                                       rtol=tol, atol=1e-12, err_msg=field)
        np.testing.assert_allclose(_tensors(ma, bodies), _tensors(mb, bodies), rtol=tol,
                                   atol=1e-14, err_msg="inertia tensors")
        for field in ("geom_size", "geom_pos", "geom_rbound", "geom_aabb", "geom_friction"):
            np.testing.assert_allclose(getattr(ma, field)[geoms], getattr(mb, field)[geoms],
                                       rtol=tol, atol=1e-12, err_msg=field)
    for field in ("body_quat", "eq_data", "jnt_pos", "jnt_stiffness", "dof_damping", "dof_armature", "dof_frictionloss",
                  "actuator_ctrlrange", "actuator_forcerange", "actuator_gainprm",
                  "actuator_biasprm", "actuator_gear", "site_pos", "cam_pos", "bvh_aabb",
                  "dof_invweight0", "body_invweight0", "actuator_acc0", "qpos0", "sensor_delay"):
        np.testing.assert_allclose(getattr(ma, field), getattr(mb, field), rtol=tol, atol=1e-12,
                                   err_msg=field)
    assert ma.stat.meaninertia == pytest.approx(mb.stat.meaninertia, rel=1e-12)


def _actions(env, n, seed=1):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        step = {}
        for a in env.possible_agents:
            sp = env.action_space(a)
            motors = sp["motors"] if hasattr(sp, "spaces") else sp
            u = rng.uniform(motors.low, motors.high).astype(np.float32)
            extra = {"expression": 0, "voice": 1, "loudness": [0.5]}   # those the space has
            step[a] = ({"motors": u, **{k: v for k, v in extra.items() if k in sp.spaces}}
                       if hasattr(sp, "spaces") else u)
        out.append(step)
    return out


def _run(env, actions, seed=3, **reset):
    obs, _ = env.reset(seed=seed, **reset)
    start = env.world.data.qpos.copy()
    for act in actions:
        env.step(act)
    return obs, start, env.world.data.qpos.copy()


@pytest.mark.parametrize("hands,actuation", [("mitten", "spring_damper"),
                                             ("five_fingers", "spring_damper"),
                                             ("mitten", "muscle"), ("mitten", "positional")])
def test_an_age_change_at_reset_equals_a_fresh_build(hands, actuation):
    kw = dict(hands=hands, actuation=actuation, delays="developmental", max_steps=10_000)
    if actuation == "spring_damper":
        kw["touch"] = True    # the whole body's skin (the task's default: the right hand's)
    env = high_five_v0.parallel_env(**kw)
    env.reset(seed=0)
    model, data = env.world.model, env.world.data
    spaces_before = {a: env.observation_space(a) for a in env.possible_agents}
    shapes = {a: {k: s.shape for k, s in sp.spaces.items()} for a, sp in spaces_before.items()}
    env.set_age(age_months=6, motor_age_months=12)
    fresh = high_five_v0.parallel_env(age_months=6, motor_age_months=12, **kw)
    actions = _actions(env, STEPS)
    obs, start, end = _run(env, actions)
    obs_f, start_f, end_f = _run(fresh, actions)
    assert env.world.model is model and env.world.data is data   # nothing rebuilt
    assert all(c.age_months == 6 and c.motor_age_months == 12 for c in env.agent_configs)
    _same_model(env, fresh)
    np.testing.assert_allclose(start, start_f, atol=1e-12)          # the start pose
    np.testing.assert_allclose(end, end_f, atol=1e-6)               # the motion
    for a in env.possible_agents:                                   # the same space objects
        assert env.observation_space(a) is spaces_before[a]
        assert {k: v.shape for k, v in obs[a].items()} == shapes[a]
        for k, v in obs[a].items():
            if k == "touch":   # a fresh skin may have a few points more or fewer
                continue
            assert v.shape == obs_f[a][k].shape
            np.testing.assert_allclose(env.observation_space(a)[k].low,
                                       fresh.observation_space(a)[k].low)
        assert env.delay_steps(a) == fresh.delay_steps(a)
    env.close()
    fresh.close()


def test_no_compile_happens_and_a_change_is_cheap(monkeypatch):
    env = free_play_v0.parallel_env(n_agents=1, touch=True)
    env.reset(seed=0)
    model = env.world.model

    def refuse(*args, **kwargs):
        raise AssertionError("compiled during an age change")

    monkeypatch.setattr(mujoco.MjSpec, "compile", refuse)
    cost = []   # CPU seconds of the reset that applies the change (the reset included)
    for age in (6, 12, 3, 24, 9, 30, 15):
        env.set_age(age_months=age, motor_age_months=age + 1)
        t = time.process_time()
        env.reset(seed=1)
        cost.append(time.process_time() - t)
        assert env.world.model is model
        assert env.agent_configs[0].age == age
    assert statistics.median(cost) <= 0.050, cost


def test_a_pickled_copy_after_an_age_change_continues_identically():
    env = free_play_v0.parallel_env(n_agents=1, touch=True, delays="developmental",
                                    max_steps=10_000)
    env.reset(seed=0, options={"age_months": 4, "motor_age_months": 9})
    actions = _actions(env, 20)
    for act in actions[:10]:
        env.step(act)
    copy = pickle.loads(pickle.dumps(env))
    assert copy.agent_configs[0].age_months == 4 and copy.agent_configs[0].motor_age_months == 9
    assert copy.world.tables[0].age_months == 4
    for act in actions[10:]:
        o1 = env.step(act)[0]["infant_0"]
        o2 = copy.step(act)[0]["infant_0"]
        for k in o1:
            np.testing.assert_array_equal(o1[k], o2[k])
    np.testing.assert_array_equal(env.world.data.qpos, copy.world.data.qpos)
    # a reset of the copy gives the same episode as the original's (the body stays 4 months)
    _, s1, e1 = _run(env, actions)
    _, s2, e2 = _run(copy, actions)
    np.testing.assert_array_equal(s1, s2)
    np.testing.assert_array_equal(e1, e2)


def test_a_seeded_reset_after_an_age_change_repeats():
    env = high_five_v0.parallel_env(max_steps=10_000)
    actions = _actions(env, 30)
    first = _run(env, actions, seed=5, options={"age_months": {"infant_0": 8}})
    again = _run(env, actions, seed=5)
    assert env.agent_configs[0].age_months == 8 and env.agent_configs[1].age_months is None
    for x, y in zip(first[1:], again[1:]):
        np.testing.assert_array_equal(x, y)


def test_every_delay_buffer_starts_from_the_reset_reading():
    k = 3
    delays = {"proprioception": 30.0, "touch": 30.0, "vestibular": 30.0, "vision": 30.0,
              "motor": 30.0}
    env = free_play_v0.parallel_env(n_agents=1, touch=True, expressions=False, delays=delays,
                                    vision={"width": 16, "height": 16}, max_steps=10_000)
    env.reset(seed=0)
    actions = _actions(env, 12)
    for act in actions:              # fill every ring with readings of a moving body
        env.step(act)
    for options in ({"age_months": 5}, None):
        obs, _ = env.reset(seed=2, options=options)
        first = obs["infant_0"]
        for t in range(k):
            later = env.step(actions[t])[0]["infant_0"]
            for key in ("proprioception", "touch", "vestibular", "eye_left", "eye_right"):
                np.testing.assert_array_equal(later[key], first[key], err_msg=f"{key} step {t}")
            # the controls applied are those in force at reset until k steps have passed
            assert not env.controls[0].any()
        later = env.step(actions[k])[0]["infant_0"]
        assert env.controls[0].any()
        assert not np.array_equal(later["proprioception"], first["proprioception"])


def test_gym_adapter_forwards_set_age_and_options():
    env = SingleAgentEnv(free_play_v0.parallel_env(n_agents=1))
    env.set_age(age_months=7)
    env.reset(seed=0)
    assert env.parallel.agent_configs[0].age_months == 7
    env.reset(seed=0, options={"motor_age_months": 20})
    cfg = env.parallel.agent_configs[0]
    assert (cfg.age_months, cfg.motor_age_months) == (7, 20)


def test_bad_input_is_named_and_changes_nothing():
    env = still_face_v0.parallel_env()
    env.reset(seed=0)
    infant, adult = env.possible_agents
    with pytest.raises(ConfigError, match=rf"{adult} is an adult.*infants: \['{infant}'\]"):
        env.set_age(age_months=6, agent=adult)
    with pytest.raises(ConfigError, match=r"age_months=40 not allowed; allowed: .*0.*33"):
        env.set_age(age_months=40)
    with pytest.raises(ConfigError, match=r"motor_age_months=-1 not allowed"):
        env.reset(options={"motor_age_months": -1})
    with pytest.raises(ConfigError, match=r"unknown option\(s\) \['age'\]; allowed: "
                                          r"\['age_months', 'motor_age_months'\]"):
        env.reset(options={"age": 6})
    with pytest.raises(KeyError, match=r"unknown agent 'infant_7'"):
        env.set_age(age_months=6, agent="infant_7")
    with pytest.raises(ConfigError, match=rf"{adult} is an adult"):
        env.reset(options={"age_months": {adult: 6}})
    env.reset(seed=0)
    assert env.agent_configs[0].age_months is None    # nothing pending from the refusals
    env.set_age(age_months=6)    # every infant: the caregiver is left as it is
    env.reset(seed=0)
    assert env.agent_configs[0].age_months == 6 and env.agent_configs[1].body == "adult"


def test_the_acuity_blur_follows_the_new_body_age():
    vision = {"width": 32, "height": 32, "acuity": "age"}
    env = free_play_v0.parallel_env(n_agents=1, vision=vision, age_months=18)
    env.reset(seed=0, options={"age_months": 1, "motor_age_months": 20})
    fresh = free_play_v0.parallel_env(n_agents=1, vision=vision, age_months=1)
    eyes, eyes_fresh = env.system("vision"), fresh.system("vision")
    assert eyes.cutoffs[0] == eyes_fresh.cutoffs[0] is not None
    obs = env.reset(seed=0)[0]["infant_0"]
    obs_fresh = fresh.reset(seed=0)[0]["infant_0"]
    np.testing.assert_array_equal(obs["eye_left"], obs_fresh["eye_left"])
    env.close()
    fresh.close()


@pytest.mark.parametrize("name", [e.name for e in CATALOG])
def test_every_catalogue_env_changes_age_as_a_fresh_build(name):
    """Tasks place agents, hold joints, size props and bind to the start state by the agents'
    sizes: after the change every one starts and moves as a fresh build at that age."""
    module = entry(name).module
    env = module.parallel_env(max_steps=10_000)
    env.reset(seed=0)
    env.set_age(age_months=7)
    per = [{"age_months": 7} if c.body == "infant" else {} for c in env.agent_configs]
    fresh = module.parallel_env(max_steps=10_000, per_agent=per)
    actions = _actions(env, 20)
    for x, y in zip(_run(env, actions, seed=4)[1:], _run(fresh, actions, seed=4)[1:]):
        np.testing.assert_allclose(x, y, atol=1e-6)
    env.close()
    fresh.close()


def test_a_pickled_copy_keeps_the_props_and_places_a_task_gave_the_new_ages():
    env = entry("imitation").module.parallel_env(max_steps=10_000)
    env.reset(seed=1, options={"age_months": 5})
    actions = _actions(env, 16)
    for act in actions[:8]:
        env.step(act)
    copy = pickle.loads(pickle.dumps(env))
    assert copy.world.props == env.world.props
    assert copy.world.agent_setups == env.world.agent_setups
    for act in actions[8:]:
        env.step(act)
        copy.step(act)
    np.testing.assert_array_equal(env.world.data.qpos, copy.world.data.qpos)
    for x, y in zip(_run(env, actions)[1:], _run(copy, actions)[1:]):
        np.testing.assert_array_equal(x, y)


def _lookup_error(skin):
    """Per point, probed half a spacing outward (as a contact is): the distance, in spacings,
    from the point to the one the lookup grid gives."""
    out = []
    for k in range(len(skin.part_names)):
        a, b = skin.part_start[k], skin.part_start[k + 1]
        s = skin.part_spacing[k]
        probe = skin.points[a:b] + 0.5 * s * skin.normals[a:b]
        dims = skin.grid_dims[k]
        cell = np.clip(np.floor((probe / s - skin.grid_lo[k]) / GRID_CELL).astype(int), 0,
                       dims - 1)
        flat = (cell[:, 0] * dims[1] + cell[:, 1]) * dims[2] + cell[:, 2]
        found = skin.grid[skin.grid_start[k] + flat]
        out.append(np.linalg.norm(skin.points[found] - skin.points[a:b], axis=1) / s)
    return np.concatenate(out)


@pytest.mark.parametrize("age", [0, 6, 30])
def test_the_carried_skin_finds_the_touched_point(age):
    env = free_play_v0.parallel_env(n_agents=1, touch=True)
    env.reset(seed=0, options={"age_months": age})
    skin = env.system("touch").skins[0]
    fresh = free_play_v0.parallel_env(n_agents=1, touch=True, age_months=age)
    error = _lookup_error(skin)
    assert np.median(error) == 0.0 and np.percentile(error, 99) <= 0.5 and error.max() <= 1.1
    # every point on its primitive's new surface, and the part as large as a fresh skin's
    m = env.world.model
    for g in np.unique(skin.point_geom):
        on = skin.point_geom == g
        R = quat_matrices(m.geom_quat[g])[0]
        local = (skin.points[on] - m.geom_pos[g]) @ R
        shape = SHAPES[int(m.geom_type[g])]
        np.testing.assert_allclose(signed_distance(shape, m.geom_size[g], local), 0.0,
                                   atol=1e-9, err_msg=m.geom(int(g)).name)
    for k, name in enumerate(skin.part_names):
        g = fresh.system("touch").skins[0]
        j = g.part_names.index(name)
        mine = skin.points[skin.part_start[k]:skin.part_start[k + 1]]
        theirs = g.points[g.part_start[j]:g.part_start[j + 1]]
        np.testing.assert_allclose(np.ptp(mine, axis=0), np.ptp(theirs, axis=0),
                                   rtol=0.15, atol=0.004, err_msg=name)
