"""The Gaussian policy's log-std after a behaviour-cloning warm start (``bc_kwargs``
``log_std``): its size checked against the learner, and set (one module for the feed-forward
clone, :mod:`~mimo_social.train.demonstrations`, and the recurrent one,
:mod:`~mimo_social.train.sequence_cloning`)."""

from __future__ import annotations

from .tasks import TrainInputError

__all__ = ["check_log_std_size", "set_log_std"]


def check_log_std_size(model, log_std) -> None:
    """A TrainInputError unless ``log_std`` (a number, a list or None) fits ``model``'s
    policy: a list needs one value per Gaussian action dimension (with categorical heads: per
    motor) and a Gaussian policy."""
    if not isinstance(log_std, (list, tuple)):
        return
    std = getattr(model.policy, "log_std", None)
    size = None if std is None else int(std.numel())
    if size != len(log_std):
        from .categorical_heads import has_categorical_heads
        what = ("its policy has no Gaussian log-std" if size is None else f"{size} of them"
                + ("; the motors: the face and voice are categorical heads"
                   if has_categorical_heads(model.policy) else ""))
        raise TrainInputError(
            f"bc_kwargs: log_std={list(log_std)!r} has {len(log_std)} values; allowed: one per "
            f"action dimension of this learner ({what})")


def set_log_std(policy, log_std) -> None:
    """The Gaussian policy's log-std set to ``log_std``: one number for every dimension, or
    one per dimension (:func:`check_log_std_size` checked the size)."""
    import torch

    with torch.no_grad():
        if isinstance(log_std, (list, tuple)):
            policy.log_std.copy_(torch.as_tensor(log_std, dtype=policy.log_std.dtype))
        else:
            policy.log_std.fill_(float(log_std))
