"""Touch on the device per body part (:class:`mimo_social.gpu.touch.BatchedTouch`) against the CPU
skin, on Warp's CPU device: scripted high five episodes (both infants run ``HighFiveController``;
full-body skins, ``touch=True``), each world's state copied from its CPU env before every step,
so that what is compared is one step of contact physics and the reading of its forces.

Measured (seeds 0 and 1, 150 steps: the palms pressing in world 0, infant_0's right arm on its
own body in world 1): each body part's summed normal force added up over the episode within
6.5 % of the skin's; each agent's summed force in a step within 3.3 % wherever it exceeds 5 N
(14 % at 3 N: how the float32 solver splits the force among the contacts of two hands); a part's
force in one step can differ by more (73 % measured, at 1.4 N of the fingers) as the split
between the hand and the fingers moves. Who presses which part (the agent itself, the other
infant, an object) is the CPU skin's ``touched_by`` wherever the part feels more than 1 N.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.envs import high_five_v0  # noqa: E402
from mimo_social.gpu import BatchedTaskEnv, BatchedTouch  # noqa: E402
from mimo_social.tasks.high_five import HighFiveController  # noqa: E402

SEEDS = (0, 1)
STEPS = 150


def _make():
    return high_five_v0.parallel_env(touch=True)


def _motors(a):
    return a["motors"] if isinstance(a, dict) else np.asarray(a, np.float32)


@pytest.fixture(scope="module")
def episodes():
    """Per step and world: the device's (nparts,) forces and (nparts, sources) table, and the
    CPU skin's per-part sums and touched_by, for every agent."""
    tenv = BatchedTaskEnv(_make(), len(SEEDS), device="cpu", seed=SEEDS[0])
    touch = BatchedTouch(tenv.batched)
    tenv.reset(seed=SEEDS[0])
    cpus, pols, obs = [], [], []
    for w in range(tenv.nworld):
        c = _make()
        o, _ = c.reset(seed=tenv.seed_of(w))
        p = {a: HighFiveController() for a in c.possible_agents}
        for a, pol in p.items():
            pol.reset(c.unwrapped, a, np.random.default_rng(w))
        cpus.append(c), pols.append(p), obs.append(o)
    records = []
    for _ in range(STEPS):
        acts = {a: np.zeros((tenv.nworld, tenv.n_controls(a)), np.float32)
                for a in tenv.learners}
        given = []
        for w, (c, p) in enumerate(zip(cpus, pols)):
            given.append({a: _motors(pol.act(c.unwrapped, a, obs[w].get(a)))
                          for a, pol in p.items()})
            for a in tenv.learners:
                acts[a][w] = given[w][a]
        tenv.batched.load(range(tenv.nworld), [tenv.batched.snapshot(c.unwrapped) for c in cpus])
        tenv.step(acts, autoreset=False)
        table = touch.by_source().numpy().copy()
        step = []
        for w, c in enumerate(cpus):
            space = c.action_space("infant_0")
            obs[w], *_ = c.step({a: {"motors": given[w][a], "expression": 0}
                                 if hasattr(space, "spaces") else given[w][a]
                                 for a in c.possible_agents})
            skin = c.unwrapped.system("touch")
            cpu = {a: {part: float(v["normal_force"].sum()) for part, v in skin.view(a).items()}
                   for a in c.possible_agents}
            who = {a: skin.touched_by(i) for i, a in enumerate(c.possible_agents)}
            step.append((table[w], cpu, who))
        records.append(step)
    return touch, records


def test_gpu_touch_parts_are_the_skins_parts(episodes):
    touch, records = episodes
    _, cpu, _ = records[0][0]
    for a, parts in cpu.items():
        assert set(parts) <= {p for b, p in touch.parts if b == a}   # the skin's parts
    assert touch.sources == ["object", "infant_0", "infant_1"]
    with pytest.raises(KeyError, match="'infant_0' has no body part 'tail'"):
        touch.index("infant_0", "tail")


def test_gpu_touch_summed_forces_are_the_cpu_skins(episodes):
    touch, records = episodes
    impulse_dev, impulse_cpu, felt = {}, {}, 0
    for step in records:
        for w, (table, cpu, _) in enumerate(step):
            forces = table.sum(-1)
            for a, parts in cpu.items():
                dev = {p: float(forces[touch.index(a, p)]) for p in parts}
                for p in parts:
                    impulse_dev[w, a, p] = impulse_dev.get((w, a, p), 0.0) + dev[p]
                    impulse_cpu[w, a, p] = impulse_cpu.get((w, a, p), 0.0) + parts[p]
                total_cpu, total_dev = sum(parts.values()), sum(dev.values())
                if total_cpu > 5.0:
                    felt += 1
                    assert abs(total_dev - total_cpu) <= 0.1 * total_cpu, (w, a, total_cpu,
                                                                           total_dev)
    assert felt >= 10         # the episodes press hands (and an arm on the body) for a while
    pressed = [k for k, v in impulse_cpu.items() if v > 5.0]
    assert {k[0] for k in pressed} == {0, 1}
    for k in pressed:
        assert abs(impulse_dev[k] - impulse_cpu[k]) <= 0.1 * impulse_cpu[k], (k, impulse_cpu[k],
                                                                              impulse_dev[k])
    assert all(impulse_dev[k] < 1.0 for k, v in impulse_cpu.items() if v == 0.0)


def test_gpu_touch_says_who_touched_whom_as_the_cpu_skin(episodes):
    touch, records = episodes
    seen = set()
    for step in records:
        for table, cpu, who in step:
            for a, parts in cpu.items():
                for p, f in parts.items():
                    if f <= 1.0:
                        continue
                    row = table[touch.index(a, p)]
                    entry = who[a][p]
                    want = {"object"} if entry["object"] else set()
                    want |= set(entry["agents"]) | ({a} if entry["self"] else set())
                    got = {s for s, v in zip(touch.sources, row) if v > 1e-6}
                    assert got == want, (a, p, got, want, row)
                    seen |= {(a, s) for s in got}
    # the palms meet (each infant touched by the other) and infant_0 touches itself
    assert {("infant_0", "infant_1"), ("infant_1", "infant_0"), ("infant_0", "infant_0")} <= seen
