"""Where the batched worlds run: MuJoCo Warp and its device, imported on first use.

The ``gpu`` extra (``pip install -e ".[gpu]"``) brings ``mujoco-warp`` and ``warp-lang``; the
batched env also needs ``torch`` (the ``train`` extra), whose tensors carry actions and
observations. :func:`pick_device` takes ``"cuda"`` when Warp sees a GPU, else Warp's CPU device,
so the same code runs on a laptop, in CI and on an accelerator.
"""

from __future__ import annotations

__all__ = ["require", "pick_device", "describe", "has_gpu", "INSTALL"]

INSTALL = 'pip install -e ".[gpu]" (mujoco-warp 4.0.0, warp-lang >= 1.19; torch: the train extra)'


def require():
    """``(warp, mujoco_warp, torch)``, imported; an ImportError saying how to install them."""
    try:
        import mujoco_warp
        import torch
        import warp
    except ImportError as e:
        raise ImportError(f"the GPU backend needs mujoco-warp, warp-lang and torch ({e}); "
                          f"install them with {INSTALL}") from e
    warp.config.quiet = True
    return warp, mujoco_warp, torch


def has_gpu() -> bool:
    """Whether Warp sees a CUDA device."""
    wp, _, _ = require()
    return bool(wp.is_cuda_available())


def pick_device(device: str | None = None) -> str:
    """The Warp device to use: ``device`` as given (``"cpu"``, ``"cuda"``, ``"cuda:1"``), or,
    when None, ``"cuda"`` where Warp sees a GPU, else ``"cpu"``. Asking for ``"cuda"`` without
    one is a ValueError that says so."""
    wp, _, _ = require()
    if device is None:
        return "cuda" if wp.is_cuda_available() else "cpu"
    if not isinstance(device, str) or not (device == "cpu" or device.startswith("cuda")):
        raise ValueError(f"device={device!r} not allowed; allowed: None (a GPU when there is "
                         f"one, else the CPU), 'cpu', 'cuda' or 'cuda:N'")
    if device.startswith("cuda") and not wp.is_cuda_available():
        raise ValueError(f"device={device!r}: Warp sees no GPU here; use device='cpu' or None")
    return device


def describe(device: str) -> str:
    """One line naming the device: the GPU's name, or ``"no GPU: Warp's CPU device"``."""
    wp, _, _ = require()
    d = wp.get_device(device)
    if d.is_cuda:
        return f"GPU: {d.name} ({d.alias})"
    return "no GPU: Warp's CPU device"
