"""A GPU-batched backend on MuJoCo Warp: N worlds of one scene stepped together
(:class:`~mimo_social.gpu.batched.BatchedEnv`), on a GPU when Warp sees one, else on Warp's CPU
device. Needs the ``gpu`` extra; what runs on the device and what does not: docs/gpu.md."""

from .batched import STATE_FIELDS, BatchedEnv
from .controls import SUPPORTED, AgentControls, check_actuation
from .device import describe, has_gpu, pick_device, require
from .proprioception import BatchedProprioception

__all__ = ["BatchedEnv", "AgentControls", "BatchedProprioception", "STATE_FIELDS", "SUPPORTED",
           "check_actuation", "describe", "has_gpu", "pick_device", "require"]
