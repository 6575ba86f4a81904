"""Which tasks, algorithms and modes ``train`` / ``eval`` / ``compare`` take, read from the
catalogue (:mod:`mimo_social.envs.catalog`), and the error they raise for anything else.

* :data:`TASKS`: the one-agent tasks (catalogue kind ``"one-agent"``), task -> Gymnasium id;
* :data:`MULTI_TASKS`: the social tasks (``entry.social``), task -> PettingZoo module name
  (each module has ``parallel_env`` and ``scripted_env``);
* :data:`ALGOS`: ``ppo``, ``sac`` (Stable-Baselines3) and ``recurrent_ppo`` (sb3-contrib's
  ``RecurrentPPO``: an LSTM policy); :data:`RECURRENT_ALGOS`: those with memory;
  :data:`MODES`: how a social task learns (``shared``,
  ``independent``, ``scripted``; default ``shared``).
"""

from __future__ import annotations

from ..envs.catalog import CATALOG, entry

__all__ = ["TASKS", "MULTI_TASKS", "ALL_TASKS", "ALGOS", "RECURRENT_ALGOS", "COMPARED_ALGOS",
           "MODES", "DEFAULT_MODE",
           "TrainInputError", "check_task", "check_algo", "check_mode", "task_module",
           "algo_class"]

TASKS = {e.name: e.gym_id for e in CATALOG if e.kind == "one-agent"}
MULTI_TASKS = {e.name: e.module.__name__ for e in CATALOG if e.social}
ALL_TASKS = (*TASKS, *MULTI_TASKS)
ALGOS = ("ppo", "sac", "recurrent_ppo")
#: the algorithms whose policy keeps a state across an episode's steps (an LSTM)
RECURRENT_ALGOS = ("recurrent_ppo",)
#: what ``compare`` trains when not told which algorithms
COMPARED_ALGOS = ("ppo", "sac")
MODES = ("shared", "independent", "scripted")
DEFAULT_MODE = "shared"


class TrainInputError(ValueError):
    """A task, mode or option that ``train`` / ``eval`` / ``compare`` cannot use (says why)."""


def check_task(task: str) -> str:
    """A one-agent task's Gymnasium id or a social task's module name (``env_id`` of
    ``config.json``), else an error naming the allowed tasks."""
    if task in MULTI_TASKS:
        return MULTI_TASKS[task]
    if task not in TASKS:
        raise TrainInputError(f"task {task!r} not allowed; allowed: {', '.join(ALL_TASKS)} "
                              f"(one-agent: {', '.join(TASKS)}; multi-agent: "
                              f"{', '.join(MULTI_TASKS)})")
    return TASKS[task]


def check_algo(algo: str) -> str:
    if algo not in ALGOS:
        raise TrainInputError(f"algo {algo!r} not allowed; allowed: {', '.join(ALGOS)}")
    return algo


def algo_class(algo: str):
    """The SB3 class of an algorithm name (``recurrent_ppo``: sb3-contrib's ``RecurrentPPO``;
    a TrainInputError saying how to install sb3-contrib if it is missing)."""
    if check_algo(algo) == "recurrent_ppo":
        try:
            from sb3_contrib import RecurrentPPO
        except ImportError:
            raise TrainInputError("--algo recurrent_ppo needs sb3-contrib (pip install "
                                  "'sb3-contrib>=2.4,<3', the version of stable-baselines3)"
                                  ) from None
        return RecurrentPPO
    from stable_baselines3 import PPO, SAC
    return {"ppo": PPO, "sac": SAC}[algo]


def task_module(task: str):
    """The PettingZoo module of a multi-agent task, else a TrainInputError naming the allowed
    tasks."""
    if task not in MULTI_TASKS:
        raise TrainInputError(f"multi-agent task {task!r} not allowed; allowed: "
                              f"{', '.join(MULTI_TASKS)}")
    module = entry(task).module
    missing = [f for f in ("parallel_env", "scripted_env")
               if not callable(getattr(module, f, None))]
    if missing:
        raise TrainInputError(f"task {task!r}: module {module.__name__} lacks "
                              f"{', '.join(missing)} (a multi-agent task module needs "
                              "parallel_env and scripted_env)")
    return module


def check_mode(task: str, mode: str | None) -> str | None:
    """The mode to use: ``None`` for one-agent tasks, one of :data:`MODES` for the others."""
    if task in TASKS:
        if mode not in (None, DEFAULT_MODE):
            raise TrainInputError(f"--mode {mode!r} is for the multi-agent tasks "
                                  f"({', '.join(MULTI_TASKS)}); {task!r} has one agent: leave "
                                  "--mode out")
        return None
    if task not in MULTI_TASKS:
        raise TrainInputError(f"task {task!r} not allowed; allowed: {', '.join(ALL_TASKS)}")
    mode = DEFAULT_MODE if mode is None else mode
    if mode not in MODES:
        raise TrainInputError(f"mode {mode!r} not allowed; allowed: {', '.join(MODES)}")
    return mode
