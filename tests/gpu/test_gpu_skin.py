"""The touch skin on the device (:mod:`mimo_social.gpu.skin`) against the CPU skin, on Warp's CPU
device.

Two questions, kept apart:

* the skin's arithmetic: fed the CPU env's own contacts and state (``contact_rows`` built from
  ``data.contact`` and ``mj_contactForce``), :class:`BatchedSkin` gives every skin point the
  CPU skin's force, step after step of scripted high five episodes with full-body skins (both
  hands pressing, an arm on its own body; ``spread_linear``), and of ``nearest`` and
  world-frame force vectors;
* the ``touch`` observation of the batched env: each world's state copied from its CPU env
  before every step, the device's contacts are Warp's (other contact points for some geom pairs,
  float32): each agent's summed touch over the episode, and per step where it exceeds 5 N,
  within 10 % of the CPU observation's.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")
import torch  # noqa: E402

from mimo_social.envs import high_five_v0, selfbody_v0  # noqa: E402
from mimo_social.tasks.selfbody import SelfBodyController  # noqa: E402
from mimo_social.gpu import BatchedEnv, BatchedTaskEnv, device_spaces  # noqa: E402
from mimo_social.gpu.skin import BatchedSkin  # noqa: E402
from mimo_social.tasks.high_five import HighFiveController  # noqa: E402

STEPS = 150
#: self-body's skin checks: the hand presses a part it is aimed at (the controller's ``target``)
#: while the task's target is another (the head), so the episode goes on and the hand keeps
#: pressing: the pressing is built, not left to where a plan for the task's target happens to
#: brush other parts (plans differ between machines: they are chosen by rollouts with contacts)
PRESSED = ("hip", "right_upper_leg")
HEAD = {"target": "head"}


def _selfbody(**kw):
    return selfbody_v0.parallel_env(task_options=HEAD, **kw)


def _aimed(part):
    return lambda: SelfBodyController(target=part)


def _motors(a):
    return a["motors"] if isinstance(a, dict) else np.asarray(a, np.float32)


def _step_cpu(env, policies, obs):
    space = env.action_space("infant_0")
    acts = {a: _motors(p.act(env.unwrapped, a, obs.get(a))) for a, p in policies.items()}
    out = env.step({a: {"motors": u, "expression": 0} if hasattr(space, "spaces") else u
                    for a, u in acts.items()})
    return out, acts


def _cpu_rows(m, d):
    """The CPU env's contacts as :func:`contact_rows` gives the device's, and its state."""
    n = d.ncon
    c = d.contact
    force = np.zeros((n, 6))
    for i in range(n):
        mujoco.mj_contactForce(m, d, i, force[i])
    as_t = lambda x, kind=torch.float64: torch.as_tensor(np.array(x), dtype=kind)  # noqa: E731
    rows = {"geom": as_t(c.geom[:n], torch.int64), "pos": as_t(c.pos[:n]),
            "frame": as_t(c.frame[:n].reshape(n, 3, 3)), "force": as_t(force[:, :3]),
            "world": torch.zeros(n, dtype=torch.int64),
            "kept": as_t(c.efc_address[:n] >= 0, torch.bool)}
    data = {"qvel": as_t(d.qvel[None]), "cdof": as_t(d.cdof[None]),
            "subtree_com": as_t(d.subtree_com[None]), "xpos": as_t(d.xpos[None]),
            "xmat": as_t(d.xmat[None])}
    return rows, data


def _episode(env, seed: int, steps: int = STEPS, controller=HighFiveController):
    """Scripted episodes (``controller`` for every agent): yields the env after each step; an
    episode that ends is followed by one of the next seed."""
    def start(seed):
        obs, _ = env.reset(seed=seed)
        pols = {a: controller() for a in env.possible_agents}
        for a, p in pols.items():
            p.reset(env.unwrapped, a, np.random.default_rng(seed))
        return obs, pols
    obs, pols = start(seed)
    for _ in range(steps):
        (obs, _, term, trunc, _), _ = _step_cpu(env, pols, obs)
        yield env
        if any(term.values()) or any(trunc.values()):
            seed += 1000
            obs, pols = start(seed)


CASES = {"spread_linear": (high_five_v0.parallel_env, {}), "nearest": (
    high_five_v0.parallel_env, {"response": "nearest"}), "world_vectors": (
    high_five_v0.parallel_env, {"frame": "world", "normal_only": False}), "selfbody": (
    _selfbody, {"density": 0.25, "frame": "body", "normal_only": False})}


@pytest.mark.parametrize("case", list(CASES))
def test_the_skin_fed_the_cpu_contacts_is_the_cpu_skin(case):
    """Every point's force (x, y, z and normal) equals the CPU skin's to float32 rounding on
    every step of scripted episodes: two high fives (full-body skins; both hands pressing, an
    arm on its own body) with each response and frame, and self-body (the hand pressing the
    hip, :data:`PRESSED`: body-frame force vectors). Contacts are carried along over
    the last step: the device skin reads the same cdof, subtree_com and qvel."""
    make, touch = CASES[case]
    env = make(touch=touch or True)
    controller = _aimed(PRESSED[0]) if make is _selfbody else HighFiveController
    env.reset(seed=0)
    system = env.unwrapped.system("touch")
    m = env.unwrapped.world.model
    skin = BatchedSkin(system, m, 1, torch, "cpu")
    felt = 0
    for seed in (0, 1):
        for e in _episode(env, seed, controller=controller):
            rows, data = _cpu_rows(m, e.unwrapped.world.data)
            skin.feel(rows, data, h=None if e.unwrapped.steps else 0.0)
            want = BatchedSkin.reading(system)[:-1]
            got = skin.acc[0, :-1].numpy()
            scale = max(1.0, np.abs(want).max())
            np.testing.assert_allclose(got, want, atol=1e-4 * scale, rtol=1e-3)
            felt += int(want[:, 3].sum() > 1.0)
    assert felt >= 20          # steps that press: the comparison is not of zeros


def test_a_contact_carried_along_matters():
    """Without carrying each contact along with its body (h=0) the points differ from the CPU
    skin's on steps where the hands move while pressing: the carrying is tested above."""
    env = high_five_v0.parallel_env(touch=True)
    env.reset(seed=0)
    system = env.unwrapped.system("touch")
    m = env.unwrapped.world.model
    skin = BatchedSkin(system, m, 1, torch, "cpu")
    worst = 0.0
    for e in _episode(env, 0):
        rows, data = _cpu_rows(m, e.unwrapped.world.data)
        skin.feel(rows, data, h=0.0)
        want = BatchedSkin.reading(system)[:-1, 3]
        worst = max(worst, float(np.abs(skin.acc[0, :-1, 3].numpy() - want).max()))
    assert worst > 1e-3


def test_touch_is_observed_on_the_device_in_the_cpu_layout():
    """The batched env's learners observe ``touch`` in the CPU space (size, bounds); off with
    ``touch=False``; a bad value is refused."""
    env = selfbody_v0.parallel_env()
    tenv = BatchedTaskEnv(env, 2, device="cpu", seed=0)
    space, _ = device_spaces(tenv, "infant_0")
    assert space["touch"] == env.observation_space("infant_0")["touch"]
    obs, _ = tenv.reset(seed=0)
    assert obs["infant_0"]["touch"].shape == (2,) + space["touch"].shape
    off = BatchedEnv(high_five_v0.parallel_env(), 1, device="cpu", touch=False)
    assert all(s.name != "touch" for senses in off.senses for s in senses)
    with pytest.raises(ValueError, match="touch='yes'"):
        BatchedEnv(high_five_v0.parallel_env(), 1, device="cpu", touch="yes")


@pytest.fixture(scope="module")
def selfbody_touch():
    """Scripted self-body episodes in 2 worlds, the hand aimed at the hip in one and at the
    right thigh in the other (:data:`PRESSED`; the task's target, the head, is not touched, so
    the hand keeps pressing), each world's state copied from its CPU env before every step:
    per step, the worlds whose CPU episode goes on, and the device and CPU touch
    observations."""
    make = _selfbody
    tenv = BatchedTaskEnv(make(), 2, device="cpu", seed=4)
    reset, _ = tenv.reset(seed=4)
    cpus, pols, obs = [], [], []
    for w in range(tenv.nworld):
        c = make()
        o, _ = c.reset(seed=tenv.seed_of(w))     # the reset reading is the CPU's
        np.testing.assert_allclose(reset["infant_0"]["touch"][w].numpy(), o["infant_0"]["touch"],
                                   atol=1e-4)
        pol = _aimed(PRESSED[w])()
        pol.reset(c.unwrapped, "infant_0", np.random.default_rng(w))
        assert pol.planned_steps < 120, (PRESSED[w], pol.planned_steps)   # presses 80+ steps
        cpus.append(c), pols.append(pol), obs.append(o)
    records, live = [], [True] * tenv.nworld
    for _ in range(200):
        acts = np.zeros((tenv.nworld, tenv.n_controls("infant_0")), np.float32)
        for w, (c, pol) in enumerate(zip(cpus, pols)):
            if live[w]:
                acts[w] = _motors(pol.act(c.unwrapped, "infant_0", obs[w].get("infant_0")))
        tenv.batched.load(range(tenv.nworld), [tenv.batched.snapshot(c.unwrapped) for c in cpus])
        dev, *_ = tenv.step({"infant_0": acts}, autoreset=False)
        step = {}
        for w, c in enumerate(cpus):
            if not live[w]:
                continue
            obs[w], _, term, trunc, _ = c.step({"infant_0": acts[w]})
            step[w] = (dev["infant_0"]["touch"][w].numpy().copy(), obs[w]["infant_0"]["touch"])
            live[w] = not (term["infant_0"] or trunc["infant_0"])
        records.append(step)
    return records


def test_the_touch_observed_on_the_device_is_within_ten_percent_of_the_cpu_skin(
        selfbody_touch):
    """Summed over the points: over each episode and in each step where the CPU skin feels
    more than 5 N, the device's touch is within 10 % of the CPU observation's."""
    for w in range(2):
        pairs = [r[w] for r in selfbody_touch if w in r]
        dev = np.array([d.sum() for d, _ in pairs])
        cpu = np.array([c.sum() for _, c in pairs])
        pressed = cpu > 5.0
        rel = np.abs(dev - cpu)[pressed] / cpu[pressed]
        print(f"world {w} ({PRESSED[w]}): episode sum {cpu.sum():.1f} N, device "
              f"{abs(dev.sum() - cpu.sum()) / max(cpu.sum(), 1e-9):.2%} apart; {pressed.sum()} "
              f"steps above 5 N, largest {rel.max(initial=0.0):.2%}")
        assert cpu.sum() > 100.0                       # the body presses
        assert abs(dev.sum() - cpu.sum()) <= 0.10 * cpu.sum()
        assert pressed.sum() >= 10, "the hand does not press hard enough for the comparison"
        np.testing.assert_array_less(np.abs(dev - cpu)[pressed], 0.10 * cpu[pressed])


def test_touch_is_felt_where_the_cpu_skin_feels_it(selfbody_touch):
    """The points that carry 90 % of the CPU skin's force over an episode carry most of the
    device's: the device feels the touch in the same places."""
    for w in range(2):
        pairs = [r[w] for r in selfbody_touch if w in r]
        dev = sum(d for d, _ in pairs)
        cpu = sum(c for _, c in pairs)
        order = np.argsort(cpu)[::-1]
        top = order[:np.searchsorted(np.cumsum(cpu[order]), 0.9 * cpu.sum()) + 1]
        print(f"world {w}: the CPU's top points carry {dev[top].sum() / dev.sum():.1%} of the "
              "device's force")
        assert dev[top].sum() >= 0.8 * dev.sum()
