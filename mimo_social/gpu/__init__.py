"""A GPU-batched backend on MuJoCo Warp: N worlds of one scene stepped together
(:class:`~mimo_social.gpu.batched.BatchedEnv`), on a GPU when Warp sees one, else on Warp's CPU
device; with a task's logic, partners and autoreset
(:class:`~mimo_social.gpu.task_env.BatchedTaskEnv`), as a Gymnasium vector env
(:class:`~mimo_social.gpu.vector.GymVectorEnv`) or a TorchRL env
(:class:`~mimo_social.gpu.torchrl_env.TorchRLEnv`, imported on first use: it needs torchrl);
touch per body part (:class:`~mimo_social.gpu.touch.BatchedTouch`) and the skin's points, the
learners' ``touch`` (:class:`~mimo_social.gpu.skin.BatchedSkin`); the eyes, MuJoCo Warp's
batch renderer (:class:`~mimo_social.gpu.eyes.BatchedEyes`) and the expressions they see
(:class:`~mimo_social.gpu.faces.BatchedFaces`); resets from kept starts
(:class:`~mimo_social.gpu.reset_bank.ResetBank`).
Needs the ``gpu`` extra; what runs on the device and what does not: docs/gpu.md."""

from .batched import DERIVED_FIELDS, STATE_FIELDS, BatchedEnv
from .contacts import BatchedContacts
from .controls import SUPPORTED, AgentControls, check_actuation
from .device import describe, has_gpu, pick_device, require
from .eyes import BatchedEyes, BatchedEyeSense
from .faces import BatchedFaces
from .partners import BatchedHandOffer, batched_partner
from .proprioception import BatchedProprioception
from .reset_bank import ResetBank
from .skin import BatchedSkin, BatchedTouchSense
from .task_env import BatchedTaskEnv
from .tasks import (TASKS, BatchedFreePlay, BatchedHighFive, BatchedReach, BatchedSelfBody,
                    BatchedTask, batched_task)
from .touch import BatchedTouch
from .vector import GymVectorEnv, device_spaces
from .vestibular import BatchedVestibular

__all__ = ["BatchedEnv", "BatchedTaskEnv", "GymVectorEnv", "TorchRLEnv", "AgentControls",
           "BatchedContacts", "BatchedEyes", "BatchedEyeSense", "BatchedFaces", "BatchedFreePlay",
           "BatchedHandOffer", "BatchedHighFive",
           "BatchedProprioception", "BatchedReach", "BatchedSelfBody", "BatchedSkin",
           "BatchedTask", "BatchedTouch", "BatchedTouchSense", "BatchedVestibular",
           "DERIVED_FIELDS", "STATE_FIELDS", "SUPPORTED", "TASKS", "batched_partner",
           "batched_task", "check_actuation", "describe", "device_spaces", "has_gpu",
           "pick_device", "require", "ResetBank"]


def __getattr__(name):
    if name == "TorchRLEnv":   # torchrl is imported only when asked for
        from .torchrl_env import TorchRLEnv
        return TorchRLEnv
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
