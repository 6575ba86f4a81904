"""RLlib (Ray) engine of ``mimo-social train --engine rllib`` and ``eval`` of its runs.

Importing this package does not import ray: the names below are loaded on first use (ray is
the ``rllib`` extra: ``pip install -e ".[rllib]"``, or ``scripts/setup_rllib.sh`` for a second
venv). :func:`require_ray` raises a :class:`~mimo_social.train.tasks.TrainInputError`
saying how to install it.

``build_config(task, mode=None, algo="ppo", seed=0, *, num_env_runners=1,
num_envs_per_runner=1, env_kwargs=None, algo_kwargs=None, num_cpus_per_learner=1,
num_gpus_per_learner=0, normalize_obs=False, flat_obs=False, frame_stack=1) -> AlgorithmConfig``
    :mod:`~mimo_social.train.rllib.config`: PPO, APPO or SAC on any task of the catalogue in
    ``shared`` / ``independent`` / ``scripted`` mode (None for a one-agent task). Agents with
    eyes see image Dicts and learn with the CNN module of :mod:`~mimo_social.train.rllib.module`
    (PPO, APPO) unless ``flat_obs`` (or SAC).
``make_rllib_env(env_config)`` / ``env_name(task)`` / ``register_rllib_envs()``
    :mod:`~mimo_social.train.rllib.env`: the env creator, registered in Ray's tune registry as
    ``"mimo_social/<task>"``; ``env_config = {"task", "mode", "env_kwargs"}``.
``train_rllib(task, algo, steps, seed, out, *, mode=None, address=None, ...)``
    :mod:`~mimo_social.train.rllib.runner`: iterations up to a step budget, writing what the SB3
    path writes.
``evaluate_rllib(run, episodes, ...)``
    :mod:`~mimo_social.train.rllib.evaluation`: the episodes of ``mimo-social eval`` with the
    run's checkpointed RLModules.
"""

from __future__ import annotations

import importlib.util

from ..tasks import TrainInputError

__all__ = ["build_config", "module_ids", "flat_spaces", "learner_spaces", "RLLIB_ALGOS",
           "make_rllib_env", "env_name", "register_rllib_envs", "flat_env", "learner_env",
           "train_rllib", "evaluate_rllib",
           "require_ray", "ray_available", "INSTALL_HINT"]

INSTALL_HINT = ('install the rllib extra: pip install -e ".[rllib]" (ray[rllib]==2.60.0, which '
                "pins gymnasium 1.2.2), or scripts/setup_rllib.sh for a separate .venv-rllib")

_WHERE = {"build_config": "config", "module_ids": "config", "flat_spaces": "config",
          "learner_spaces": "config", "learner_env": "env",
          "RLLIB_ALGOS": "config", "make_rllib_env": "env", "env_name": "env",
          "register_rllib_envs": "env", "flat_env": "env", "train_rllib": "runner",
          "evaluate_rllib": "evaluation"}


def ray_available() -> bool:
    """Whether ray's RLlib can be imported here."""
    try:
        return importlib.util.find_spec("ray") is not None and \
            importlib.util.find_spec("ray.rllib") is not None
    except (ImportError, ValueError):
        return False


def require_ray() -> None:
    """A TrainInputError saying how to install ray when RLlib is missing."""
    if not ray_available():
        raise TrainInputError(f"--engine rllib needs ray's RLlib, which is not installed: "
                              f"{INSTALL_HINT}")


def __getattr__(name: str):
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    if where == "config":  # (imports ray only inside its functions)
        from . import config as module
    else:
        require_ray()
        if where == "env":
            from . import env as module
        elif where == "runner":
            from . import runner as module
        else:
            from . import evaluation as module
    return getattr(module, name)
