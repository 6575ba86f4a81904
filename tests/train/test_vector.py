"""The process vector env when a worker fails: a clear error naming the worker, never a raw
pipe error or a step that waits forever."""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest

from mimo_social.envs import reach_v0
from mimo_social.train.vector import SpawnConcatVecEnv, sb3_vec_env


def _remote(**kwargs):
    vec = sb3_vec_env(reach_v0.parallel_env, n_envs=2, n_cpus=2, start_method="spawn")
    vec.reset()
    return vec


def _actions(vec):
    return np.stack([vec.action_space.sample() for _ in range(vec.num_envs)])


def test_a_worker_killed_between_steps_is_named_in_a_runtime_error():
    vec = _remote()
    try:
        proc = vec.gym_venv._procs[1]
        proc.kill()
        proc.join(5)
        with pytest.raises(RuntimeError, match=rf"worker 1 \(pid {proc.pid}\) died \(exit code "
                                               r"-9\).*make a new one"):
            vec.step(_actions(vec))
    finally:
        vec.close()


def test_a_stopped_worker_is_a_timeout_error_not_a_hang():
    vec = _remote()
    proc = vec.gym_venv._procs[0]
    try:
        vec.gym_venv.timeout_s = 2.0
        os.kill(proc.pid, signal.SIGSTOP)
        with pytest.raises(RuntimeError, match=r"worker 0 .* did not answer within 2 s"):
            vec.step(_actions(vec))
    finally:
        os.kill(proc.pid, signal.SIGCONT)
        vec.close()


def test_timeout_must_be_positive():
    with pytest.raises(ValueError, match=r"timeout_s=0.*positive"):
        SpawnConcatVecEnv(reach_v0.parallel_env, 1, 1, timeout_s=0)
