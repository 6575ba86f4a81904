"""The joint-attention probe's image shift (scripts/joint_attention_probe.py ``--augment``):
both eyes of a step move by the same offset, edges replicated, nothing else changes."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import torch

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "joint_attention_probe.py"


def _probe():
    spec = importlib.util.spec_from_file_location("joint_attention_probe", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_both_eyes_of_a_step_shift_together_and_the_vector_does_not():
    probe = _probe()
    n, pad = 6, 3
    left = torch.arange(n * 3 * 16 * 16, dtype=torch.float32).reshape(n, 3, 16, 16)
    batch = {"left_eye": left, "right_eye": left + 1.0, "vector": torch.ones(n, 5)}
    out = probe.shift_images(batch, ("left_eye", "right_eye"), pad, np.random.default_rng(0))
    assert out["left_eye"].shape == left.shape and torch.equal(out["vector"], batch["vector"])
    assert torch.equal(out["right_eye"], out["left_eye"] + 1.0)      # the same offset
    shifted = 0
    for i in range(n):          # each image is its original moved by one (dy, dx) in the pad
        padded = torch.nn.functional.pad(left[i:i + 1], (pad,) * 4, mode="replicate")[0]
        hits = [(dy, dx) for dy in range(2 * pad + 1) for dx in range(2 * pad + 1)
                if torch.equal(padded[:, dy:dy + 16, dx:dx + 16], out["left_eye"][i])]
        assert len(hits) == 1
        shifted += hits[0] != (pad, pad)
    assert shifted >= n - 1
