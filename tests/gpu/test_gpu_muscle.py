"""Muscle actuation on the device (:mod:`mimo_social.gpu.muscles`) against the CPU env, on Warp's
CPU device: the batched worlds and one CPU env per world, reset alike, given the same muscle
controls (``actuation="muscle"``: 2 controls in [0, 1] per axis).

Measured (docs/gpu.md): with random commands redrawn every step, qpos within 1e-7 after the first
step, 1e-5 after three and 1.4e-4 / 1.9e-4 after 20 (one infant with mittens; two with five
fingers and delays), the activations and forces the proprioception reports close behind;
with no commands the muscles at rest leave the floppy body to sink and its float32 physics
parts faster (1e-7 over three steps, 1.0e-3 / 2.3e-3 after 20; the worlds part by 200). A
world loaded with a CPU state taken mid-episode carries that state's activations (without
them the next step is 1e-3 off).
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from test_gpu_agreement import _make, _motors, no_commands, run  # noqa: E402 (on the path)

from mimo_social.envs import reach_v0  # noqa: E402
from mimo_social.gpu import BatchedEnv, GymVectorEnv, device_spaces  # noqa: E402

CASES = [(1, "mitten", None), (2, "five_fingers", "developmental")]
IDS = ["1-mitten-nodelay", "2-five_fingers-delays"]


def _muscle(n, hands, delays):
    return lambda: _make(n, hands, delays, actuation="muscle")


def muscle_commands(seed=1):
    rng = np.random.default_rng(seed)

    def draw(batched, t):
        return {a: rng.uniform(0, 1, (batched.nworld, batched.n_controls(a))).astype(np.float32)
                for a in batched.agents}
    return draw


@pytest.mark.parametrize("n, hands, delays", CASES, ids=IDS)
def test_gpu_muscles_at_rest_agree_while_the_body_settles(n, hands, delays):
    """No commands: the muscles at rest leave the joints 5 % of the spring-damper model's
    stiffness, and the floppy body sinks: the float32 physics parts from the CPU's faster than
    a spring-damper body's (a device world without any muscle torque parts as fast: 1.8e-3
    after 20 steps; the rest torques are below 1e-3 N m). Within 1e-6 over the first three
    steps and 5e-3 after 20."""
    diffs, _ = run(_muscle(n, hands, delays), 20, no_commands, worlds=1)
    errors = diffs.max(axis=(1, 2))
    assert errors[:3].max() < 1e-6 and errors[19] < 5e-3, errors


def test_gpu_muscles_follow_random_commands_as_on_the_cpu():
    """Each world its own random muscle commands: qpos, and the activations and forces the
    proprioception reports (its ``actuation`` part), stay with the CPU env's (the joint
    velocities and torques, more sensitive, within 5e-2)."""
    make = _muscle(1, "mitten", None)
    draw = muscle_commands()
    batched = BatchedEnv(make(), 2, device="cpu", seed=0)
    batched.reset()
    cpus = [make() for _ in range(2)]
    for c in cpus:
        c.reset(seed=0)
    part = dict(cpus[0].senses[0][0].slices)["actuation"]
    worst = np.zeros((3, 20))         # qpos, the actuation part, all of proprioception
    for t in range(20):
        acts = draw(batched, t)
        obs, _ = batched.step(acts)
        for w, c in enumerate(cpus):
            cpu, *_ = c.step({a: _motors(c, a, u[w]) for a, u in acts.items()})
            d = np.abs(obs["infant_0"]["proprioception"][w].numpy()
                       - cpu["infant_0"]["proprioception"])
            q = np.abs(batched.qpos[w].numpy() - c.world.data.qpos).max()
            worst[:, t] = np.maximum(worst[:, t], [q, d[part].max(), d.max()])
    assert worst[0, 0] < 1e-5 and worst[0, 19] < 1e-3, worst[0]
    assert worst[1, 0] < 1e-6 and worst[1].max() < 5e-3, worst[1]
    assert worst[2].max() < 5e-2, worst[2]
    assert worst[0, 19] > 0.0          # (the worlds moved: the comparison is not of rest)


def test_gpu_muscle_state_travels_with_a_loaded_world():
    """A CPU state taken after 10 steps of commands, loaded into a world, steps on as the CPU
    env does (its activations carried); the same state with the activations at rest does not."""
    make = _muscle(1, "mitten", None)
    cpu = make()
    cpu.reset(seed=0)
    rng = np.random.default_rng(3)
    n = cpu.action_space("infant_0")["motors"].shape[0] if hasattr(
        cpu.action_space("infant_0"), "spaces") else cpu.action_space("infant_0").shape[0]
    for _ in range(10):
        cpu.step({"infant_0": _motors(cpu, "infant_0", rng.uniform(0, 1, n).astype(np.float32))})
    u = np.full((1, n), 0.5, np.float32)
    batched = BatchedEnv(make(), 2, device="cpu", seed=0)
    snap = batched.snapshot(cpu)
    rest = dict(snap, muscles=[tuple(np.zeros_like(x) for x in m) for m in snap["muscles"]])
    batched.load([0, 1], [snap, rest])
    batched.step({"infant_0": np.repeat(u, 2, axis=0)})
    cpu.step({"infant_0": _motors(cpu, "infant_0", u[0])})
    carried = np.abs(batched.qpos[0].numpy() - cpu.world.data.qpos).max()
    at_rest = np.abs(batched.qpos[1].numpy() - cpu.world.data.qpos).max()
    assert carried < 1e-5 < 1e-3 < at_rest, (carried, at_rest)


def test_gpu_muscles_in_a_task_env_observe_their_activations():
    """Reach with muscles on the device: 2 controls in [0, 1] per axis, the proprioception in
    the CPU env's space (its actuation part: activations and forces)."""
    env = reach_v0.parallel_env(actuation="muscle")
    v = GymVectorEnv(env, 2, device="cpu", seed=0)
    space, act = device_spaces(v.tenv, "infant_0")
    assert space["proprioception"] == env.observation_space("infant_0")["proprioception"]
    assert act.shape == (2 * 8,) and float(act.low.min()) == 0.0
    obs, _ = v.reset(seed=0)
    obs, *_ = v.step(np.ones((2, 16), np.float32))
    assert obs["proprioception"].shape == (2,) + space["proprioception"].shape
