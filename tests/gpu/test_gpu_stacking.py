"""Captured starts as rows (:mod:`mimo_social.gpu.stacking`): stacked leaf by leaf, carried to
the device and indexed there; a reset bank keeps its starts so, on the env's device; loading
stacked rows gives the worlds what loading the snapshots one by one gives."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

import torch  # noqa: E402

from mimo_social.envs import high_five_v0  # noqa: E402
from mimo_social.gpu import BatchedEnv, BatchedTaskEnv  # noqa: E402
from mimo_social.gpu.stacking import rows_to, stack_rows, take_rows  # noqa: E402


def test_rows_are_stacked_leaf_by_leaf_moved_and_taken():
    items = [{"a": np.full(3, k, float), "b": [k, None, (np.eye(2) * k, k + 0.5)]}
             for k in range(4)]
    rows = stack_rows(items)
    assert rows["a"].shape == (4, 3) and rows["b"][1] is None
    assert isinstance(rows["b"][2], tuple) and rows["b"][2][0].shape == (4, 2, 2)
    moved = rows_to(rows, torch, "cpu")
    assert isinstance(moved["a"], torch.Tensor) and moved["b"][1] is None
    got = take_rows(moved, torch.tensor([3, 1]))
    assert got["a"][:, 0].tolist() == [3.0, 1.0] and got["b"][0].tolist() == [3, 1]
    assert got["b"][2][1].tolist() == [3.5, 1.5]
    with pytest.raises(ValueError, match="None in some captures and not in others"):
        stack_rows([{"x": None}, {"x": 1.0}])


def test_loading_stacked_rows_equals_loading_snapshots_one_by_one():
    env = high_five_v0.parallel_env()
    a, b = (BatchedEnv(env, 3, device="cpu", seed=0) for _ in range(2))
    snaps = []
    for seed in (5, 6):
        env.reset(seed=seed)
        snaps.append(a.snapshot(env))
    got_a = a.load([2, 0], snaps)
    got_b = b.load_rows(np.array([2, 0]), rows_to(stack_rows(snaps), torch, "cpu"))
    for agent in a.agents:
        for k in got_a[agent]:
            np.testing.assert_array_equal(got_a[agent][k][[2, 0]].numpy(),
                                          got_b[agent][k][[2, 0]].numpy(), err_msg=k)
    np.testing.assert_array_equal(a.qpos.numpy(), b.qpos.numpy())
    assert not np.array_equal(a.qpos[0].numpy(), a.qpos[1].numpy())   # world 1 untouched


def test_a_reset_bank_keeps_its_starts_on_the_device():
    tenv = BatchedTaskEnv(high_five_v0.scripted_env(max_steps=2), 2, device="cpu", seed=0,
                          reset_bank=3)
    snaps, task, partners = tenv.bank.rows(torch.tensor([2, 0]))
    assert isinstance(snaps["qpos"], torch.Tensor) and snaps["qpos"].shape[0] == 2
    assert snaps["qpos"].device == tenv.batched.qpos.device
    assert isinstance(partners["infant_1"]["kp"], torch.Tensor)
