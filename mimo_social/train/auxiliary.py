"""An auxiliary label while cloning: the policy also trained to name a task's info.

``bc_kwargs`` ``aux_label`` (an info key, e.g. joint attention's ``"target"``: the toy the
partner looks at, -1 while it looks at none) and ``aux_weight`` (1.0): while the demonstrations
and DAgger's episodes play, each recorded pair keeps the step's ``info[aux_label]`` (an integer
class; a negative value, a missing key or ``None``: no label); every cloning minibatch (the warm
start, DAgger's rounds, the cloning kept during RL) then adds ``aux_weight`` x the cross-entropy
of a linear head on the actor's last hidden layer (the latent its action is read from, so the
label's gradient runs through the actor's layers and its features extractor: the eyes' CNN)
naming that class, over the labelled pairs of the batch. The head is not part of the policy (saved
models are unchanged, nothing is observed that was not before): the label only shapes what the
features extractor learns to read. Where a task's skill hangs on one fact the images show
faintly (which toy the partner looks at: its eyes about 3 pixels across), cloning the actions
alone teaches that fact through the controller's motor commands only; the label teaches it
directly (an auxiliary task, Jaderberg et al. 2017, "Reinforcement learning with unsupervised
auxiliary tasks", here supervised by the task's own bookkeeping).

The label is training signal, never observation (the task reads it from the world, as its
reward does). One head per policy object, made at its first use with as many classes as the
largest label seen + 1 and kept for the policy's later cloning (a later label beyond it is
refused by name).
"""

from __future__ import annotations

import math
import weakref
from typing import Any, Mapping

import numpy as np

from .tasks import TrainInputError

__all__ = ["AUX_DEFAULTS", "check_aux", "label_of", "AuxiliaryHead", "aux_head",
           "features_and_distribution"]

#: ``bc_kwargs``' auxiliary-label settings and their defaults
AUX_DEFAULTS = {"aux_label": None, "aux_weight": 1.0}

_HEADS: "weakref.WeakKeyDictionary[Any, AuxiliaryHead]" = weakref.WeakKeyDictionary()


def check_aux(settings: dict, algo: str) -> None:
    """``aux_label`` and ``aux_weight`` of the warm start's settings checked (a TrainInputError
    naming the value and what is allowed)."""
    key, weight = settings["aux_label"], settings["aux_weight"]
    if key is not None and algo != "ppo":
        raise TrainInputError(f"bc_kwargs: aux_label={key!r} with algo {algo!r}; allowed: ppo "
                              "(the head sits on an actor-critic policy's actor)")
    if key is not None and (not isinstance(key, str) or not key):
        raise TrainInputError(f"bc_kwargs: aux_label={key!r}; allowed: None or the name of an "
                              "info key of the task holding an integer class (e.g. "
                              "joint_attention's 'target')")
    if isinstance(weight, bool) or not isinstance(weight, (int, float)) \
            or not 0 < weight < math.inf:
        raise TrainInputError(f"bc_kwargs: aux_weight={weight!r}; allowed: a number > 0 (the "
                              "auxiliary cross-entropy's weight beside the cloning loss)")
    settings["aux_weight"] = float(weight)


def label_of(info: Mapping[str, Any], key: str) -> int:
    """The step's class under ``key`` (-1: none: missing, None or negative); a TrainInputError
    for a value that is not a whole number (an integer, or a float such as 2.0: some wrappers
    pass infos on as floats)."""
    value = info.get(key)
    if value is None:
        return -1
    whole = isinstance(value, (int, np.integer)) or (
        isinstance(value, (float, np.floating)) and math.isfinite(value)
        and float(value) == round(float(value)))
    if isinstance(value, (bool, np.bool_)) or not whole:
        raise TrainInputError(f"bc_kwargs: aux_label={key!r}: the info's value {value!r} is not "
                              "an integer class; allowed: an info key holding integers (-1 or "
                              "below: no label)")
    return max(-1, int(round(float(value))))


class AuxiliaryHead:
    """A linear head on an actor-critic policy's actor latent naming an integer label, and its
    loss."""

    def __init__(self, policy, n_classes: int):
        import torch

        self.n_classes = int(n_classes)
        width = int(policy.mlp_extractor.latent_dim_pi)
        self.linear = torch.nn.Linear(width, self.n_classes).to(policy.device)

    def parameters(self):
        return self.linear.parameters()

    def loss(self, latent, labels: np.ndarray):
        """The mean cross-entropy over the labelled rows (0 where no row has a label)."""
        import torch

        labels = np.asarray(labels)
        if labels.size and int(labels.max()) >= self.n_classes:
            raise TrainInputError(f"bc_kwargs: aux_label: class {int(labels.max())} appeared "
                                  f"after the head was made for {self.n_classes} classes; "
                                  "allowed: the classes of the first demonstrations")
        keep = labels >= 0
        if not keep.any():
            return latent.sum() * 0.0
        target = torch.as_tensor(labels[keep], device=latent.device, dtype=torch.long)
        return torch.nn.functional.cross_entropy(self.linear(latent[torch.as_tensor(keep)]),
                                                 target)

    def accuracy(self, latent, labels: np.ndarray) -> tuple[int, int]:
        """Right and labelled counts of the head's choices."""
        import torch

        keep = np.asarray(labels) >= 0
        if not keep.any():
            return 0, 0
        with torch.no_grad():
            chosen = self.linear(latent[torch.as_tensor(keep)]).argmax(1).cpu().numpy()
        return int((chosen == np.asarray(labels)[keep]).sum()), int(keep.sum())


def aux_head(policy, labels: np.ndarray) -> AuxiliaryHead:
    """The policy's auxiliary head, made at the first call (classes: the largest label + 1);
    a TrainInputError when no pair has a label."""
    head = _HEADS.get(policy)
    if head is None:
        top = int(np.max(labels)) if len(labels) else -1
        if top < 0:
            raise TrainInputError("bc_kwargs: aux_label: no recorded step had a label (every "
                                  "value missing, None or negative); allowed: an info key the "
                                  "task fills with integer classes")
        head = _HEADS[policy] = AuxiliaryHead(policy, top + 1)
    return head


def features_and_distribution(policy, obs):
    """The actor's latent of ``obs`` (its last hidden layer, the output of
    ``mlp_extractor.policy_net``, caught by a forward hook) and the action distribution
    ``policy.get_distribution(obs)`` made from it."""
    caught = []
    hook = policy.mlp_extractor.policy_net.register_forward_hook(
        lambda module, args, output: caught.append(output))
    try:
        dist = policy.get_distribution(obs)
    finally:
        hook.remove()
    return caught[-1], dist
