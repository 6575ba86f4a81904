"""Demonstrations from a task's scripted controller and a behaviour-cloning warm start (issue 30).

``--bc-episodes N`` (``train(..., bc_episodes=N, bc_epochs=E, bc_kwargs={...})``): before any
RL step, the catalogue's controller of the task (``entry(task).controller``, a Partner, as
``mimo-social baselines`` runs it) plays ``N`` episodes, seeded ``20000 + seed`` onwards, on
the learner's env as the learner sees it (:func:`~mimo_social.train.envs.make_env`: the flat
Box or the image Dict, ``--frame-stack`` frames; with a curriculum, the stage evaluated), each
of its actions put into the learner's action form (the flat Box of ``FlatActionWrapper``: the
motors, then the expression as logits, 1 for the chosen one and -1 for the others; or the
``Discrete`` expression of a face-only learner; ``ActionDecoder.encode``, the decoder's
inverse) and stepped through the learner's env, so each recorded (observation, action) pair is
what the learner would have seen and done. Then the SB3 policy's action distribution is
trained on the pairs for ``E`` epochs (Adam, minibatches), through the policy's own
``get_distribution`` (PPO) or actor (SAC):

* ``loss="mse"`` (default): the squared error of the distribution's mean action (PPO's
  Gaussian; SAC's squashed mean against the action scaled to [-1, 1]); a ``Discrete`` action
  (a face-only learner): cross-entropy (the negative log-likelihood of the controller's
  choice);
* ``loss="nll"`` (PPO): the negative log-likelihood of the controller's actions, which trains
  the log-std too (it shrinks towards the demonstrations' spread, here none: exploration
  drops with it);
* ``log_std`` (PPO with a Gaussian, optional): the policy's log-std set to this value after
  cloning (SB3's initial value is 0: std 1 on actions in [-1, 1]; e.g. -1 keeps the cloned
  mean from being drowned by the sampling noise in the first rollouts); or a list, one value
  per action dimension (checked against the policy's action size before any episode plays),
  e.g. a learner with motors and a face (the flat Box: the motors, then the expression's
  logits) with its motors precise and its face sampled: ``[-2] * 9 + [0] * 7``; with
  categorical heads (``categorical_heads``, :mod:`~mimo_social.train.categorical_heads`) the
  face is a categorical choice, cloned by cross-entropy beside the motors' squared error
  (``mse``), and the list has one value per motor (``[-2] * 9``);
* ``batch_size`` (64), ``lr`` (1e-3; its own optimiser, the algorithm's is untouched);
* ``critic_epochs`` (PPO, default 0: none): after the actor, the value function is fitted for
  that many epochs to the demonstrations' discounted returns-to-go (PPO's ``gamma``; each
  episode's last step taken as its end, a truncated one too), through the value layers only
  (a features extractor shared with the actor, e.g. the eyes' CNN, is left as cloned). Without
  it PPO's critic starts from scratch and its first updates are driven by advantages of an
  untrained value function: measured on social touch (issue 30), the cloned policy's 60 %
  success fell to 0 % within the first 10k steps whatever the log-std (-1, -2).

* ``keep_updates`` (default 0: none) and ``keep_until`` (0.5): the cloning goes on during RL
  (:class:`KeepCloning`, an SB3 callback): after each of the algorithm's updates, that many
  minibatches of the same cloning loss (its own Adam, ``lr``), falling linearly with the run's
  progress to none at ``keep_until`` of its steps (beyond 1: still on at the run's end, at
  ``1 - 1 / keep_until`` of the first updates' number); the demonstrations hold the policy near
  the controller while RL's first, noisy updates would pull it away (the regularisation of
  demonstration-augmented policy gradient, Rajeswaran et al. 2018, as alternating updates).

* ``dagger_rounds`` (default 0: none) and ``dagger_episodes`` (50): DAgger after the cloning
  (:mod:`~mimo_social.train.dagger`): the cloned policy plays, the controller labels the states
  it meets, the policy is cloned again on everything (the critic, if fitted, keeps the
  controller's own episodes; ``keep_updates`` uses all the pairs).

* ``controller`` (default None: the controller's defaults): keyword arguments of the task's
  controller (``entry(task).controller(**controller)``) for the demonstrations and DAgger's
  labels, e.g. ``{"frequency": 6.0}``: a stiffer PD demonstrator. A clone is the controller plus
  an error, and how much that error costs depends on the controller: measured on social touch
  (30 episodes, seeds 1000-1029; ``scripts/demonstrator_tolerance.py``), a constant error of
  sd 0.03 (drawn per episode) on every action of the 3-Hz scripted toucher brought its success
  from 97 % to 67 % (0.06: 57 %); at 6 Hz 97 % to 83 % (0.06: 80 %). Checked by making the
  controller once (its own error, named).

* ``demonstrator`` (default None: the catalogue entry's ``controller``): another controller of
  the task by name (the entry's ``demonstrators``), e.g. joint attention's ``"checking"``
  (:class:`~mimo_social.tasks.joint_attention.checking.CheckingFollowController`: reads the
  partner only while it watches the partner's face, as a learner's eyes must); ``controller``'s
  keyword arguments are then that one's.

* ``aux_label`` (default None: none) and ``aux_weight`` (1.0, PPO): each pair keeps the step's
  ``info[aux_label]`` (an integer class) and every cloning minibatch adds the cross-entropy of
  a linear head on the actor's last hidden layer naming it (:mod:`~mimo_social.train.auxiliary`): the
  features extractor learns to read what the label names (which toy the partner looks at).

* ``noise`` (default 0: none): the demonstrations are played with the executed action
  perturbed and the controller's own action recorded (DART, Laskey et al. 2017): a Box action
  plus Gaussian noise of that sd (clipped to the space), a ``Discrete`` one replaced by a
  uniformly drawn choice with that probability (each episode's noise drawn from a generator
  spawned from its seed). The clone then sees the states just off the controller's path and
  the way back from them, where a clone of clean episodes has no data (its errors compound).

* ``seq_len`` (default 128) and ``seq_batch`` (4), ``--algo recurrent_ppo`` only: the LSTM
  policy is cloned by consecutive sequences of ``seq_len`` steps of each episode, ``seq_batch``
  of them a minibatch, the LSTM state zero at each sequence's start
  (:mod:`~mimo_social.train.sequence_cloning`); ``keep_updates`` then draws ``seq_batch``
  sequences a minibatch; DAgger, ``critic_epochs`` and ``aux_label`` are refused with it (they
  work pair by pair).

``config.json["bc"]`` records the episodes, their seeds, the demonstrations' success rate and
mean return, the samples, the settings, the loss before and after cloning and the time taken;
an evaluation right after cloning (before any RL step) is the first row of ``progress.csv``
(``timesteps`` 0, ``before_rl`` 1; every later row has ``before_rl`` 0), outside the
evaluation budget.

The ``imitation`` library (HumanCompatibleAI) is not used: its last release, 1.0.1, pins
``gymnasium~=0.29`` and ``stable-baselines3~=2.2.1``; this project runs gymnasium 1.x and
stable-baselines3 2.9.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
from gymnasium import spaces

from ..core.episodes import run_episode
from ..core.wrappers import ActionDecoder
from ..envs.catalog import DEFAULT_DEMONSTRATOR, entry
from .auxiliary import aux_head, features_and_distribution, label_of
from .bc_settings import BC_ALGOS, BC_DEFAULTS, BC_LOSSES, check_bc
from .log_std import check_log_std_size, set_log_std
from .sequence_cloning import SequenceCloner, clone_sequences, is_recurrent
from .tasks import TrainInputError

__all__ = ["BC_DEFAULTS", "BC_ALGOS", "BC_LOSSES", "DEMO_SEED", "Demonstrations", "Demonstrator",
           "demonstrator", "check_bc", "play", "record_demonstrations", "Cloner", "clone", "keep_cloning",
           "returns_to_go", "fit_critic", "warm_start", "evaluate_after_bc", "check_log_std_size",
           "set_log_std"]

#: the demonstrations' first seed is this plus the run's seed (training: seed + i; the
#: evaluations: 10000 + seed + k)
DEMO_SEED = 20_000


def demonstrator(task: str, settings: Mapping[str, Any] | None = None):
    """The task's controller class (``settings["demonstrator"]``: one of the catalogue entry's
    named ones, ``bc_kwargs`` ``demonstrator``), or a factory of it with
    ``settings["controller"]``'s keyword arguments (``bc_kwargs`` ``controller``)."""
    cls = entry(task).controller_class((settings or {}).get("demonstrator"))
    kw = (settings or {}).get("controller")
    return functools.partial(cls, **kw) if kw else cls


@dataclass
class Demonstrations:
    """Observation and action pairs (``obs``: an array, or a dict of arrays for image
    observations; ``actions``: the learner's actions) and each episode's numbers."""

    obs: Any
    actions: np.ndarray
    rewards: np.ndarray
    """each pair's reward (the step's, after the action)"""
    ends: np.ndarray
    """True on each episode's last pair"""
    seeds: list[int]
    returns: list[float]
    lengths: list[int]
    successes: list[bool | None]
    labels: np.ndarray | None = None
    """each pair's auxiliary label (``aux_label``: the step's info; -1: none), or None"""

    def __len__(self) -> int:
        return len(self.actions)

    def joined(self, other: "Demonstrations") -> "Demonstrations":
        """These pairs followed by ``other``'s (the episode numbers: these, the
        demonstrations'; the labels only when both have them)."""
        if isinstance(self.obs, dict):
            obs = {k: np.concatenate([self.obs[k], other.obs[k]]) for k in self.obs}
        else:
            obs = np.concatenate([self.obs, other.obs])
        labels = (None if self.labels is None or other.labels is None
                  else np.concatenate([self.labels, other.labels]))
        return Demonstrations(obs, np.concatenate([self.actions, other.actions]),
                              np.concatenate([self.rewards, other.rewards]),
                              np.concatenate([self.ends, other.ends]), self.seeds,
                              self.returns, self.lengths, self.successes, labels)

    def take(self, idx):
        """The observations at the indices ``idx``."""
        if isinstance(self.obs, dict):
            return {k: v[idx] for k, v in self.obs.items()}
        return self.obs[idx]

    def summary(self) -> dict:
        reported = [s for s in self.successes if s is not None]
        return {"episodes": len(self.seeds), "seeds": [self.seeds[0], self.seeds[-1]],
                "samples": len(self),
                "success_rate": float(np.mean(reported)) if reported else None,
                "return_mean": float(np.mean(self.returns)),
                "length_mean": float(np.mean(self.lengths))}


class Demonstrator:
    """The task's controller as a policy of the core episode loop on the learner's env ``env``:
    it acts on the core env under ``env`` (looked up at every reset: a curriculum's env may
    change it) and returns its action in the learner's form, recording each pair."""

    def __init__(self, controller_cls, env, noise: float = 0.0, aux_label: str | None = None):
        self.controller, self.env = controller_cls(), env
        self.noise = float(noise)
        self.aux_label = aux_label
        self.labels: list[int] = []
        self.rng = None
        raw = env.unwrapped.action_space       # the agent's own action space
        self.decoder = ActionDecoder(raw)
        self.space = env.action_space          # the learner's
        self.core = None
        self.obs: list = []
        self.actions: list = []
        self.rewards: list = []

    def on_step(self, env, obs, rewards, terminations, truncations, infos) -> None:
        """``run_episode``'s hook: the reward of the action just recorded (and its label)."""
        self.rewards.append(float(next(iter(rewards.values()))))
        if self.aux_label is not None:
            self.labels.append(label_of(next(iter(infos.values())), self.aux_label))

    def reset(self, env, agent: str, rng) -> None:
        self.core = self.env.unwrapped.parallel.unwrapped
        if self.noise:      # its own stream: the controller's draws stay as without noise
            self.rng = rng.spawn(1)[0]
        self.controller.reset(self.core, agent, rng)

    def act(self, env, agent: str, obs):
        flat = self.decoder.encode(self.controller.act(self.core, agent, obs))
        box = isinstance(self.space, spaces.Box)
        if box:
            flat = np.clip(np.asarray(flat, np.float32), self.space.low, self.space.high)
        self.obs.append({k: np.array(v) for k, v in obs.items()} if isinstance(obs, dict)
                        else np.array(obs))
        self.actions.append(flat)
        if not self.noise:
            return flat
        if box:             # DART: the executed action perturbed, the recorded one clean
            return np.clip(flat + self.rng.normal(0.0, self.noise, flat.shape).astype(
                np.float32), self.space.low, self.space.high)
        if self.rng.random() < self.noise:
            return np.int64(self.space.start + int(self.rng.integers(self.space.n)))
        return flat


def play(recorder: Demonstrator, env, first: int, episodes: int) -> Demonstrations:
    """``episodes`` episodes (seeds ``first, first+1, ...``) of ``recorder`` (a
    :class:`Demonstrator`, or anything that records as one) on ``env``: every pair it recorded,
    with each step's reward, the episodes' ends and each episode's numbers."""
    seeds, returns, lengths, successes = [], [], [], []
    for k in range(int(episodes)):
        ep = run_episode(env, recorder, first + k, on_step=recorder.on_step)
        agent = next(iter(ep.returns))
        seeds.append(first + k)
        returns.append(float(ep.returns[agent]))
        lengths.append(int(ep.length))
        successes.append(ep.success(agent))
    obs = ({k: np.stack([o[k] for o in recorder.obs]) for k in recorder.obs[0]}
           if isinstance(recorder.obs[0], dict) else np.stack(recorder.obs))
    ends = np.zeros(len(recorder.actions), bool)
    ends[np.cumsum(lengths) - 1] = True
    labels = (np.asarray(recorder.labels, np.int64)
              if getattr(recorder, "aux_label", None) is not None else None)
    return Demonstrations(obs, np.stack(recorder.actions),
                          np.asarray(recorder.rewards, np.float32), ends, seeds, returns,
                          lengths, successes, labels)


def record_demonstrations(task: str, env, episodes: int, seed: int,
                          controller: Mapping[str, Any] | None = None,
                          noise: float = 0.0, aux_label: str | None = None,
                          demonstrator_name: str | None = None) -> Demonstrations:
    """``episodes`` episodes of the task's controller (``demonstrator_name``: one of the catalogue
    entry's named ones; made with the keyword arguments ``controller``, if given) on the
    learner's env ``env`` (seeds ``seed, seed+1, ...``; the
    controller reset with each episode's seed), the executed actions perturbed by ``noise``
    (``bc_kwargs``, DART) and the controller's own recorded; ``aux_label``: each pair's label
    (the step's info under that key)."""
    if entry(task).controller is None:
        raise TrainInputError(f"{task} has no scripted controller")
    cls = demonstrator(task, {"controller": controller, "demonstrator": demonstrator_name})
    return play(Demonstrator(cls, env, noise, aux_label), env, seed, episodes)


def returns_to_go(rewards: np.ndarray, ends: np.ndarray, gamma: float) -> np.ndarray:
    """Each step's discounted return to its episode's end (``ends``: True on last steps)."""
    out = np.zeros(len(rewards), np.float64)
    acc = 0.0
    for i in range(len(rewards) - 1, -1, -1):
        acc = float(rewards[i]) + (0.0 if ends[i] else gamma * acc)
        out[i] = acc
    return out.astype(np.float32)


def fit_critic(model, demos: Demonstrations, epochs: int, batch_size: int = 64,
               lr: float = 1e-3, seed: int = 0) -> dict:
    """Fits PPO's value function (its value layers only) to the demonstrations' discounted
    returns-to-go: first its last layer by least squares on the value features (the returns'
    scale, tens to hundreds, is reached at once), then ``epochs`` epochs of Adam on every value
    layer. Returns the explained variance of the returns before, after the first step and at
    the end."""
    import torch

    policy = model.policy
    target = returns_to_go(demos.rewards, demos.ends, float(model.gamma))
    chunks = np.array_split(np.arange(len(demos)), max(1, -(-len(demos) // 1024)))

    def latent(idx):
        features = policy.extract_features(policy.obs_to_tensor(demos.take(idx))[0])
        vf = features if policy.share_features_extractor else features[1]
        return policy.mlp_extractor.forward_critic(vf)

    def explained() -> float:
        with torch.no_grad():
            v = np.concatenate([policy.value_net(latent(i)).flatten().cpu().numpy()
                                for i in chunks])
        var = float(np.var(target))
        return float(1.0 - np.var(target - v) / var) if var > 0 else float("nan")

    policy.set_training_mode(False)
    before = explained()
    with torch.no_grad():          # the last layer: ridge regression on the value features
        h = np.concatenate([latent(i).cpu().numpy() for i in chunks]).astype(np.float64)
        x = np.hstack([h, np.ones((len(h), 1))])
        reg = 1e-3 * len(h) * np.eye(x.shape[1])
        reg[-1, -1] = 0.0
        coef = np.linalg.solve(x.T @ x + reg, x.T @ target.astype(np.float64))
        policy.value_net.weight.copy_(torch.as_tensor(coef[None, :-1]))
        policy.value_net.bias.fill_(float(coef[-1]))
    linear = explained()
    params = (list(policy.mlp_extractor.value_net.parameters())
              + list(policy.value_net.parameters()))
    optimiser = torch.optim.Adam(params, lr=lr)
    rng = np.random.default_rng(seed + 1)
    tgt = torch.as_tensor(target, device=policy.device)
    for _ in range(int(epochs)):
        order = rng.permutation(len(demos))
        for start in range(0, len(demos), int(batch_size)):
            idx = order[start:start + int(batch_size)]
            optimiser.zero_grad()
            value = policy.value_net(latent(idx)).flatten()
            torch.mean((value - tgt[idx]) ** 2).backward()
            optimiser.step()
    return {"critic_epochs": int(epochs), "critic_explained_variance_before": before,
            "critic_explained_variance_linear": linear,
            "critic_explained_variance_after": explained(),
            "return_to_go_mean": float(np.mean(target))}


def _is_sac(policy) -> bool:
    return hasattr(policy, "actor") and not hasattr(policy, "action_net")


class Cloner:
    """The cloning loss of ``model``'s policy on ``demos`` (module docstring) and its own Adam
    optimiser: ``step(idx)`` one update on the pairs ``idx``, ``mean_loss()`` over all."""

    def __init__(self, model, demos: Demonstrations, lr: float = 1e-3, loss: str = "mse",
                 aux_weight: float = 1.0):
        import torch

        self.torch, self.demos, self.loss_name = torch, demos, loss
        policy = self.policy = model.policy
        self.sac = _is_sac(policy)
        self.discrete = isinstance(model.action_space, spaces.Discrete)
        self.kind = "cross-entropy" if self.discrete else ("mse" if self.sac else loss)
        from .categorical_heads import has_categorical_heads
        self.heads = has_categorical_heads(policy)
        if self.kind == "mse" and self.heads:
            self.kind = "mse + cross-entropy"
        params = list(policy.actor.parameters()) if self.sac else list(policy.parameters())
        self.aux = None if demos.labels is None else aux_head(policy, demos.labels)
        self.aux_weight = float(aux_weight)
        if self.aux is not None:
            params += list(self.aux.parameters())
        self.optimiser = torch.optim.Adam(params, lr=lr)
        self.targets = policy.scale_action(demos.actions) if self.sac else demos.actions

    def loss(self, idx):
        torch, policy = self.torch, self.policy
        obs = policy.obs_to_tensor(self.demos.take(idx))[0]
        act = torch.as_tensor(np.asarray(self.targets[idx]), device=policy.device)
        if self.sac:
            return torch.mean((policy.actor(obs, deterministic=True) - act.float()) ** 2)
        if self.aux is None:
            return self.action_loss(policy.get_distribution(obs), act)
        latent, dist = features_and_distribution(policy, obs)
        return self.action_loss(dist, act) + self.aux_weight * self.aux.loss(
            latent, self.demos.labels[idx])

    def action_loss(self, dist, act):
        if self.discrete:
            return -dist.log_prob(act.long()).mean()
        if self.loss_name == "nll":
            return -dist.log_prob(act.float()).mean()
        if self.heads:     # categorical heads: mse on the motors + the face's cross-entropy
            return dist.clone_loss(act.float())
        return self.torch.mean((dist.mode() - act.float()) ** 2)

    def step(self, idx) -> None:
        self.optimiser.zero_grad()
        self.loss(idx).backward()
        self.optimiser.step()

    def aux_accuracy(self) -> float | None:
        """The auxiliary head's accuracy on every labelled pair (None: no label)."""
        n, right, labelled = len(self.demos), 0, 0
        self.policy.set_training_mode(False)
        with self.torch.no_grad():
            for idx in np.array_split(np.arange(n), max(1, -(-n // 1024))):
                obs = self.policy.obs_to_tensor(self.demos.take(idx))[0]
                latent, _ = features_and_distribution(self.policy, obs)
                r, k = self.aux.accuracy(latent, self.demos.labels[idx])
                right, labelled = right + r, labelled + k
        return right / labelled if labelled else None

    def mean_loss(self) -> float:
        n = len(self.demos)
        self.policy.set_training_mode(False)
        with self.torch.no_grad():
            parts = [(float(self.loss(idx)), len(idx))
                     for idx in np.array_split(np.arange(n), max(1, -(-n // 1024)))]
        return float(sum(v * k for v, k in parts) / n)


def clone(model, demos: Demonstrations, epochs: int, batch_size: int = 64, lr: float = 1e-3,
          loss: str = "mse", seed: int = 0, log_std: float | list | None = None,
          aux_weight: float = 1.0, seq_len: int = 128, seq_batch: int = 4) -> dict:
    """Trains ``model``'s policy on ``demos`` (module docstring); returns the mean loss over
    all pairs before and after, the updates made and the kind of loss (with an auxiliary label:
    the head's accuracy on the labelled pairs after). A recurrent policy is cloned by sequences
    (:func:`~mimo_social.train.sequence_cloning.clone_sequences`: ``seq_batch`` sequences of
    ``seq_len`` steps a minibatch; ``batch_size`` and ``aux_weight`` are for pairs)."""
    if is_recurrent(model.policy):
        return clone_sequences(model, demos, epochs, seq_len, seq_batch, lr, loss, seed,
                               log_std)
    cloner = Cloner(model, demos, lr, loss, aux_weight)
    before = cloner.mean_loss()
    rng = np.random.default_rng(seed)
    updates = 0
    cloner.policy.set_training_mode(True)
    for _ in range(int(epochs)):
        order = rng.permutation(len(demos))
        for start in range(0, len(demos), int(batch_size)):
            cloner.step(order[start:start + int(batch_size)])
            updates += 1
    after = cloner.mean_loss()
    if log_std is not None:
        set_log_std(cloner.policy, log_std)
    cloner.policy.set_training_mode(False)
    res = {"loss": cloner.kind, "loss_before": before, "loss_after": after, "updates": updates}
    if cloner.aux is not None:
        res["aux_accuracy_after"] = cloner.aux_accuracy()
    return res


def keep_cloning(model, demos: Demonstrations, settings: Mapping[str, Any], total_steps: int,
                 seed: int):
    """The SB3 callback that goes on cloning during RL (``keep_updates`` minibatches after each
    update, falling linearly to none at ``keep_until`` of ``total_steps`` SB3 timesteps); None
    when ``keep_updates`` is 0. Its ``updates`` counts the minibatches made."""
    from stable_baselines3.common.callbacks import BaseCallback

    if not int(settings.get("keep_updates", 0)):
        return None
    rng = np.random.default_rng(seed + 2)
    per_update, until = int(settings["keep_updates"]), float(settings["keep_until"])
    if is_recurrent(model.policy):      # by sequences: seq_batch of them a minibatch
        cloner = SequenceCloner(model, demos, int(settings["seq_len"]), float(settings["lr"]),
                                str(settings["loss"]))
        seqs, batch = cloner.seqs, int(settings["seq_batch"])

        def draw():
            return [seqs[j] for j in rng.integers(0, len(seqs), batch)]
    else:
        cloner = Cloner(model, demos, float(settings["lr"]), str(settings["loss"]),
                        float(settings.get("aux_weight", 1.0)))
        batch = int(settings["batch_size"])

        def draw():
            return rng.integers(0, len(demos), batch)

    class KeepCloning(BaseCallback):
        updates = 0
        rollouts = 0

        def _on_rollout_start(self) -> None:     # after each update (the first: before any)
            self.rollouts += 1
            if self.rollouts == 1:
                return
            share = max(0.0, 1.0 - self.model.num_timesteps / (until * max(1, total_steps)))
            n = int(round(per_update * share))
            if n == 0:
                return
            mode = cloner.policy.training
            cloner.policy.set_training_mode(True)
            for _ in range(n):
                cloner.step(draw())
            cloner.policy.set_training_mode(mode)
            self.updates += n

        def _on_step(self) -> bool:
            return True

    return KeepCloning()


def warm_start(model, task: str, env, settings: Mapping[str, Any],
               seed: int) -> tuple[dict, Demonstrations]:
    """Records ``settings["episodes"]`` controller episodes on ``env`` (seeds from
    ``DEMO_SEED + seed``) and clones them into ``model`` (:func:`clone`); returns what
    config.json records under ``bc``, and the demonstrations."""
    check_log_std_size(model, settings["log_std"])
    t0 = time.perf_counter()
    demos = record_demonstrations(task, env, int(settings["episodes"]), DEMO_SEED + int(seed),
                                  settings.get("controller"), settings.get("noise", 0.0),
                                  settings.get("aux_label"), settings.get("demonstrator"))
    t1 = time.perf_counter()
    res = clone(model, demos, int(settings["epochs"]), int(settings["batch_size"]),
                float(settings["lr"]), str(settings["loss"]), int(seed), settings["log_std"],
                float(settings.get("aux_weight", 1.0)), int(settings["seq_len"]),
                int(settings["seq_batch"]))
    if int(settings["critic_epochs"]):
        res.update(fit_critic(model, demos, int(settings["critic_epochs"]),
                              int(settings["batch_size"]), float(settings["lr"]), int(seed)))
    name = settings.get("demonstrator")
    return {**demos.summary(), "controller": entry(task).controller_class(name).__name__,
            "demonstrator": name or DEFAULT_DEMONSTRATOR,
            "controller_kwargs": settings.get("controller") or {},
            "noise": float(settings.get("noise", 0.0)),
            "aux_label": settings.get("aux_label"),
            "aux_weight": float(settings.get("aux_weight", 1.0)),
            "epochs": int(settings["epochs"]), "batch_size": int(settings["batch_size"]),
            "lr": float(settings["lr"]), "log_std": settings["log_std"],
            "keep_updates": int(settings["keep_updates"]),
            "keep_until": float(settings["keep_until"]),
            "dagger_rounds": int(settings["dagger_rounds"]),
            "dagger_episodes": int(settings["dagger_episodes"]), **res,
            "record_time_s": round(t1 - t0, 1),
            "clone_time_s": round(time.perf_counter() - t1, 1)}, demos


def evaluate_after_bc(log, episodes: int) -> dict:
    """The progress row of the cloned policy before any RL step (``timesteps`` 0, outside the
    evaluation budget), labelled by a ``before_rl`` column (1 here, 0 on every later row)."""
    state = {"before_rl": 1}
    log.columns.append(lambda: dict(state))
    row = log.evaluate(0, int(episodes), budget=False)
    state["before_rl"] = 0
    return row
