"""``build_config``: the RLlib ``AlgorithmConfig`` of a task, mode and algorithm.

``build_config(task, mode=None, algo="ppo", seed=0, *, num_env_runners=1,
num_envs_per_runner=1, env_kwargs=None, algo_kwargs=None, num_cpus_per_learner=1,
num_gpus_per_learner=0, normalize_obs=False) -> AlgorithmConfig``

* ``task``: any task of :data:`~mimo_social.train.tasks.ALL_TASKS`; ``mode``: ``shared`` (one
  module ``"shared"`` for every agent; their flat spaces must be equal), ``independent`` (one
  module per agent, named as the agent: heterogeneous agents, i.e. different bodies, hands or
  senses, each get their own spaces), ``scripted`` (one module for the learner, the partner
  scripted), None for a one-agent task (one module named as its agent).
* ``algo``: :data:`RLLIB_ALGOS`. ``ppo`` and ``appo`` take every action space of the catalogue
  (Box, and ``Discrete`` for a face-only agent); ``sac`` takes Box and ``Discrete`` actions too
  (RLlib's SAC module has a discrete head), with a multi-agent episode replay buffer.
* Defaults follow the SB3 path: PPO with SB3's hyperparameters (2048 steps per update,
  minibatches of 64, 10 epochs, lr 3e-4, two tanh layers of 64) and SB3's policy and loss:
  separate policy and value networks (``vf_share_layers=False``), a state-free log std
  starting at 0 (``free_log_std``, Box actions only), SB3's initial weights (:mod:`.sb3_init`:
  orthogonal, gain 0.01 on the action means, so the first mean |action| is ~0.005 as in SB3
  rather than RLlib's ~0.1), no KL penalty (``use_kl_loss=False``) and no value-loss clipping
  (``vf_clip_param=inf``; RLlib's 10 clamps the squared value error, so the critic gets no
  gradient once it is off by more than ~3, and high five's returns are in the hundreds). With
  RLlib's own settings for these five, PPO never reached 80 % success on high five in 70k env
  steps where SB3 does in 60k; with them it does in ~51k. Putting any one of them back alone
  (RLlib's init, a shared encoder, a state-dependent log std or ``vf_clip_param=10``) still
  learned it in 20-51k (one seed each): no single one is the cause, hence all SB3's. RLlib standardises the advantages
  over the whole train batch, SB3 per minibatch: left as is. SAC with two ReLU layers of
  256, lr 3e-4, batch 256, learning from step 100; APPO with RLlib's defaults and two tanh
  layers of 64. ``algo_kwargs`` override: keys of RLlib's ``DefaultModelConfig``
  (``fcnet_hiddens``, ``fcnet_activation``, ...) go to the model, every other key to
  ``config.training(...)``.
* ``num_env_runners`` (0: sample in the driver) x ``num_envs_per_runner`` envs, one CPU a
  runner; one local learner with ``num_cpus_per_learner`` / ``num_gpus_per_learner``.
* ``normalize_obs``: RLlib's ``MeanStdFilter`` connector on every observation (running mean
  and std, kept in the checkpoint), as ``--normalize-obs`` of the SB3 path; eye images are
  already scaled to [0, 1] by the flat env either way.

``module_ids(task, mode, agents)``: agent -> RLModule id. The envs are made in the env runners
by :class:`~mimo_social.train.rllib.env.CatalogEnv` (the env creator of
:mod:`mimo_social.train.rllib.env` as a class) from ``env_config = {"task", "mode",
"env_kwargs"}``; ``config.environment(env_name(task))`` after ``register_rllib_envs()`` is the
same env by its tune-registry name.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Mapping

from ..tasks import TrainInputError, check_mode, check_task

__all__ = ["RLLIB_ALGOS", "SHARED", "build_config", "module_ids", "flat_spaces",
           "split_algo_kwargs", "quiet_rllib"]

RLLIB_ALGOS = ("ppo", "appo", "sac")
SHARED = "shared"

_DEFAULTS = {
    "ppo": ({"fcnet_hiddens": [64, 64], "fcnet_activation": "tanh",
             "vf_share_layers": False, "free_log_std": True},
            {"lr": 3e-4, "gamma": 0.99, "lambda_": 0.95, "clip_param": 0.2,
             "entropy_coeff": 0.0, "vf_loss_coeff": 0.5, "grad_clip": 0.5,
             "train_batch_size_per_learner": 2048, "minibatch_size": 64, "num_epochs": 10,
             "use_kl_loss": False, "vf_clip_param": float("inf")}),
    "appo": ({"fcnet_hiddens": [64, 64], "fcnet_activation": "tanh"}, {}),
    "sac": ({"fcnet_hiddens": [256, 256], "fcnet_activation": "relu"},
            {"actor_lr": 3e-4, "critic_lr": 3e-4, "alpha_lr": 3e-4, "gamma": 0.99,
             "tau": 0.005, "train_batch_size_per_learner": 256,
             "num_steps_sampled_before_learning_starts": 100,
             "replay_buffer_config": {"type": "MultiAgentEpisodeReplayBuffer",
                                      "capacity": 1_000_000}}),
}


def quiet_rllib() -> None:
    """RLlib's notices about its new API stack and deprecations off in this process."""
    import logging
    import warnings

    for name in ("ray.rllib", "ray.tune", "ray._common.deprecation"):
        logging.getLogger(name).setLevel(logging.ERROR)
    warnings.filterwarnings("ignore", category=DeprecationWarning, module=r"ray\..*")


def _to_shared(agent_id, episode=None, **kwargs):
    return SHARED


def _to_self(agent_id, episode=None, **kwargs):
    return agent_id


def module_ids(task: str, mode: str | None, agents) -> dict[str, str]:
    """agent -> RLModule id: ``"shared"`` for every agent in ``shared`` mode, else the agent's
    own name."""
    mode = check_mode(task, mode)
    return {a: (SHARED if mode == "shared" else a) for a in agents}


def flat_spaces(task: str, mode: str | None, env_kwargs: Mapping[str, Any] | None = None):
    """``(agents, {agent: (observation space, action space)})`` of the flat env a mode learns
    on (made once here, never reset: no renderer is started). ``shared`` mode with agents whose
    spaces differ is a TrainInputError saying to use ``independent``."""
    from ..multi import check_shared_spaces
    from .env import flat_env

    env = flat_env(task, mode, **dict(env_kwargs or {}))
    try:
        if mode == "shared":
            check_shared_spaces(env, task)
        agents = list(env.possible_agents)
        return agents, {a: (env.observation_space(a), env.action_space(a)) for a in agents}
    finally:
        env.close()


def split_algo_kwargs(algo: str, algo_kwargs: Mapping[str, Any] | None):
    """``(model_config, training_kwargs)``: the defaults of ``algo`` with ``algo_kwargs`` over
    them (model keys to the model, the rest to ``training()``)."""
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig

    model_keys = {f.name for f in dataclasses.fields(DefaultModelConfig)}
    model, training = (dict(d) for d in _DEFAULTS[algo])
    for k, v in dict(algo_kwargs or {}).items():
        (model if k in model_keys else training)[k] = v
    return model, training


def _algo_config_class(algo: str):
    if algo == "ppo":
        from ray.rllib.algorithms.ppo import PPOConfig
        return PPOConfig
    if algo == "appo":
        from ray.rllib.algorithms.appo import APPOConfig
        return APPOConfig
    from ray.rllib.algorithms.sac import SACConfig
    return SACConfig


def check_algo(algo: str) -> str:
    if algo not in RLLIB_ALGOS:
        raise TrainInputError(f"algo {algo!r} not allowed with --engine rllib; allowed: "
                              f"{', '.join(RLLIB_ALGOS)}")
    return algo


def _module_kwargs(algo: str, model_config, act_space) -> dict:
    """RLModuleSpec's model config (and, for PPO, SB3's initial weights: :mod:`.sb3_init`);
    ``free_log_std`` only where the actions are a Box (RLlib refuses it for Discrete)."""
    import gymnasium as gym

    if model_config.free_log_std and not isinstance(act_space, gym.spaces.Box):
        model_config = dataclasses.replace(model_config, free_log_std=False)
    if algo != "ppo":
        return {"model_config": model_config}
    from ray.rllib.algorithms.ppo.ppo_catalog import PPOCatalog

    from .sb3_init import SB3InitPPOModule
    return {"model_config": model_config, "module_class": SB3InitPPOModule,
            "catalog_class": PPOCatalog}


def build_config(task: str, mode: str | None = None, algo: str = "ppo", seed: int = 0, *,
                 num_env_runners: int = 1, num_envs_per_runner: int = 1,
                 env_kwargs: Mapping[str, Any] | None = None,
                 algo_kwargs: Mapping[str, Any] | None = None,
                 num_cpus_per_learner: int = 1, num_gpus_per_learner: float = 0,
                 normalize_obs: bool = False, spaces: tuple | None = None):
    """The ``AlgorithmConfig`` (new API stack, torch) of a run; see the module docstring.
    ``spaces``: :func:`flat_spaces`'s answer, when the caller has it already."""
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig
    from ray.rllib.core.rl_module.multi_rl_module import MultiRLModuleSpec
    from ray.rllib.core.rl_module.rl_module import RLModuleSpec

    from .callbacks import EpisodeLog
    from .env import CatalogEnv

    check_task(task)
    mode = check_mode(task, mode)
    check_algo(algo)
    if int(num_env_runners) < 0 or int(num_envs_per_runner) < 1:
        raise TrainInputError(f"num_env_runners={num_env_runners} (allowed: >= 0), "
                              f"num_envs_per_runner={num_envs_per_runner} (allowed: >= 1)")
    env_kwargs = dict(env_kwargs or {})
    agents, per_agent = spaces if spaces is not None else flat_spaces(task, mode, env_kwargs)
    ids = module_ids(task, mode, agents)
    model, training = split_algo_kwargs(algo, algo_kwargs)
    try:
        model_config = DefaultModelConfig(**model)
    except TypeError as e:
        raise TrainInputError(f"algo_kwargs: bad model setting: {e}") from None
    specs = {}
    for a in agents:
        if ids[a] not in specs:
            obs_space, act_space = per_agent[a]
            specs[ids[a]] = RLModuleSpec(observation_space=obs_space, action_space=act_space,
                                         **_module_kwargs(algo, model_config, act_space))
    config = (_algo_config_class(algo)()
              .api_stack(enable_rl_module_and_learner=True,
                         enable_env_runner_and_connector_v2=True)
              .framework("torch")
              .environment(CatalogEnv,
                           env_config={"task": task, "mode": mode, "env_kwargs": env_kwargs},
                           disable_env_checking=True)
              .env_runners(num_env_runners=int(num_env_runners),
                           num_envs_per_env_runner=int(num_envs_per_runner),
                           num_cpus_per_env_runner=1)
              .learners(num_learners=0, num_cpus_per_learner=num_cpus_per_learner,
                        num_gpus_per_learner=num_gpus_per_learner)
              .multi_agent(policies=set(specs),
                           policy_mapping_fn=_to_shared if mode == "shared" else _to_self,
                           policies_to_train=sorted(specs))
              .rl_module(rl_module_spec=MultiRLModuleSpec(rl_module_specs=specs))
              .callbacks(EpisodeLog)
              .debugging(seed=int(seed)))
    if algo != "appo":  # (APPO's minibatches are whole fragments: keep its 50)
        config = config.env_runners(rollout_fragment_length="auto")
    if normalize_obs:
        from ray.rllib.connectors.env_to_module import MeanStdFilter
        config = config.env_runners(
            env_to_module_connector=lambda env, spaces=None, device=None: MeanStdFilter(
                multi_agent=True))
    try:
        config = config.training(**training)
    except TypeError as e:
        raise TrainInputError(f"algo_kwargs: {e} (a key of {algo.upper()}'s training() or of "
                              "RLlib's DefaultModelConfig)") from None
    return config
