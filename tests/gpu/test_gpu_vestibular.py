"""The vestibular sense on the device (issue 34) against the CPU env, on Warp's CPU device: the
gyro and accelerometer MuJoCo Warp computes into ``sensordata``, in the CPU sense's layout,
without and with the developmental delay (MuJoCo's own sensor delay: 1 control step at 18
months), over steps with random commands in the whole Box, each world its own.

One infant in free play, its body free: random commands swing the head (the gyro reads up to
a few rad/s) while it settles on the floor. Tolerances: 1e-3 rad/s and 2e-2 m/s^2 (float32
physics against float64, the contact and friction-loss constraints solved in float32: the
accelerometer reads the constraint forces' accelerations); measured: see the printout.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.envs import free_play_v0  # noqa: E402
from mimo_social.gpu import BatchedEnv  # noqa: E402

W = 2
STEPS = 8


def _cpu_step(env, actions):
    return env.step({a: {"motors": u, "expression": 0} for a, u in actions.items()})[0]


@pytest.mark.parametrize("delays", [None, "developmental"])
def test_gpu_vestibular_is_the_cpu_senses(delays):
    make = lambda: free_play_v0.parallel_env(n_agents=1, delays=delays)  # noqa: E731
    batched = BatchedEnv(make(), W, device="cpu", seed=0)
    cpus = [make() for _ in range(W)]
    obs = batched.reset()
    cpu_obs = [c.reset(seed=0)[0] for c in cpus]
    k = cpus[0].delay_steps("infant_0")["vestibular"]
    assert k == (1 if delays else 0)
    rng = np.random.default_rng(4)
    errs, seen = [], []
    for t in range(STEPS + 1):
        for w, c in enumerate(cpus):
            for a in batched.agents:
                got, want = obs[a]["vestibular"][w].numpy(), cpu_obs[w][a]["vestibular"]
                assert got.shape == want.shape == c.observation_space(a)["vestibular"].shape
                assert got.dtype == want.dtype == np.float32
                errs.append((np.abs(got[:3] - want[:3]).max(), np.abs(got[3:] - want[3:]).max()))
                seen.append(np.abs(want[:3]).max())
        if t == STEPS:
            break
        acts = {a: rng.uniform(-1, 1, (W, batched.n_controls(a))).astype(np.float32)
                for a in batched.agents}
        obs, _ = batched.step(acts)
        cpu_obs = [_cpu_step(c, {a: v[w] for a, v in acts.items()}) for w, c in enumerate(cpus)]
    errs = np.array(errs)
    print(f"delays={delays}: largest gyro / accel difference {errs.max(axis=0)}, largest "
          f"gyro reading {max(seen):.3g} rad/s")
    assert max(seen) > 0.1           # the head moves: the comparison is not of zeros
    assert errs[:, 0].max() < 1e-3 and errs[:, 1].max() < 2e-2, errs.max(axis=0)
