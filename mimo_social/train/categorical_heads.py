"""A policy whose face (and voice) is a categorical choice beside Gaussian motors (issue 30).

A learner with motors and a face takes the flat ``Box`` of
:class:`~mimo_social.core.wrappers.FlatActionWrapper`: its motors, then one logit per
expression (then, with a voice, one logit per sound kind and the loudness); the env picks the
largest logit. SB3's PPO treats that whole ``Box`` as one diagonal Gaussian, so the face is
chosen by the largest of seven noisy numbers: its probabilities are set by the logits' means
and one shared spread, cloning fits the logits' values (not the choice's likelihood), and at a
small log-std a face that is not the most likely one is never sampled.

``train(..., categorical_heads=True)`` (``--categorical-heads``; a recipe's ``[train]``) gives
the learner :class:`CategoricalHeadsPolicy` instead: the same network, the same flat ``Box``
and the same env, but each logit group (``ActionDecoder.categorical_groups``: the expression,
the voice) is a categorical distribution over its choices, and only the other dimensions
(motors, loudness) are Gaussian, with one learnt log-std each. A sampled action carries the
drawn choice as the decoder's own encoding (``LOGIT_HIGH`` for the chosen one, ``LOGIT_LOW``
for the others), so the env, the demonstrations (``ActionDecoder.encode``) and the rollout
buffer are unchanged; its log-probability is the Gaussian's over the motors plus each group's
categorical one of the choice (the largest value of the group), its entropy the sum, its mode
the motors' mean and each group's most likely choice.

Cloning (:mod:`~mimo_social.train.demonstrations`) with ``loss="mse"`` trains the motors' mean
by squared error and each group by cross-entropy on the controller's choice (:meth:`
CategoricalHeads.clone_loss`); ``loss="nll"`` is the negative log-likelihood of both. A list
``log_std`` then has one value per Gaussian dimension (the motors, not the logits).

For PPO and A2C (``ActorCriticPolicy``); refused for SAC (its actor is a squashed Gaussian),
RecurrentPPO, ``--mode independent`` and a learner whose action has no logit group.

Measured (issue 30, ninth session, docs/training/issue30/pilots/still_face_categorical and
contingency_categorical): with a categorical face the still-face learner's smiling follows the
phases (drop 0.53, recovery 0.46; Gaussian logits 0.38, 0.17); a face sampled afresh every
10-ms step still flickers where the teacher smiles in bouts timed by a clock the learner does
not sense (contingency: 18 smile onsets a second; Gaussian logits 8-10; the scripted detector
0.5-0.7).
"""

from __future__ import annotations

from typing import Sequence

import torch
from stable_baselines3.common.distributions import DiagGaussianDistribution, sum_independent_dims
from stable_baselines3.common.policies import ActorCriticPolicy
from torch import nn
from torch.distributions import Categorical, Normal

from ..core.action_decoder import LOGIT_HIGH, LOGIT_LOW, ActionDecoder
from .tasks import TrainInputError

__all__ = ["CategoricalHeads", "CategoricalHeadsPolicy", "check_categorical_heads", "check_groups",
           "learner_groups", "record_learner_groups", "has_categorical_heads",
           "CATEGORICAL_ALGOS"]

#: the algorithms whose policy can have categorical heads
CATEGORICAL_ALGOS = ("ppo", "a2c")


def check_categorical_heads(on, algo: str, mode: str | None) -> None:
    """A TrainInputError unless ``categorical_heads=on`` fits the run: a bool, and when on,
    PPO or A2C with one learner (a one-agent task, ``scripted``) or ``shared``."""
    if not isinstance(on, bool):
        raise TrainInputError(f"categorical_heads={on!r}; allowed: True or False")
    if not on:
        return
    if algo not in CATEGORICAL_ALGOS:
        raise TrainInputError(f"categorical_heads with algo {algo!r}; allowed: "
                              f"{', '.join(CATEGORICAL_ALGOS)} (actor-critic policies; SAC's "
                              "actor is a squashed Gaussian, RecurrentPPO's an LSTM policy)")
    if mode == "independent":
        raise TrainInputError("categorical_heads with --mode independent; allowed: one learner "
                              "(a one-agent task, --mode scripted) or --mode shared")


def check_groups(groups, action_dim: int) -> tuple[tuple[int, int], ...]:
    """``groups`` as ``((start, n), ...)``: each a run of ``n >= 2`` dimensions of the flat
    action, inside it, not overlapping, at least one; else a ValueError naming the group."""
    out = []
    for g in groups:
        if (not isinstance(g, (list, tuple)) or len(g) != 2
                or not all(isinstance(v, int) and not isinstance(v, bool) for v in g)):
            raise ValueError(f"categorical group {g!r}; allowed: (start, n), two integers")
        out.append((int(g[0]), int(g[1])))
    if not out:
        raise ValueError("categorical_groups=(); allowed: at least one (start, n) group")
    taken = set()
    for start, n in out:
        dims = set(range(start, start + n))
        if n < 2 or start < 0 or start + n > action_dim or dims & taken:
            raise ValueError(f"categorical group (start={start}, n={n}); allowed: n >= 2 "
                             f"dimensions within the action's {action_dim}, not overlapping "
                             "another group")
        taken |= dims
    return tuple(out)


def learner_groups(raw_space, who: str) -> list[list[int]]:
    """The logit groups of a learner's flat action (its raw action space, e.g. the task's
    ``Dict(motors, expression)``), as config.json records them; a TrainInputError naming the
    learner when it has none (a ``Box`` of motors, or a face-only learner: already
    categorical)."""
    decoder = ActionDecoder(raw_space)
    if decoder.discrete or not decoder.categorical_groups:
        what = ("its action is already one categorical choice (Discrete)" if decoder.discrete
                else "its action is a Box of motors")
        raise TrainInputError(f"categorical_heads: learner {who!r} has no logit group (face or "
                              f"voice) beside motors; {what}; allowed: a learner with a "
                              "Dict(motors, expression / voice) action")
    return [list(g) for g in decoder.categorical_groups]


def record_learner_groups(config: dict, env, raw_space, who: str) -> None:
    """``config["categorical_groups"]``: the learner's logit groups (:func:`learner_groups`),
    for a run whose ``config`` asks for categorical heads; ``env`` (the run's evaluation env,
    made before) is closed when the learner has none, and the TrainInputError raised."""
    if not config.get("categorical_heads"):
        return
    try:
        config["categorical_groups"] = learner_groups(raw_space, who)
    except TrainInputError:
        env.close()
        raise


def has_categorical_heads(policy) -> bool:
    """Whether an SB3 policy's action distribution is :class:`CategoricalHeads`."""
    return isinstance(getattr(policy, "action_dist", None), CategoricalHeads)


class CategoricalHeads(DiagGaussianDistribution):
    """A diagonal Gaussian over the flat action's continuous dimensions and one categorical
    distribution per logit group (module docstring). A ``DiagGaussianDistribution`` to SB3's
    ``ActorCriticPolicy``: one linear layer gives the motors' means and the groups' logits,
    one log-std parameter per continuous dimension."""

    def __init__(self, action_dim: int, groups: Sequence[Sequence[int]]):
        super().__init__(int(action_dim))
        self.groups = check_groups(groups, self.action_dim)
        grouped = {d for s, n in self.groups for d in range(s, s + n)}
        self.continuous = [d for d in range(self.action_dim) if d not in grouped]
        self.gaussian: Normal | None = None
        self.categoricals: list[Categorical] = []

    def proba_distribution_net(self, latent_dim: int, log_std_init: float = 0.0):
        mean_and_logits = nn.Linear(latent_dim, self.action_dim)
        log_std = nn.Parameter(torch.ones(len(self.continuous)) * log_std_init,
                               requires_grad=True)
        return mean_and_logits, log_std

    def proba_distribution(self, mean_actions: torch.Tensor, log_std: torch.Tensor):
        mean = mean_actions[..., self.continuous]
        self.gaussian = Normal(mean, torch.ones_like(mean) * log_std.exp())
        self.distribution = self.gaussian
        self.categoricals = [Categorical(logits=mean_actions[..., s:s + n])
                             for s, n in self.groups]
        self._shape = mean_actions.shape
        return self

    def choices(self, actions: torch.Tensor) -> list[torch.Tensor]:
        """Each group's choice in flat ``actions``: the index of its largest value."""
        return [actions[..., s:s + n].argmax(dim=-1) for s, n in self.groups]

    def _assemble(self, motors: torch.Tensor, picks: Sequence[torch.Tensor]) -> torch.Tensor:
        out = torch.full(self._shape, LOGIT_LOW, dtype=motors.dtype, device=motors.device)
        out[..., self.continuous] = motors
        for (s, n), pick in zip(self.groups, picks):
            group = torch.full((*pick.shape, n), LOGIT_LOW, dtype=motors.dtype,
                               device=motors.device)
            group.scatter_(-1, pick.unsqueeze(-1), LOGIT_HIGH)
            out[..., s:s + n] = group
        return out

    def log_prob(self, actions: torch.Tensor) -> torch.Tensor:
        lp = sum_independent_dims(self.gaussian.log_prob(actions[..., self.continuous]))
        for cat, pick in zip(self.categoricals, self.choices(actions)):
            lp = lp + cat.log_prob(pick)
        return lp

    def entropy(self) -> torch.Tensor:
        ent = sum_independent_dims(self.gaussian.entropy())
        for cat in self.categoricals:
            ent = ent + cat.entropy()
        return ent

    def sample(self) -> torch.Tensor:
        return self._assemble(self.gaussian.rsample(), [c.sample() for c in self.categoricals])

    def mode(self) -> torch.Tensor:
        return self._assemble(self.gaussian.mean,
                              [c.logits.argmax(dim=-1) for c in self.categoricals])

    def clone_loss(self, actions: torch.Tensor) -> torch.Tensor:
        """Behaviour cloning's ``mse`` loss: the squared error of the motors' mean (over the
        Gaussian dimensions) plus each group's cross-entropy of the choice in ``actions``."""
        loss = (torch.mean((self.gaussian.mean - actions[..., self.continuous]) ** 2)
                if self.continuous else torch.zeros((), device=actions.device))
        for cat, pick in zip(self.categoricals, self.choices(actions)):
            loss = loss - cat.log_prob(pick).mean()
        return loss


class CategoricalHeadsPolicy(ActorCriticPolicy):
    """SB3's actor-critic policy with :class:`CategoricalHeads` as its action distribution:
    ``policy_kwargs={"categorical_groups": [[start, n], ...], ...}`` (the other keywords as
    ``ActorCriticPolicy``'s; pass ``features_extractor_class`` for a ``Dict`` observation). A
    saved model loads with its groups (they are among its ``policy_kwargs``)."""

    def __init__(self, *args, categorical_groups=(), **kwargs):
        if kwargs.get("use_sde"):
            raise ValueError("CategoricalHeadsPolicy: use_sde=True not allowed; the motors are "
                             "a diagonal Gaussian")
        self._groups = [list(g) for g in categorical_groups]
        super().__init__(*args, **kwargs)

    def _build(self, lr_schedule) -> None:
        self.action_dist = CategoricalHeads(int(self.action_space.shape[0]), self._groups)
        super()._build(lr_schedule)

    def _get_constructor_parameters(self) -> dict:
        data = super()._get_constructor_parameters()
        data["categorical_groups"] = [list(g) for g in self._groups]
        return data
