"""Behaviour cloning of a recurrent policy (``--algo recurrent_ppo``): whole stretches of the
demonstrations, so the LSTM learns what to carry from step to step (issue 30).

A feed-forward clone (:func:`~mimo_social.train.demonstrations.clone`) fits each pair alone. A
task whose controller acts on what it saw earlier (joint attention's checking follower: it reads
the partner's toy while it watches the face and turns to it when the face is out of view) needs
a policy with memory and a cloning that shows it the history. Here each demonstration episode is
cut into consecutive sequences of ``seq_len`` steps (the last one shorter; padded, the padding
masked out of the loss); each minibatch is ``seq_batch`` sequences, the LSTM states start at
zero at each sequence's first step (truncated back-propagation through time: a memory of up to
``seq_len`` steps is trained) and run through the sequence with the policy's own recurrence
(sb3-contrib's ``RecurrentActorCriticPolicy``: its features, LSTM and action head). The loss
per step is the mean action's squared error (``"mse"``) or the negative log-likelihood
(``"nll"``; a ``Discrete`` action: the cross-entropy), as the feed-forward clone's.

Cloning kept during RL (``keep_updates``) draws ``seq_batch`` sequences at random a minibatch
(:func:`~mimo_social.train.demonstrations.keep_cloning`). Refused with a recurrent policy (by
:func:`~mimo_social.train.bc_settings.check_bc`): DAgger, the critic's fit and an auxiliary
label, which work pair by pair.
"""

from __future__ import annotations

import numpy as np

from .log_std import set_log_std

__all__ = ["is_recurrent", "sequences", "SequenceCloner", "clone_sequences"]


def is_recurrent(policy) -> bool:
    """Whether ``policy`` is sb3-contrib's LSTM policy (RecurrentPPO's)."""
    return hasattr(policy, "lstm_actor")


def sequences(ends: np.ndarray, seq_len: int) -> list[np.ndarray]:
    """The pair indices of each sequence: every episode (``ends``: True on its last pair; the
    pairs in episode order) cut into consecutive pieces of at most ``seq_len`` steps."""
    ends = np.asarray(ends, bool)
    if len(ends) and not ends[-1]:
        ends = ends.copy()
        ends[-1] = True                  # an unfinished last episode ends with the pairs
    out, start = [], 0
    for stop in np.flatnonzero(ends) + 1:
        out += [np.arange(s, min(s + seq_len, stop)) for s in range(start, stop, seq_len)]
        start = stop
    return out


class SequenceCloner:
    """The cloning loss of a recurrent ``model``'s policy on ``demos``, by sequences (module
    docstring), and its own Adam optimiser."""

    def __init__(self, model, demos, seq_len: int, lr: float = 1e-3, loss: str = "mse"):
        import torch

        from gymnasium import spaces

        self.torch, self.demos = torch, demos
        self.discrete = isinstance(model.action_space, spaces.Discrete)
        self.kind = "cross-entropy" if self.discrete else loss
        self.policy = model.policy
        self.seqs = sequences(demos.ends, int(seq_len))
        self.seq_len = int(seq_len)
        self.optimiser = torch.optim.Adam(self.policy.parameters(), lr=lr)

    def _batch(self, chosen: list[np.ndarray]):
        """Padded indices (n_seq * seq_len, sequence-major), the mask of real steps, and the
        episode-start flags (1 at each sequence's first step)."""
        n, L = len(chosen), max(len(s) for s in chosen)
        idx = np.zeros((n, L), np.intp)
        mask = np.zeros((n, L), bool)
        for k, s in enumerate(chosen):
            idx[k, :len(s)], mask[k, :len(s)] = s, True
            idx[k, len(s):] = s[-1]                 # padding repeats the last step (masked)
        starts = np.zeros((n, L), np.float32)
        starts[:, 0] = 1.0
        return idx.ravel(), mask.ravel(), starts.ravel(), n

    def loss(self, chosen: list[np.ndarray]):
        torch, policy = self.torch, self.policy
        idx, mask, starts, n = self._batch(chosen)
        obs = policy.obs_to_tensor(self.demos.take(idx))[0]
        act = torch.as_tensor(np.asarray(self.demos.actions[idx]), device=policy.device)
        act = act.long() if self.discrete else act.float()
        lstm = policy.lstm_actor
        zeros = torch.zeros(lstm.num_layers, n, lstm.hidden_size, device=policy.device)
        dist, _ = policy.get_distribution(obs, (zeros, zeros.clone()),
                                          torch.as_tensor(starts, device=policy.device))
        m = torch.as_tensor(mask, device=policy.device)
        if self.kind in ("nll", "cross-entropy"):
            per = -dist.log_prob(act)
        else:
            per = ((dist.mode() - act) ** 2).mean(dim=-1)
        return per[m].mean()

    def step(self, chosen: list[np.ndarray]) -> None:
        self.optimiser.zero_grad()
        self.loss(chosen).backward()
        self.optimiser.step()

    def mean_loss(self, seq_batch: int) -> float:
        self.policy.set_training_mode(False)
        total, count = 0.0, 0
        with self.torch.no_grad():
            for k in range(0, len(self.seqs), seq_batch):
                chosen = self.seqs[k:k + seq_batch]
                steps = sum(len(s) for s in chosen)
                total, count = total + float(self.loss(chosen)) * steps, count + steps
        return total / max(1, count)


def clone_sequences(model, demos, epochs: int, seq_len: int = 128, seq_batch: int = 4,
                    lr: float = 1e-3, loss: str = "mse", seed: int = 0,
                    log_std=None) -> dict:
    """Trains a recurrent ``model``'s policy on ``demos`` by sequences (module docstring);
    returns what :func:`~mimo_social.train.demonstrations.clone` returns, with the sequences'
    count and length."""
    cloner = SequenceCloner(model, demos, seq_len, lr, loss)
    before = cloner.mean_loss(seq_batch)
    rng = np.random.default_rng(seed)
    updates = 0
    cloner.policy.set_training_mode(True)
    for _ in range(int(epochs)):
        order = rng.permutation(len(cloner.seqs))
        for k in range(0, len(order), int(seq_batch)):
            cloner.step([cloner.seqs[j] for j in order[k:k + int(seq_batch)]])
            updates += 1
    after = cloner.mean_loss(seq_batch)
    if log_std is not None:
        set_log_std(cloner.policy, log_std)
    cloner.policy.set_training_mode(False)
    return {"loss": f"{cloner.kind}, by sequences", "loss_before": before, "loss_after": after,
            "updates": updates, "sequences": len(cloner.seqs), "seq_len": int(seq_len)}
