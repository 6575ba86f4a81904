"""Batched task logic (issue 34) against the CPU env, on Warp's CPU device: the rewards, success
and terminations of reach, high five and self-body on the catalogue's scripted episodes, free
play's, the high five's scripted partner on the device, self-body's target observed, and the
errors for what the device does not run.

Self-body's hand presses boxes and capsules of the legs: MuJoCo Warp's collision routines
give those pairs other contact points than C MuJoCo's (two where C has one, at other places),
so the nearest contact's distance to the target, the reward, differs by a few millimetres while
the hand presses, with the state copied before every step too; which primitives are pressed
and the success agree.

Each world of a :class:`BatchedTaskEnv` and one CPU env reset with the world's seed get the
same actions (the scripted controller's, and for high five the default partner's, computed on
the CPU env). Reach has no gravity and no friction-loss stick-slip on its path: the worlds
follow their CPU envs free running (rewards within 1e-5 measured). High five's bodies stand
under gravity with friction loss at every joint, so float32 physics parts from the CPU's
slowly (docs/gpu.md): free running, rewards agree within 2e-3 and success on the same step;
with each world's state copied from its CPU env before every step (the task's hold timer
kept), what is compared is the task logic over one step of physics: 1e-4 (the hands pressing
together: the contact solver's float32 over one step).
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.envs import (free_play_v0, high_five_v0, mirror_v0, reach_v0,  # noqa: E402
                              selfbody_v0)
from mimo_social.envs.catalog import entry  # noqa: E402
from mimo_social.gpu import BatchedTaskEnv  # noqa: E402
from mimo_social.partners import Still  # noqa: E402
from mimo_social.tasks.high_five import HighFiveController, default_partner  # noqa: E402
from mimo_social.tasks.selfbody import SelfBodyController  # noqa: E402
from mimo_social.tasks.selfbody.task import MISS_REWARD  # noqa: E402

SEEDS = (0, 1)


def _motors(a):
    return a["motors"] if isinstance(a, dict) else np.asarray(a, np.float32)


def _cpu_action(env, agent, u):
    space = env.action_space(agent)
    return {"motors": u, "expression": 0} if hasattr(space, "spaces") else u


def run_pair(tenv, make_cpu, policies, force=False, steps=500):
    """Scripted episodes side by side: CPU env ``w`` reset with world ``w``'s seed, each
    agent of ``policies`` (agent -> Partner class) acting on it; the same actions given to the
    world (``force``: the CPU env's state copied into the world before each step). Returns
    per world the lists of (device reward, CPU reward, device success, CPU success, device
    terminated, CPU terminated, largest difference of the controls applied) of the CPU
    episode's steps."""
    tenv.reset(seed=SEEDS[0])
    cpus, pols, obs = [], [], []
    for w in range(tenv.nworld):
        c = make_cpu()
        o, _ = c.reset(seed=tenv.seed_of(w))
        p = {a: cls() for a, cls in policies.items()}
        for a, pol in p.items():
            pol.reset(c.unwrapped, a, np.random.default_rng(w))
        cpus.append(c), pols.append(p), obs.append(o)
    live = [True] * tenv.nworld
    records = [[] for _ in cpus]
    learner = tenv.learners[0]
    for _ in range(steps):
        acts = {a: np.zeros((tenv.nworld, tenv.n_controls(a)), np.float32)
                for a in tenv.learners}
        given = [None] * tenv.nworld
        for w, (c, p) in enumerate(zip(cpus, pols)):
            if live[w]:
                given[w] = {a: _motors(pol.act(c.unwrapped, a, obs[w].get(a)))
                            for a, pol in p.items()}
                for a in tenv.learners:
                    acts[a][w] = given[w][a]
        if force:
            worlds = [w for w in range(tenv.nworld) if live[w]]
            tenv.batched.load(worlds, [tenv.batched.snapshot(cpus[w].unwrapped) for w in worlds])
        _, rew, term, _, infos = tenv.step(acts, autoreset=False)
        for w, c in enumerate(cpus):
            if not live[w]:
                continue
            lone = {a: _cpu_action(c, a, given[w][a]) for a in c.possible_agents}
            obs[w], r, te, tr, inf = c.step(lone)
            records[w].append((float(rew[learner][w]), r[learner],
                               float(infos["is_success"][w]), float(inf[learner]["is_success"]),
                               bool(term[w]), te[learner],
                               np.abs(tenv.batched.tensors["ctrl"][w].numpy()
                                      - c.unwrapped.world.data.ctrl).max()))
            live[w] = not (te[learner] or tr[learner])
        if not any(live):
            break
    return [np.array(r) for r in records], cpus


def check(records, tol, same_success=True):
    print("largest reward difference per world:",
          [float(np.abs(r[:, 0] - r[:, 1]).max()) for r in records],
          "steps:", [len(r) for r in records])
    for w, rec in enumerate(records):
        assert rec[-1, 3] == 1.0, f"world {w}: the scripted episode did not succeed on the CPU"
        err = np.abs(rec[:, 0] - rec[:, 1]).max()
        assert err < tol, (w, err)
        if not same_success:
            continue
        assert (rec[:, 2] == rec[:, 3]).all(), (w, np.flatnonzero(rec[:, 2] != rec[:, 3]))
        assert (rec[:, 4] == rec[:, 5]).all(), (w, np.flatnonzero(rec[:, 4] != rec[:, 5]))


@pytest.fixture(scope="module")
def reach():
    return BatchedTaskEnv(reach_v0.parallel_env(), len(SEEDS), device="cpu", seed=SEEDS[0])


@pytest.fixture(scope="module")
def high_five():
    return BatchedTaskEnv(high_five_v0.parallel_env(), len(SEEDS), device="cpu", seed=SEEDS[0])


@pytest.fixture(scope="module")
def high_five_scripted():
    return BatchedTaskEnv(high_five_v0.scripted_env(), len(SEEDS), device="cpu",
                          seed=SEEDS[0])


def test_gpu_reach_rewards_and_success_are_the_cpu_envs(reach):
    """Free running; each world's ball is its own seed's (the model's body_pos per world)."""
    records, cpus = run_pair(reach, reach_v0.parallel_env, {"infant_0": entry("reach").controller})
    check(records, 1e-4)
    balls = reach.batched.model_tensors["body_pos"]
    assert not np.allclose(balls[0].numpy(), balls[1].numpy())


def test_gpu_reach_with_developmental_delays_is_the_cpu_envs():
    """Motor and proprioceptive delays of 2 control steps (18 months) on both sides."""
    make = lambda: reach_v0.parallel_env(delays="developmental")  # noqa: E731
    tenv = BatchedTaskEnv(make(), len(SEEDS), device="cpu", seed=SEEDS[0])
    assert tenv.inner.delay_steps("infant_0")["motor"] == 2
    records, _ = run_pair(tenv, make, {"infant_0": entry("reach").controller})
    check(records, 1e-4)


def test_gpu_high_five_touch_rule_is_the_cpus():
    """``success="touch"`` (the first versions' rule): any touch both skins feel, one step."""
    make = lambda: high_five_v0.parallel_env(task_options={"success": "touch"})  # noqa: E731
    tenv = BatchedTaskEnv(make(), len(SEEDS), device="cpu", seed=SEEDS[0])
    records, _ = run_pair(tenv, make, {"infant_0": HighFiveController,
                                       "infant_1": default_partner})
    check(records, 2e-3)


def test_gpu_high_five_rewards_and_success_are_the_cpu_envs(high_five):
    """Both infants act as learners on the device, the CPU's scripted learner and default
    partner computing the actions; free running."""
    records, _ = run_pair(high_five, high_five_v0.parallel_env,
                          {"infant_0": HighFiveController, "infant_1": default_partner})
    check(records, 2e-3)
    assert all(r[-1, 2] == 1.0 for r in records)


def test_gpu_high_five_task_logic_over_one_step_is_the_cpus(high_five):
    """Each world's state copied from its CPU env before every step: the palms' distance,
    the skins feeling the partner, the palm-to-palm rule and the hold timer over one step."""
    records, _ = run_pair(high_five, high_five_v0.parallel_env,
                          {"infant_0": HighFiveController, "infant_1": default_partner},
                          force=True)
    check(records, 1e-4)


def test_gpu_high_five_partner_on_the_device_is_the_cpus(high_five_scripted):
    """One learner (the scripted controller's actions); the default partner (HandOffer)
    acting on the device from its CPU plan and the batched data."""
    tenv = high_five_scripted
    assert tenv.learners == ["infant_0"] and list(tenv.partners) == ["infant_1"]
    records, cpus = run_pair(tenv, high_five_v0.scripted_env, {"infant_0": HighFiveController})
    check(records, 2e-3)
    # every agent's controls (the partner's from the device's law, the learner's given)
    print("largest control difference, first 50 steps, all:",
          [(r[:50, 6].max(), r[:, 6].max()) for r in records])
    assert all(r[:50, 6].max() < 1e-5 and r[:, 6].max() < 0.1 for r in records)


SOLE = {"target": "right_sole"}
#: primitives of the sole's foot the hand may be aimed at to press the foot off the target
#: (which one presses without brushing the sole depends on the plan, and plans differ between
#: machines: they are chosen by rollouts with contacts)
FOOT = ("right_heel", "right_ball")


def _sole_env(**touch):
    kw = {"touch": {"density": 0.25, "normal_only": True, **touch}} if touch else {}
    return selfbody_v0.parallel_env(task_options=SOLE, **kw)


def _aimed(part):
    return lambda: SelfBodyController(target=part)


def _presses_off_target(make, part, steps=400):
    """A CPU episode (seed 0) with the hand aimed at ``part``, up to its success: (the steps in
    which the hand presses the body without success, i.e. a reward other than the miss; the
    steps before the success or the end)."""
    env = make()
    obs, _ = env.reset(seed=0)
    pol = SelfBodyController(target=part)
    pol.reset(env.unwrapped, "infant_0", np.random.default_rng(0))
    pressing = 0
    for t in range(steps):
        obs, r, te, tr, inf = env.step({"infant_0": pol.act(env.unwrapped, "infant_0",
                                                            obs["infant_0"])})
        if inf["infant_0"]["is_success"]:
            return pressing, t
        pressing += r["infant_0"] != MISS_REWARD
        if te["infant_0"] or tr["infant_0"]:
            return pressing, t + 1
    return pressing, steps


def test_gpu_selfbody_task_logic_over_one_step_is_the_cpus():
    """The state copied from the CPU env before every step: the hand aimed at another primitive
    of the target's foot (the first of :data:`FOOT` that presses it without touching the sole):
    the reach through the air (the miss reward, exactly), then the hand pressing the foot off
    the target while the foot feels it (no success on either), up to the step before the hand
    slides onto the sole; aimed at the target: success on
    the CPU's step, the reward within the contact points' difference (module docstring)."""
    scans = {p: _presses_off_target(_sole_env, p) for p in FOOT}
    aim = next((p for p in FOOT if scans[p][0] >= 20), None)
    assert aim is not None, f"no primitive of the foot pressed 20 steps off the target: {scans}"
    tenv = BatchedTaskEnv(_sole_env(), 1, device="cpu", seed=0)
    off, _ = run_pair(tenv, _sole_env, {"infant_0": _aimed(aim)}, force=True,
                      steps=scans[aim][1])
    on, _ = run_pair(tenv, _sole_env, {"infant_0": SelfBodyController}, force=True)
    check(on, 1e-2)
    off, on = off[0], on[0]
    assert np.abs(off[:, 0] - off[:, 1]).max() < 1e-2
    air = np.concatenate([off[:, 1], on[:, 1]]) == MISS_REWARD
    both = np.concatenate([off, on])
    assert air.sum() > 100 and (both[air, 0] == MISS_REWARD).all()
    other = (off[:, 1] != MISS_REWARD)                 # pressing the foot, not the target
    assert other.sum() >= 20 and (off[other, 0] != MISS_REWARD).all()
    assert (off[:, 2] == 0.0).all() and (off[:, 3] == 0.0).all()


def test_gpu_selfbody_success_needs_the_target_part_to_feel_the_touch():
    """The foot without skin (``touch`` ``exclude``): the hand presses right_sole as before
    (the skin does not move the body) and neither the CPU nor the device counts it. The
    episode runs to the step the controller's plan touches the sole, and 20 more."""
    make = lambda: _sole_env(exclude=("right_foot",))  # noqa: E731
    probe = make()
    probe.reset(seed=0)
    pol = SelfBodyController()
    pol.reset(probe.unwrapped, "infant_0", np.random.default_rng(0))
    assert np.isfinite(pol.planned_steps), "the controller found no plan that touches the sole"
    tenv = BatchedTaskEnv(make(), 1, device="cpu", seed=0)
    records, cpus = run_pair(tenv, make, {"infant_0": SelfBodyController},
                             force=True, steps=int(pol.planned_steps) + 20)
    rec = records[0]
    assert "right_sole" in cpus[0].unwrapped.task._touched
    assert (rec[:, 2] == 0.0).all() and (rec[:, 3] == 0.0).all()
    assert np.abs(rec[:, 0] - rec[:, 1]).max() < 1e-2


@pytest.fixture(scope="module")
def selfbody():
    return BatchedTaskEnv(selfbody_v0.parallel_env(), len(SEEDS), device="cpu", seed=SEEDS[0])


@pytest.mark.slow
def test_gpu_selfbody_free_running_reaches_its_targets(selfbody):
    """Free running: the reach through the air is the CPU's in every world; once the hand
    presses other primitives the contact points differ (module docstring) and the hand slides
    on another path (seed 0: 4 cm apart); a world whose hand goes to its target directly
    succeeds on the CPU's step."""
    records, _ = run_pair(selfbody, selfbody_v0.parallel_env,
                          {"infant_0": entry("selfbody").controller})
    for rec in records:
        first = int(np.flatnonzero(rec[:, 1] != -1.0)[0])
        assert first > 20 and (rec[:first, 0] == -1.0).all()
    assert any(rec[-1, 2] == rec[-1, 3] == 1.0 for rec in records)


def test_gpu_selfbody_observes_each_worlds_target_and_redraws_it_at_resets(selfbody):
    """The one-hot target of each world is its CPU reset's (the world's seed); an autoreset
    draws the next episode's, the finished step's own kept in final_obs."""
    tenv = selfbody
    obs, _ = tenv.reset(seed=5)
    got = obs["infant_0"]["target"].numpy()
    assert got.shape == (tenv.nworld, len(tenv.inner.task.targets))
    for w in range(tenv.nworld):
        cpu = selfbody_v0.parallel_env()
        o, _ = cpu.reset(seed=tenv.seed_of(w))
        np.testing.assert_array_equal(got[w], o["infant_0"]["target"])
    before = got.copy()
    n = tenv.n_controls("infant_0")
    done = np.zeros(tenv.nworld, bool)
    for _ in range(tenv.max_steps):
        obs, _, term, trunc, infos = tenv.step({"infant_0": np.zeros((tenv.nworld, n),
                                                                    np.float32)})
        done = (term | trunc).numpy()
        if done.any():
            break
    assert done.all()                 # the zero action touches nothing: truncated together
    np.testing.assert_array_equal(infos["final_obs"]["infant_0"]["target"].numpy(), before)
    after = obs["infant_0"]["target"].numpy()
    for w in range(tenv.nworld):
        cpu = selfbody_v0.parallel_env()
        o, _ = cpu.reset(seed=tenv.seed_of(w))
        np.testing.assert_array_equal(after[w], o["infant_0"]["target"])
    assert not np.array_equal(after, before)
    assert (infos["target"].numpy() == before.argmax(1)).all()


def test_gpu_free_play_has_no_reward_and_ends_at_its_time_limit():
    """Free play of two infants: reward 0 for both, never terminated, truncated at max_steps
    in every world, the worlds reset by themselves."""
    tenv = BatchedTaskEnv(free_play_v0.parallel_env(n_agents=2, max_steps=3), 2, device="cpu")
    assert tenv.learners == ["infant_0", "infant_1"] and tenv.task.info_keys == ()
    tenv.reset(seed=0)
    rng = np.random.default_rng(0)
    for k in range(1, 7):
        acts = {a: rng.uniform(-1, 1, (2, tenv.n_controls(a))).astype(np.float32)
                for a in tenv.learners}
        _, rew, term, trunc, infos = tenv.step(acts)
        assert all((r.numpy() == 0.0).all() for r in rew.values())
        assert not term.any() and bool(trunc.all()) == (k % 3 == 0) and trunc.any() == trunc.all()
        assert (infos["instability"].numpy() == 0.0).all()
    assert list(tenv._episode) == [2, 2]


def test_gpu_task_env_refuses_what_the_device_does_not_run():
    with pytest.raises(ValueError, match=r"task 'mirror' has no batched task logic .*"
                                         r"allowed: catch, free_play, high_five, reach, rollover, "
                                         r"selfbody, standup"):
        BatchedTaskEnv(mirror_v0.parallel_env(), 1, device="cpu")
    with pytest.raises(ValueError, match=r"high_five: task option assisted_gaze=True does not "
                                         r"run .* allowed: assisted_gaze=False"):
        BatchedTaskEnv(high_five_v0.parallel_env(task_options={"assisted_gaze": True}), 1,
                       device="cpu")
    with pytest.raises(ValueError, match=r"infant_1: scripted partner Still\(\) has no batched "
                                         r"form .* allowed: HandOffer\(grip=False, "
                                         r"release=None\)"):
        BatchedTaskEnv(high_five_v0.scripted_env(partner=Still()), 1, device="cpu")


def test_gpu_task_env_names_the_agent_and_field_of_a_bad_action(high_five_scripted):
    tenv = high_five_scripted
    tenv.reset(seed=0)
    n = tenv.n_controls("infant_0")
    with pytest.raises(ValueError, match=r"infant_0: motors of shape \(2, 3\); expected "
                                         r"\(2, %d\)" % n):
        tenv.step({"infant_0": np.zeros((2, 3), np.float32)})
    with pytest.raises(ValueError, match=r"infant_0: motors of dtype torch.bool; expected real"):
        tenv.step({"infant_0": np.zeros((2, n), bool)})
    with pytest.raises(ValueError, match=r"\['infant_1'\] act by their scripted partners"):
        tenv.step({"infant_0": np.zeros((2, n), np.float32),
                   "infant_1": np.zeros((2, n), np.float32)})
    with pytest.raises(ValueError, match=r"worlds \[5\] not allowed; allowed: indices from 0 "
                                         r"to 1"):
        tenv.reset(worlds=[5])
