"""Training throughput (issue 29): env steps per second of SB3 PPO training against the env
alone, per task and number of env workers.

Two measurements per configuration (task, workers), made back to back, their order alternating
from one configuration to the next (env first, then PPO first, ...) so that a change in the
machine's load meets both sides alike:

``env alone``
    The learner's vector env, built as training builds it (the caller's ``make_vec_env(task,
    workers)``: the same env factory and the same vector env class with ``workers`` envs),
    stepped with uniformly random actions drawn beforehand from its action space
    (:func:`env_alone`). Timed: ``steps`` env steps (``steps / workers`` vector steps, episodes
    reset as they end) after the build, a reset and :data:`ENV_WARMUP` untimed vector steps.
``PPO``
    A whole training run by the caller's function (``mimo_social.train.train``: the shipped
    hyperparameters, ``workers`` envs), whose learning phase is read from the files the run
    writes (:func:`learning_phase`): from its first checkpoint, saved from SB3's callback on
    the first env step after the first update, to ``model.zip``, saved as soon as
    ``model.learn`` returns. The figure is the env steps in between over that wall time:
    rollouts (env steps, policy inference), the PPO updates and the checkpoints saved in
    between; not the start (processes, model, the first rollout and update) nor the final
    evaluation, which are timed apart (``startup_s``: the call's start to the first checkpoint;
    ``final_s``: ``model.zip`` to the call's end, the final evaluation's ``eval_steps`` env steps
    and the files written).

This layer does not import the training layer: :func:`measure` takes the two measuring
functions (``env_rate(config, steps, seed)`` and ``ppo_rate(config, steps, seed)``, each a
dict with at least ``steps_per_s``); ``mimo-social bench training`` passes those of SB3
(:mod:`mimo_social.cli.bench_training`). :func:`markdown` writes the table, the machine and
issue 29's targets (:data:`TARGETS`).
"""

from __future__ import annotations

import json
import re
import time
from dataclasses import asdict, dataclass
from importlib import metadata
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np

from .machine import load_average, machine_info

__all__ = ["TrainingConfig", "DEFAULT_TASKS", "DEFAULT_WORKERS", "TARGETS", "TARGET_WORKERS",
           "TARGET_ENVS_PER_WORKER",
           "ENV_WARMUP", "configs", "env_alone", "learning_phase", "measure", "targets",
           "format_table", "markdown"]

#: the tasks of issue 29: reach (one agent), high five and mirror (its learner with eyes), the
#: social ones with one learner and the partner scripted
DEFAULT_TASKS = ("reach", "high_five", "mirror")
DEFAULT_WORKERS = (1, 2)
#: issue 29's targets: PPO's steps/s at least this fraction of the env alone's, with
#: :data:`TARGET_WORKERS` workers
TARGETS = {"reach": 0.60, "high_five": 0.60, "mirror": 0.40}
TARGET_WORKERS = 2
#: the envs per worker the targets are read at: ``train``'s default
TARGET_ENVS_PER_WORKER = 1
#: untimed vector steps of the env alone after its reset
ENV_WARMUP = 10

Rate = Callable[["TrainingConfig", int, int], dict]


@dataclass(frozen=True)
class TrainingConfig:
    """One configuration: ``task``, its training ``mode`` (None: a one-agent task; ``scripted``:
    one learner, the partner scripted), the number of env ``workers`` (processes) and the envs
    each steps (``envs_per_worker``; ``n_envs`` in all)."""

    task: str
    mode: str | None
    workers: int
    envs_per_worker: int = 1

    @property
    def n_envs(self) -> int:
        return self.workers * self.envs_per_worker

    @property
    def name(self) -> str:
        mode = f" --mode {self.mode}" if self.mode else ""
        return (f"{self.task}{mode}, {self.workers} worker{'s' if self.workers > 1 else ''} x "
                f"{self.envs_per_worker} env{'s' if self.envs_per_worker > 1 else ''}")


def configs(tasks: Sequence[str], workers: Sequence[int],
            modes: Mapping[str, str | None],
            envs_per_worker: Sequence[int] = (1,)) -> list[TrainingConfig]:
    """Every task x workers x envs-per-worker configuration, a task's next to each other;
    ``modes``: every task that may be measured -> its training mode. ValueError, naming what is
    allowed, for an unknown task or a count below 1."""
    for k in envs_per_worker:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise ValueError(f"envs_per_worker={k!r}; allowed: integers >= 1, e.g. 1,4")
    tasks, workers = list(tasks), list(workers)
    if not tasks:
        raise ValueError("no task given; allowed: " + ", ".join(modes))
    bad = [t for t in tasks if t not in modes]
    if bad:
        raise ValueError(f"unknown task {', '.join(map(repr, bad))}; allowed: "
                         + ", ".join(modes))
    if not workers:
        raise ValueError("no worker count given; allowed: integers >= 1, e.g. 1,2")
    for n in workers:
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"workers={n!r}; allowed: integers >= 1, e.g. 1,2")
    if len(set(tasks)) != len(tasks) or len(set(workers)) != len(workers):
        raise ValueError(f"a task or worker count is repeated: tasks {tasks}, workers {workers}")
    return [TrainingConfig(t, modes[t], int(n), int(k)) for t in tasks for n in workers
            for k in dict.fromkeys(envs_per_worker)]


def _check_steps(steps: int) -> int:
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 1:
        raise ValueError(f"steps={steps!r}; allowed: a positive integer")
    return int(steps)


# -- the env alone --------------------------------------------------------------------------------
def env_alone(make_vec_env: Callable[[], object], steps: int, seed: int = 0) -> dict:
    """The vector env ``make_vec_env()`` (an SB3 ``VecEnv``) stepped with random actions:
    ``steps`` env steps (rounded up to whole vector steps) after a reset and
    :data:`ENV_WARMUP` untimed vector steps; wall-clock time (the envs may be other processes).
    The actions are drawn from the action space (seeded) before the clock starts."""
    steps = _check_steps(steps)
    t0 = time.perf_counter()
    venv = make_vec_env()
    try:
        n = int(venv.num_envs)
        space = venv.action_space
        space.seed(int(seed))
        vec_steps = -(-steps // n)
        actions = [np.stack([space.sample() for _ in range(n)])
                   for _ in range(ENV_WARMUP + vec_steps)]
        venv.seed(int(seed))
        venv.reset()
        for a in actions[:ENV_WARMUP]:
            venv.step(a)
        startup = time.perf_counter() - t0
        t1 = time.perf_counter()
        for a in actions[ENV_WARMUP:]:
            venv.step(a)
        seconds = time.perf_counter() - t1
    finally:
        venv.close()
    return {"env_steps": vec_steps * n, "seconds": round(seconds, 3),
            "steps_per_s": vec_steps * n / seconds, "startup_s": round(startup, 2)}


# -- PPO: the learning phase of a run, from its files -------------------------------------------
_CHECKPOINT = re.compile(r"model_(\d+)_steps\.zip")


def learning_phase(out: str | Path, call_start: float, call_end: float) -> dict:
    """The learning phase of the one-learner run in ``out`` (written by ``train``), from its
    files: ``config.json`` (``timesteps_done``, ``eval_steps_done``, ``wall_time_s``, PPO's
    ``n_steps`` and ``n_envs``), the checkpoints ``checkpoints/model_<n>_steps.zip`` and
    ``model.zip``, their modification times (``time.time()``'s clock, as ``call_start`` and
    ``call_end``, the train call's). From the first checkpoint after the first update to
    ``model.zip`` (module docstring); ValueError if the run has no such checkpoint."""
    out = Path(out)
    config = json.loads((out / "config.json").read_text())
    n_envs = int(config.get("n_envs", 1))
    rollout = int(config["algo_kwargs"]["n_steps"]) * n_envs
    done = int(config["timesteps_done"])
    marks = sorted((int(m.group(1)), p.stat().st_mtime)
                   for p in (out / "checkpoints").glob("model_*_steps.zip")
                   if (m := _CHECKPOINT.fullmatch(p.name)))
    after = [(n, t) for n, t in marks if rollout < n < done]
    if not after:
        raise ValueError(f"{out}: no checkpoint between the first update ({rollout} steps) and "
                         f"the end ({done} steps): too few steps to time the learning phase")
    n0, t0 = after[0]
    t_end = (out / "model.zip").stat().st_mtime
    seconds = t_end - t0
    return {"env_steps": done - n0, "seconds": round(seconds, 3),
            "steps_per_s": (done - n0) / seconds, "timesteps_done": done,
            "rollout": rollout, "first_mark": n0,
            "startup_s": round(t0 - call_start, 2), "final_s": round(call_end - t_end, 2),
            "eval_steps": int(config.get("eval_steps_done", 0)),
            "call_s": round(call_end - call_start, 2),
            "call_steps_per_s": done / (call_end - call_start),
            "config_wall_time_s": config.get("wall_time_s"),
            "checkpoints_in_phase": sum(1 for n, _ in marks if n0 < n <= done),
            "policy": config.get("policy"), "normalize_obs": config.get("normalize_obs")}


# -- the measurement ---------------------------------------------------------------------------
def measure(configurations: Sequence[TrainingConfig], steps: int | Mapping[str, int], *,
            env_rate: Rate, ppo_rate: Rate, seed: int = 0, progress: bool = False,
            command: str = "", settings: Mapping | None = None) -> dict:
    """Each configuration's env alone and PPO (``env_rate`` / ``ppo_rate(config, steps, seed)``,
    each a dict with ``steps_per_s``), back to back, their order alternating from one
    configuration to the next; a tqdm bar with ``progress``. ``steps``: env steps per
    configuration, or task -> env steps. The results (plain JSON): one row per configuration,
    the machine, the load averages, the date."""
    per_task = {c.task: _check_steps(steps[c.task] if isinstance(steps, Mapping) else steps)
                for c in configurations}
    from tqdm import tqdm

    rows = []
    load_before = load_average()
    t0 = time.time()
    bar = tqdm(total=2 * len(configurations), disable=not progress, unit="run",
               desc="bench training", dynamic_ncols=True)
    try:
        for i, config in enumerate(configurations):
            order = ("env", "ppo") if i % 2 == 0 else ("ppo", "env")
            got = {}
            for side in order:
                bar.set_postfix_str(f"{config.name}: {'env alone' if side == 'env' else 'PPO'}")
                fn = env_rate if side == "env" else ppo_rate
                got[side] = dict(fn(config, per_task[config.task], seed))
                got[side]["load"] = load_average()
                bar.update(1)
            rows.append({**asdict(config), "config": config.name, "order": list(order),
                         "steps": per_task[config.task],
                         "env": got["env"], "ppo": got["ppo"],
                         "ratio": got["ppo"]["steps_per_s"] / got["env"]["steps_per_s"]})
    finally:
        bar.close()
    return {"rows": rows, "steps": per_task, "seed": seed, "settings": dict(settings or {}),
            "command": command, "machine": {**machine_info(), **_versions()},
            "load_before": load_before, "load_after": load_average(),
            "measured": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(t0)),
            "total_s": round(time.time() - t0, 1)}


def _versions() -> dict:
    out = {}
    for name in ("torch", "stable_baselines3"):
        try:
            out[name] = metadata.version(name.replace("_", "-"))
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def targets(results: dict) -> list[dict]:
    """Issue 29's targets (:data:`TARGETS`, with :data:`TARGET_WORKERS` workers of
    :data:`TARGET_ENVS_PER_WORKER` envs, train's default) for the measured tasks: task, the
    ratio wanted, the ratio measured and whether it is met (None: not measured so)."""
    by = {(r["task"], r["workers"], r.get("envs_per_worker", 1)): r["ratio"]
          for r in results["rows"]}
    out = []
    for task in dict.fromkeys(r["task"] for r in results["rows"]):
        if task in TARGETS:
            got = by.get((task, TARGET_WORKERS, TARGET_ENVS_PER_WORKER))
            out.append({"task": task, "workers": TARGET_WORKERS,
                        "envs_per_worker": TARGET_ENVS_PER_WORKER, "wanted": TARGETS[task],
                        "ratio": got, "met": None if got is None else got >= TARGETS[task]})
    return out


def format_table(results: dict) -> str:
    """The markdown table: per task and workers the env alone's and PPO's env steps/s, their
    ratio, the whole train call's steps/s and the parts of the call outside the timed phase."""
    lines = ["| task | workers x envs | env alone steps/s | PPO steps/s | PPO / env | whole "
             "train() steps/s | start s (to the 1st update's end) | final eval steps, s |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results["rows"]:
        e, p = r["env"], r["ppo"]
        task = f"`{r['task']}`" + (f" ({r['mode']})" if r["mode"] else "")
        lines.append(f"| {task} | {r['workers']} x {r.get('envs_per_worker', 1)} | "
                     f"{e['steps_per_s']:.0f} | "
                     f"{p['steps_per_s']:.0f} | **{r['ratio']:.0%}** | "
                     f"{p.get('call_steps_per_s', float('nan')):.0f} | "
                     f"{p.get('startup_s', float('nan')):.1f} | "
                     f"{p.get('eval_steps', '-')}, {p.get('final_s', float('nan')):.1f} |")
    return "\n".join(lines)


def markdown(results: dict) -> str:
    """The machine line, the table, what the figures include and issue 29's targets."""
    m = results["machine"]
    load = results["load_before"]
    text = [f"Measured {results['measured']} on {m['cpu']} ({m['usable_cores']} usable cores "
            f"of {m['cores']}), Python {m['python']}, MuJoCo {m['mujoco']}, torch "
            f"{m.get('torch')}, SB3 {m.get('stable_baselines3')}; load average before "
            f"{load}, after {results['load_after']}; env steps per configuration: "
            + ", ".join(f"{t} {n}" for t, n in results["steps"].items())
            + f"; {results['total_s'] / 60:.1f} min in all.", "",
            format_table(results), "",
            "PPO steps/s: env steps over wall time of the learning phase, from the first "
            "checkpoint after the first update to model.zip (rollouts, inference, PPO updates, "
            "checkpoints); the start (workers, model, first rollout and update) and the final "
            "evaluation (both policies, 1 episode each) are the last two columns. Env alone: "
            "the same vector env, random actions, after a reset and a warm-up."]
    met = targets(results)
    if met:
        text.append("")
        for t in met:
            verdict = ("not measured" if t["met"] is None
                       else f"{t['ratio']:.0%}: {'met' if t['met'] else 'NOT met'}")
            k = t["envs_per_worker"]
            text.append(f"- `{t['task']}`, {t['workers']} workers x {k} "
                        f"env{'s' if k > 1 else ''}: target >= "
                        f"{t['wanted']:.0%} of the env alone; {verdict}")
    if results.get("command"):
        text += ["", "```", results["command"], "```"]
    return "\n".join(text) + "\n"
