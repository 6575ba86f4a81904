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
  mean from being drowned by the sampling noise in the first rollouts);
* ``batch_size`` (64), ``lr`` (1e-3; its own optimiser, the algorithm's is untouched).

The value function is not trained (PPO's critic starts from scratch). ``RecurrentPPO`` is
refused (its policy needs the LSTM states over whole sequences).
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

import math
import time
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
from gymnasium import spaces

from ..core.episodes import run_episode
from ..core.wrappers import ActionDecoder
from ..envs.catalog import entry
from .tasks import TrainInputError

__all__ = ["BC_DEFAULTS", "BC_ALGOS", "DEMO_SEED", "Demonstrations", "Demonstrator",
           "check_bc", "record_demonstrations", "clone", "warm_start", "evaluate_after_bc"]

#: the settings of ``bc_kwargs`` and their defaults (``epochs``: ``bc_epochs``)
BC_DEFAULTS = {"epochs": 20, "batch_size": 64, "lr": 1e-3, "loss": "mse", "log_std": None}
BC_LOSSES = ("mse", "nll")
BC_ALGOS = ("ppo", "sac")
#: the demonstrations' first seed is this plus the run's seed (training: seed + i; the
#: evaluations: 10000 + seed + k)
DEMO_SEED = 20_000


def check_bc(task: str, algo: str, mode: str | None, episodes, epochs,
             kwargs: Mapping[str, Any] | None) -> dict | None:
    """The warm start's settings, checked (None: no warm start, ``episodes`` 0); a
    TrainInputError naming the argument, its value and what is allowed otherwise."""
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 0:
        raise TrainInputError(f"bc_episodes={episodes!r}; allowed: an integer >= 0 (scripted "
                              "episodes to clone before training; 0: none)")
    if isinstance(epochs, bool) or not isinstance(epochs, int) or epochs < 1:
        raise TrainInputError(f"bc_epochs={epochs!r}; allowed: an integer >= 1")
    if kwargs is not None and not isinstance(kwargs, Mapping):
        raise TrainInputError(f"bc_kwargs={kwargs!r}; allowed: a dict of "
                              f"{', '.join(k for k in BC_DEFAULTS if k != 'epochs')}")
    kwargs = dict(kwargs or {})
    if episodes == 0:
        if kwargs:
            raise TrainInputError(f"bc_kwargs={kwargs!r} without bc_episodes; allowed: "
                                  "bc_kwargs with bc_episodes >= 1")
        return None
    unknown = sorted(set(kwargs) - set(BC_DEFAULTS) | ({"epochs"} & set(kwargs)))
    if unknown:
        raise TrainInputError(f"bc_kwargs: unknown key(s) {', '.join(unknown)}; allowed: "
                              f"{', '.join(k for k in BC_DEFAULTS if k != 'epochs')} (the "
                              "epochs: bc_epochs)")
    if algo not in BC_ALGOS:
        raise TrainInputError(f"bc_episodes with algo {algo!r}; allowed: {', '.join(BC_ALGOS)} "
                              "(a recurrent policy is cloned over whole sequences: not here)")
    if mode not in (None, "scripted"):
        raise TrainInputError(f"bc_episodes with --mode {mode}; allowed: one learner (a "
                              "one-agent task, or --mode scripted): the controller drives one "
                              "agent")
    if entry(task).controller is None:
        raise TrainInputError(f"bc_episodes: {task} has no scripted controller (catalogue "
                              "entry: controller=None); allowed: tasks with one")
    s = {**BC_DEFAULTS, **kwargs, "epochs": epochs, "episodes": episodes}
    bs = s["batch_size"]
    if isinstance(bs, bool) or not isinstance(bs, int) or bs < 1:
        raise TrainInputError(f"bc_kwargs: batch_size={bs!r}; allowed: an integer >= 1")
    lr = s["lr"]
    if isinstance(lr, bool) or not isinstance(lr, (int, float)) or not 0 < lr < math.inf:
        raise TrainInputError(f"bc_kwargs: lr={lr!r}; allowed: a number > 0")
    if s["loss"] not in BC_LOSSES or (algo == "sac" and s["loss"] != "mse"):
        allowed = "mse" if algo == "sac" else ", ".join(BC_LOSSES)
        raise TrainInputError(f"bc_kwargs: loss={s['loss']!r}; allowed with {algo}: {allowed}")
    ls = s["log_std"]
    if ls is not None and (algo != "ppo" or isinstance(ls, bool)
                           or not isinstance(ls, (int, float)) or not math.isfinite(ls)):
        raise TrainInputError(f"bc_kwargs: log_std={ls!r}; allowed: None, or with ppo a finite "
                              "number (the Gaussian's log-std after cloning)")
    return s


@dataclass
class Demonstrations:
    """Observation and action pairs (``obs``: an array, or a dict of arrays for image
    observations; ``actions``: the learner's actions) and each episode's numbers."""

    obs: Any
    actions: np.ndarray
    seeds: list[int]
    returns: list[float]
    lengths: list[int]
    successes: list[bool | None]

    def __len__(self) -> int:
        return len(self.actions)

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

    def __init__(self, controller_cls, env):
        self.controller, self.env = controller_cls(), env
        raw = env.unwrapped.action_space       # the agent's own action space
        self.decoder = ActionDecoder(raw)
        self.space = env.action_space          # the learner's
        self.core = None
        self.obs: list = []
        self.actions: list = []

    def reset(self, env, agent: str, rng) -> None:
        self.core = self.env.unwrapped.parallel.unwrapped
        self.controller.reset(self.core, agent, rng)

    def act(self, env, agent: str, obs):
        flat = self.decoder.encode(self.controller.act(self.core, agent, obs))
        if isinstance(self.space, spaces.Box):
            flat = np.clip(np.asarray(flat, np.float32), self.space.low, self.space.high)
        self.obs.append({k: np.array(v) for k, v in obs.items()} if isinstance(obs, dict)
                        else np.array(obs))
        self.actions.append(flat)
        return flat


def record_demonstrations(task: str, env, episodes: int, seed: int) -> Demonstrations:
    """``episodes`` episodes of the task's controller on the learner's env ``env`` (seeds
    ``seed, seed+1, ...``; the controller reset with each episode's seed)."""
    controller = entry(task).controller
    if controller is None:
        raise TrainInputError(f"{task} has no scripted controller")
    demo = Demonstrator(controller, env)
    seeds, returns, lengths, successes = [], [], [], []
    for k in range(int(episodes)):
        ep = run_episode(env, demo, seed + k)
        agent = next(iter(ep.returns))
        seeds.append(seed + k)
        returns.append(float(ep.returns[agent]))
        lengths.append(int(ep.length))
        successes.append(ep.success(agent))
    obs = ({k: np.stack([o[k] for o in demo.obs]) for k in demo.obs[0]}
           if isinstance(demo.obs[0], dict) else np.stack(demo.obs))
    return Demonstrations(obs, np.stack(demo.actions), seeds, returns, lengths, successes)


def _is_sac(policy) -> bool:
    return hasattr(policy, "actor") and not hasattr(policy, "action_net")


def clone(model, demos: Demonstrations, epochs: int, batch_size: int = 64, lr: float = 1e-3,
          loss: str = "mse", seed: int = 0, log_std: float | None = None) -> dict:
    """Trains ``model``'s policy on ``demos`` (module docstring); returns the mean loss over
    all pairs before and after, the updates made and the kind of loss."""
    import torch

    policy = model.policy
    sac = _is_sac(policy)
    discrete = isinstance(model.action_space, spaces.Discrete)
    kind = "cross-entropy" if discrete else ("mse" if sac else loss)
    params = list(policy.actor.parameters()) if sac else list(policy.parameters())
    optimiser = torch.optim.Adam(params, lr=lr)
    targets = (policy.scale_action(demos.actions) if sac else demos.actions)

    def batch_loss(idx):
        obs = policy.obs_to_tensor(demos.take(idx))[0]
        act = torch.as_tensor(np.asarray(targets[idx]), device=policy.device)
        if sac:
            return torch.mean((policy.actor(obs, deterministic=True) - act.float()) ** 2)
        dist = policy.get_distribution(obs)
        if discrete:
            return -dist.log_prob(act.long()).mean()
        if loss == "nll":
            return -dist.log_prob(act.float()).mean()
        return torch.mean((dist.mode() - act.float()) ** 2)

    def mean_loss() -> float:
        policy.set_training_mode(False)
        with torch.no_grad():
            parts = [(float(batch_loss(idx)), len(idx))
                     for idx in np.array_split(np.arange(len(demos)),
                                               max(1, -(-len(demos) // 1024)))]
        return float(sum(v * k for v, k in parts) / len(demos))

    before = mean_loss()
    rng = np.random.default_rng(seed)
    updates = 0
    policy.set_training_mode(True)
    for _ in range(int(epochs)):
        order = rng.permutation(len(demos))
        for start in range(0, len(demos), int(batch_size)):
            idx = order[start:start + int(batch_size)]
            optimiser.zero_grad()
            value = batch_loss(idx)
            value.backward()
            optimiser.step()
            updates += 1
    after = mean_loss()
    if log_std is not None:
        with torch.no_grad():
            policy.log_std.fill_(float(log_std))
    policy.set_training_mode(False)
    return {"loss": kind, "loss_before": before, "loss_after": after, "updates": updates}


def warm_start(model, task: str, env, settings: Mapping[str, Any], seed: int) -> dict:
    """Records ``settings["episodes"]`` controller episodes on ``env`` (seeds from
    ``DEMO_SEED + seed``) and clones them into ``model`` (:func:`clone`); returns what
    config.json records under ``bc``."""
    t0 = time.perf_counter()
    demos = record_demonstrations(task, env, int(settings["episodes"]), DEMO_SEED + int(seed))
    t1 = time.perf_counter()
    res = clone(model, demos, int(settings["epochs"]), int(settings["batch_size"]),
                float(settings["lr"]), str(settings["loss"]), int(seed), settings["log_std"])
    return {**demos.summary(), "controller": entry(task).controller.__name__,
            "epochs": int(settings["epochs"]), "batch_size": int(settings["batch_size"]),
            "lr": float(settings["lr"]), "log_std": settings["log_std"], **res,
            "record_time_s": round(t1 - t0, 1),
            "clone_time_s": round(time.perf_counter() - t1, 1)}


def evaluate_after_bc(log, episodes: int) -> dict:
    """The progress row of the cloned policy before any RL step (``timesteps`` 0, outside the
    evaluation budget), labelled by a ``before_rl`` column (1 here, 0 on every later row)."""
    state = {"before_rl": 1}
    log.columns.append(lambda: dict(state))
    row = log.evaluate(0, int(episodes), budget=False)
    state["before_rl"] = 0
    return row
