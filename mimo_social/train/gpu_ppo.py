"""PPO on the device: a learner that collects and learns from batched MuJoCo Warp worlds without
pulling every step back to the host (issue 34; ``mimo-social train-gpu``; docs/gpu.md).

The worlds are a :class:`~mimo_social.gpu.GymVectorEnv` (torch tensors on Warp's device: a GPU
when there is one, else the CPU) of reach, of stand-up, of roll-over, of catch, of self-body
(its target observed as a one-hot) or of the high five's one-learner form (``infant_0``
learns, the scripted partner ``HandOffer`` acts on the device). The learner is built from
TorchRL's PPO pieces (:mod:`mimo_social.train.gpu_networks`): a
:class:`~torchrl.modules.ProbabilisticActor` with a tanh-normal distribution over the motors'
Box (an MLP for the mean, a learnt state-independent log std), a
:class:`~torchrl.modules.ValueOperator` critic MLP, :class:`~torchrl.objectives.value.GAE` and
:class:`~torchrl.objectives.ClipPPOLoss`. Both networks start with the same running
normalisation of the observations (:class:`RunningObsNorm`: the senses the device computes,
concatenated; its statistics are buffers of the policy, saved with it). With ``eyes`` the
learner also sees through its two eyes (rendered on the device): each network encodes the
images with its own small CNN and reads the encoding beside the normalised senses.

Each iteration: ``rollout`` control steps of every world on the device (the policy samples,
the env steps and resets finished worlds in the same step; a finished world's bootstrap value
is taken from its final observation, ``infos["final_obs"]``, and cut only where it
terminated), GAE over the rollout, ``epochs`` passes over it in shuffled minibatches of
``minibatch`` samples, then the normaliser takes the rollout's observations. The episode
figures are summed on the device and read once per iteration: one row of ``progress.csv``
(:data:`PROGRESS_COLUMNS`). The run writes ``config.json``, ``progress.csv`` and ``policy.pt``
(the actor's state_dict, the normaliser's statistics included) to ``out``;
:func:`plot_progress` draws the progress (``mimo-social train-gpu`` does, to
``learning_curve.png``).

Determinism: under one ``seed`` two runs on Warp's CPU device give the same progress (torch's
generator is seeded from it, the worlds' resets are the CPU env's with seeds from it; torch
is set to one thread unless the device is ``"cuda"``). On a GPU, atomics in the physics may
reorder sums: close, not bit-identical.
"""

from __future__ import annotations

import csv
import json
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from tensordict import TensorDict
from torch import nn
from torchrl.objectives import ClipPPOLoss
from torchrl.objectives.value import GAE

from ..envs import catch_v0, high_five_v0, reach_v0, rollover_v0, selfbody_v0, standup_v0
from ..gpu import GymVectorEnv
from .gpu_networks import RunningObsNorm, act, build_networks

__all__ = ["TASKS", "EYE_SIDES", "PROGRESS_COLUMNS", "GpuPPOConfig", "RunningObsNorm",
           "make_env", "build_networks", "act", "train_gpu_ppo", "evaluate_gpu_ppo",
           "read_progress", "plot_progress"]

#: the tasks the on-device PPO trains: name -> the CPU env with one learner
TASKS = {"reach": reach_v0.parallel_env, "high_five": high_five_v0.scripted_env,
         "selfbody": selfbody_v0.parallel_env, "standup": standup_v0.parallel_env,
         "catch": catch_v0.parallel_env, "rollover": rollover_v0.parallel_env}
DEVICES = (None, "cpu", "cuda")
#: the eye image sides (pixels) the learner's CNN takes
EYE_SIDES = (16, 256)

#: the columns of ``progress.csv``, one row per iteration; the episode columns are over the
#: episodes that finished in the iteration (empty when none did)
PROGRESS_COLUMNS = ("iteration", "timesteps", "wall_time_s", "episode_return_mean",
                    "success_rate", "episodes", "episode_length_mean", "loss_policy",
                    "loss_critic", "loss_entropy", "steps_per_s")


@dataclass(frozen=True)
class GpuPPOConfig:
    """The run's settings. ``steps``: world-steps in all (one world-step is one step of the
    learner; rounded up to whole iterations of ``worlds * rollout``); ``rollout``: control
    steps per world per iteration; ``minibatch``: samples per gradient step (at most
    ``worlds * rollout``); ``device``: Warp's and torch's (None: a GPU when Warp sees one, else
    the CPU); ``reward_scale``: the rewards' factor for the critic and the advantages (the
    progress reports unscaled returns); ``max_steps``: the episodes' length (None: the
    task's); ``hidden``: the width of both MLPs' two hidden layers; ``touch``: the touch skin
    in the learner's observation where the task's env has touch (self-body, high five);
    ``eyes``: the learner's two eyes observed, square images of this side in pixels
    (:data:`EYE_SIDES`; rendered on the device, encoded by a small CNN:
    :class:`~mimo_social.train.gpu_networks.EyeEncoder`), or None (no eyes)."""

    task: str = "reach"
    worlds: int = 64
    steps: int = 100_000
    seed: int = 0
    learning_rate: float = 3e-4
    epochs: int = 10
    minibatch: int = 512
    rollout: int = 32
    device: str | None = None
    gamma: float = 0.99
    gae_lambda: float = 0.95
    clip_epsilon: float = 0.2
    entropy_coeff: float = 0.0
    critic_coeff: float = 0.5
    max_grad_norm: float = 0.5
    reward_scale: float = 0.1
    init_log_std: float = 0.0
    hidden: int = 64
    max_steps: int | None = None
    touch: bool = True
    eyes: int | None = None

    def __post_init__(self):
        if self.task not in TASKS:
            _bad("task", self.task, f"one of {', '.join(TASKS)}")
        for name in ("worlds", "steps", "epochs", "minibatch", "rollout", "hidden"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                _bad(name, value, "a positive integer")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            _bad("seed", self.seed, "an integer >= 0")
        if not isinstance(self.touch, bool):
            _bad("touch", self.touch, "True or False")
        lo, hi = EYE_SIDES
        if self.eyes is not None and (isinstance(self.eyes, bool) or not isinstance(
                self.eyes, int) or not lo <= self.eyes <= hi):
            _bad("eyes", self.eyes, f"None (no eyes) or an image side from {lo} to {hi} pixels")
        if self.max_steps is not None and (isinstance(self.max_steps, bool) or not isinstance(
                self.max_steps, int) or self.max_steps < 1):
            _bad("max_steps", self.max_steps, "None or a positive integer")
        if self.device not in DEVICES:
            _bad("device", self.device, "None (a GPU when there is one, else the CPU), "
                                        "'cpu' or 'cuda'")
        for name, lo, hi in (("learning_rate", 0.0, None), ("gamma", 0.0, 1.0),
                             ("gae_lambda", 0.0, 1.0), ("clip_epsilon", 0.0, None),
                             ("reward_scale", 0.0, None), ("max_grad_norm", 0.0, None)):
            value = getattr(self, name)
            if not _number(value) or value <= lo or (hi is not None and value > hi):
                _bad(name, value, f"a number > {lo:g}" + (f" and <= {hi:g}" if hi else ""))
        for name in ("entropy_coeff", "critic_coeff"):
            value = getattr(self, name)
            if not _number(value) or value < 0:
                _bad(name, value, "a number >= 0")
        if not _number(self.init_log_std):
            _bad("init_log_std", self.init_log_std, "a finite number")
        if self.minibatch > self.worlds * self.rollout:
            _bad("minibatch", self.minibatch, f"at most worlds * rollout = {self.worlds} * "
                                              f"{self.rollout} = {self.worlds * self.rollout}")

    @property
    def batch(self) -> int:
        """Samples per iteration."""
        return self.worlds * self.rollout

    @property
    def iterations(self) -> int:
        return max(1, math.ceil(self.steps / self.batch))


def _number(value) -> bool:
    return (not isinstance(value, bool) and isinstance(value, (int, float))
            and math.isfinite(value))


def _bad(name, value, allowed):
    raise ValueError(f"{name}={value!r} not allowed; allowed: {allowed}")


def make_env(config: GpuPPOConfig) -> GymVectorEnv:
    """The batched worlds of ``config.task`` as a Gymnasium vector env of torch tensors."""
    kw = {} if config.max_steps is None else {"max_steps": config.max_steps}
    if config.eyes is not None:
        kw["vision"] = {"width": config.eyes, "height": config.eyes}
    return GymVectorEnv(TASKS[config.task](**kw), config.worlds, device=config.device,
                        seed=config.seed, touch=config.touch)


def _start(config: GpuPPOConfig):
    """The vector env reset with the config's seed, its first inputs (:func:`_inputs`) and
    fresh networks sized for them: ``(venv, inputs, (actor, critic, norm))``."""
    venv = make_env(config)
    obs_dict, _ = venv.reset(seed=config.seed)
    inputs = _inputs(obs_dict)
    space = venv.single_action_space
    dev = inputs["observation"].device
    low = torch.as_tensor(space.low, dtype=torch.float32, device=dev)
    high = torch.as_tensor(space.high, dtype=torch.float32, device=dev)
    pixels = inputs.get("pixels")
    eyes = None if pixels is None else tuple(pixels.shape[1:])
    return venv, inputs, build_networks(int(inputs["observation"].shape[-1]), low, high,
                                        config, eyes)


def _inputs(obs: dict) -> dict:
    """The networks' inputs from one observation Dict: ``"observation"``, the senses other than
    the eyes concatenated in their order (float32 ``(n, size)``), and where the eyes are
    observed ``"pixels"``, ``eye_left`` and ``eye_right`` stacked along the colour axis (uint8
    ``(n, H, W, 6)``)."""
    eyes = [k for k in ("eye_left", "eye_right") if k in obs]
    out = {"observation": torch.cat([obs[k].to(torch.float32).flatten(1) for k in obs
                                     if k not in eyes], dim=-1)}
    if eyes:
        out["pixels"] = torch.cat([obs[k] for k in eyes], dim=-1)
    return out


def train_gpu_ppo(config: GpuPPOConfig, out, progress=None) -> dict:
    """Train (see the module) and write ``config.json``, ``progress.csv`` and ``policy.pt`` to
    ``out``; ``progress``: called with each row (a dict) as it is written. Returns a summary:
    the last row, the iterations, the device and the build time."""
    if not isinstance(config, GpuPPOConfig):
        raise TypeError(f"config: a GpuPPOConfig, not {type(config).__name__}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(config.seed)
    if config.device != "cuda":
        torch.set_num_threads(1)   # the same sums every run (and Warp's CPU device beside it)
    t0 = time.perf_counter()
    venv, obs, (actor, critic, norm) = _start(config)
    dev = obs["observation"].device
    norm.update(obs["observation"])
    loss_fn = ClipPPOLoss(actor, critic, clip_epsilon=config.clip_epsilon,
                          entropy_bonus=config.entropy_coeff > 0,
                          entropy_coeff=config.entropy_coeff or None,
                          critic_coeff=config.critic_coeff, loss_critic_type="l2",
                          normalize_advantage=True)
    gae = GAE(gamma=config.gamma, lmbda=config.gae_lambda, value_network=critic,
              average_gae=False)
    optim = torch.optim.Adam(loss_fn.parameters(), lr=config.learning_rate)
    gen = torch.Generator(device="cpu").manual_seed(config.seed)
    build_s = time.perf_counter() - t0
    meta = {"config": asdict(config), "device": str(dev), "device_name": venv.device_name,
            "observation_size": int(obs["observation"].shape[-1]),
            "pixels": list(obs["pixels"].shape[1:]) if "pixels" in obs else None,
            "action_size": int(venv.single_action_space.shape[-1]),
            "build_s": build_s}
    (out / "config.json").write_text(json.dumps(meta, indent=1))
    n = config.worlds
    ep_return = torch.zeros(n, device=dev)
    ep_length = torch.zeros(n, device=dev)
    rows = []
    t_start = time.perf_counter()
    with open(out / "progress.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=PROGRESS_COLUMNS)
        writer.writeheader()
        for it in range(config.iterations):
            t_it = time.perf_counter()
            batch, obs, stats = _collect(venv, actor, obs, ep_return, ep_length, config)
            losses = _learn(batch, gae, loss_fn, optim, gen, config)
            norm.update(batch["observation"])
            row = _row(it, (it + 1) * config.batch, time.perf_counter() - t_start, stats,
                       losses, config.batch / (time.perf_counter() - t_it))
            writer.writerow(row)
            f.flush()
            rows.append(row)
            if progress is not None:
                progress(row)
    torch.save(actor.state_dict(), out / "policy.pt")
    venv.close()
    return {"last": rows[-1], "iterations": len(rows), "device": str(dev),
            "device_name": meta["device_name"], "build_s": build_s}


@torch.no_grad()
def _collect(venv, actor, obs, ep_return, ep_length, config):
    """``config.rollout`` steps of every world; the batch ``(worlds, rollout)``, the next
    observation and the iteration's episode sums (one read from the device)."""
    dev = obs["observation"].device
    steps, sums = [], torch.zeros(4, device=dev)   # episodes, returns, lengths, successes
    for _ in range(config.rollout):
        td = act(actor, obs)
        nxt, rew, term, trunc, infos = venv.step(td["action"])
        rew = rew.to(torch.float32)
        done = term | trunc
        final = _inputs(infos["final_obs"])
        ep_return += rew
        ep_length += 1
        d = done.to(torch.float32)
        succ = infos["final_info"]["is_success"].to(torch.float32)
        sums += torch.stack([d.sum(), (ep_return * d).sum(), (ep_length * d).sum(),
                             (succ * d).sum()])
        ep_return *= 1.0 - d
        ep_length *= 1.0 - d
        td.set("next", TensorDict({
            **final, "reward": (rew * config.reward_scale)[:, None],
            "done": done[:, None], "terminated": term[:, None]},
            batch_size=[config.worlds], device=dev))
        steps.append(td)
        obs = _inputs(nxt)
    batch = torch.stack(steps, dim=1)   # (worlds, rollout): time last, as GAE reads it
    return batch, obs, sums.tolist()


def _learn(batch, gae, loss_fn, optim, gen, config):
    """GAE over the rollout, then ``epochs`` passes of shuffled minibatches; the mean
    losses of the last pass."""
    with torch.no_grad():
        gae(batch)
    flat = batch.reshape(-1)
    size = flat.shape[0]
    params = list(loss_fn.parameters())
    for _ in range(config.epochs):
        perm = torch.randperm(size, generator=gen).to(flat.device)
        sums, count = torch.zeros(3, device=flat.device), 0
        for start in range(0, size - config.minibatch + 1, config.minibatch):
            mb = flat[perm[start:start + config.minibatch]]
            loss = loss_fn(mb)
            parts = [loss["loss_objective"], loss["loss_critic"],
                     loss.get("loss_entropy", torch.zeros((), device=flat.device))]
            optim.zero_grad()
            sum(parts).backward()
            nn.utils.clip_grad_norm_(params, config.max_grad_norm)
            optim.step()
            sums += torch.stack([p.detach() for p in parts])
            count += 1
    return (sums / max(count, 1)).tolist()


def _row(it, timesteps, wall, stats, losses, fps) -> dict:
    episodes, ret, length, succ = stats
    k = int(round(episodes))
    each = (lambda v: f"{v / k:.6g}") if k else (lambda v: "")
    return {"iteration": it, "timesteps": timesteps, "wall_time_s": f"{wall:.3f}",
            "episode_return_mean": each(ret), "success_rate": each(succ), "episodes": k,
            "episode_length_mean": each(length), "loss_policy": f"{losses[0]:.6g}",
            "loss_critic": f"{losses[1]:.6g}", "loss_entropy": f"{losses[2]:.6g}",
            "steps_per_s": f"{fps:.1f}"}


def evaluate_gpu_ppo(run, worlds: int = 64, seed: int = 1_000_000, explore: bool = False,
                     device: str | None = None) -> dict:
    """The first episode of each of ``worlds`` worlds (seeds ``seed + w``: episodes the run did
    not train on, with the default) under ``run``'s ``policy.pt``: its mode (``explore``
    False) or sampled actions. Returns the success rate, the mean return and length of those
    episodes, and what was run."""
    run = Path(run)
    meta = json.loads((run / "config.json").read_text())
    # a run written before the device had touch observed none
    settings = dict({"touch": False}, **meta["config"])
    settings = dict(settings, worlds=int(worlds), seed=int(seed), device=device,
                    minibatch=1)
    config = GpuPPOConfig(**settings)
    torch.manual_seed(config.seed)
    venv, obs, (actor, _, _) = _start(config)
    dev = obs["observation"].device
    actor.load_state_dict(torch.load(run / "policy.pt", map_location=dev))
    n = config.worlds
    ret, length = torch.zeros(n, device=dev), torch.zeros(n, device=dev)
    first = torch.zeros((3, n), device=dev)     # return, length, success of the first episode
    finished = torch.zeros(n, dtype=torch.bool, device=dev)
    for _ in range(venv.tenv.max_steps):
        nxt, rew, term, trunc, infos = venv.step(act(actor, obs, explore)["action"])
        ret += rew.to(torch.float32)
        length += 1
        new = (term | trunc) & ~finished
        succ = infos["final_info"]["is_success"].to(torch.float32)
        first[:, new] = torch.stack([ret, length, succ])[:, new]
        finished |= term | trunc
        ret *= ~(term | trunc)
        length *= ~(term | trunc)
        obs = _inputs(nxt)
        if bool(finished.all()):
            break
    venv.close()
    r, ln, sc = first.mean(1).tolist()
    return {"episodes": n, "success_rate": sc, "return_mean": r, "length_mean": ln,
            "policy": "sampled" if explore else "mode", "seed": config.seed,
            "task": config.task, "device": str(dev)}


def read_progress(path) -> list[dict]:
    """The rows of a ``progress.csv`` this module wrote, numbers as floats (empty: None)."""
    with open(path, newline="") as f:
        return [{k: (float(v) if v not in ("", None) else None) for k, v in r.items()}
                for r in csv.DictReader(f)]


def plot_progress(run, path=None, window: int = 5) -> Path:
    """The run's ``progress.csv`` drawn: the success rate and the mean return of the episodes
    that finished in each iteration (dots) and their mean over ``window`` iterations (line),
    over world-steps, with the wall time on the top axis; to ``path`` (default
    ``run/learning_curve.png``). Needs matplotlib."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    from .plots import steps_axis

    run = Path(run)
    rows = [r for r in read_progress(run / "progress.csv") if r["episodes"]]
    if not rows:
        raise ValueError(f"{run / 'progress.csv'}: no iteration with finished episodes to draw")
    meta = json.loads((run / "config.json").read_text())
    cfg = meta["config"]
    x = np.array([r["timesteps"] for r in rows])
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, key, label in ((axes[0], "success_rate", "success rate"),
                           (axes[1], "episode_return_mean", "mean episode return")):
        y = np.array([r[key] for r in rows])
        w = np.array([r["episodes"] for r in rows], float)
        k = min(window, len(y))
        smooth = np.array([np.average(y[max(0, i - k + 1):i + 1], weights=w[max(0, i - k + 1):
                                                                            i + 1])
                           for i in range(len(y))])
        ax.plot(x, y, ".", color="0.7", ms=3, label="per iteration")
        ax.plot(x, smooth, "-", color="C0", label=f"over {k} iterations")
        steps_axis(ax, "world-steps")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if len(x) > 1:   # the wall time on the top axis
            wall = [r["wall_time_s"] for r in rows]
            top = ax.secondary_xaxis("top", functions=(lambda s: np.interp(s, x, wall),
                                                       lambda t: np.interp(t, wall, x)))
            ticks = MaxNLocator(6).tick_values(wall[0], wall[-1])
            top.set_xticks([t for t in ticks if wall[0] <= t <= wall[-1]])
            top.set_xlabel("wall time, s")
    axes[0].set_ylim(-0.02, 1.02)
    axes[0].legend(loc="upper left", fontsize=8)
    eyes = f", eyes {cfg['eyes']}x{cfg['eyes']}" if cfg.get("eyes") else ""
    fig.suptitle(f"PPO on the device: {cfg['task']}{eyes}, {cfg['worlds']} worlds, seed "
                 f"{cfg['seed']} ({meta['device_name']})", fontsize=10)
    fig.tight_layout()
    path = Path(path) if path is not None else run / "learning_curve.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
