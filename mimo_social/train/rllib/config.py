"""``build_config``: the RLlib ``AlgorithmConfig`` of a task, mode and algorithm.

``build_config(task, mode=None, algo="ppo", seed=0, *, num_env_runners=1,
num_envs_per_runner=1, env_kwargs=None, algo_kwargs=None, num_cpus_per_learner=1,
num_gpus_per_learner=0, normalize_obs=False, flat_obs=False, frame_stack=1) -> AlgorithmConfig``

* ``task``: any task of :data:`~mimo_social.train.tasks.ALL_TASKS`; ``mode``: ``shared`` (one
  module ``"shared"`` for every agent; their spaces must be equal), ``independent`` (one
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
  learned it in 20-51k (one seed each): no single one is the cause, hence all SB3's.
  RLlib standardises the advantages over the whole train batch, SB3 per minibatch: left as
  is. SAC with two ReLU layers of 256, lr 3e-4, batch 256, learning from step 100; APPO with
  RLlib's defaults and two tanh layers of 64. ``algo_kwargs`` override: keys of RLlib's
  ``DefaultModelConfig`` (``fcnet_hiddens``, ``fcnet_activation``, ...) go to the model, every
  other key to ``config.training(...)``.
* ``num_env_runners`` (0: sample in the driver) x ``num_envs_per_runner`` envs, one CPU a
  runner; one local learner with ``num_cpus_per_learner`` / ``num_gpus_per_learner``.
* Eyes: an agent with eyes sees the image ``Dict`` of
  :func:`~mimo_social.train.rllib.env.learner_env` (each eye ``uint8`` channel-first
  ``(3 * frame_stack, H, W)``, the other senses one float32 ``"vector"``) and, with PPO and
  APPO, gets the CNN module of :mod:`~mimo_social.train.rllib.module` (``EyesPPOModule`` /
  ``EyesAPPOModule``: a CNN per eye, the same as the SB3 path's, its features and the vector
  into SB3's policy and value MLPs), per policy: in ``shared`` mode the one module, in
  ``independent`` mode each agent with eyes (an agent without keeps RLlib's default module on
  its Box), in ``scripted`` mode the learner. ``algo_kwargs`` ``image_dim`` (128 features per
  eye) and ``share_weights`` (one CNN for same-shaped eyes, True) go to that module.
  RLlib's default env-to-module connectors batch the Dict as it is (they flatten nothing).
  ``flat_obs=True`` (and always ``sac``, whose RLlib module takes no image Dict) is the flat
  path: every observation one float32 Box, eye images scaled to [0, 1] in it, RLlib's default
  MLP. ``frame_stack``: frames of each eye stacked along the channels (needs the image path
  and an agent with eyes).
* ``normalize_obs``: RLlib's ``MeanStdFilter`` connector on every observation (running mean
  and std, kept in the checkpoint), as ``--normalize-obs`` of the SB3 path; on the image path
  the CNN module normalises its ``"vector"`` itself (running statistics in the module's
  buffers, updated by the learner; the pixels are only scaled to [0, 1]), and a run whose
  agents mix image Dicts and Boxes (``independent``, eyes on one agent) needs ``flat_obs``.

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

__all__ = ["RLLIB_ALGOS", "SHARED", "build_config", "module_ids", "flat_spaces", "learner_spaces",
           "split_algo_kwargs", "quiet_rllib", "uses_images", "obs_filter", "is_flat",
           "EYES_KEYS"]

RLLIB_ALGOS = ("ppo", "appo", "sac")
SHARED = "shared"
#: ``algo_kwargs`` of the CNN module (:mod:`.module`), besides RLlib's model keys
EYES_KEYS = ("image_dim", "share_weights")

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


def is_flat(algo: str, flat_obs: bool = False) -> bool:
    """Whether a run is on the flat path: ``flat_obs`` or SAC (module docstring)."""
    return bool(flat_obs) or algo == "sac"


def learner_spaces(task: str, mode: str | None, env_kwargs: Mapping[str, Any] | None = None, *,
                   flat: bool = False, frame_stack: int = 1):
    """``(agents, {agent: (observation space, action space)})`` of the env a mode learns on
    (:func:`~mimo_social.train.rllib.env.learner_env`, made once here, never reset: no renderer
    is started). ``shared`` mode with agents whose spaces differ is a TrainInputError saying to
    use ``independent``; so is a ``frame_stack`` the images do not allow or that has no image
    to stack."""
    from ..multi import check_shared_spaces
    from .env import learner_env

    if isinstance(frame_stack, bool) or not isinstance(frame_stack, int) or frame_stack < 1:
        raise TrainInputError(f"frame_stack={frame_stack!r}; allowed: an integer >= 1")
    if frame_stack > 1 and flat:
        raise TrainInputError(f"frame_stack={frame_stack} stacks eye images for the CNN: not "
                              "with flat observations (flat_obs, or SAC)")
    try:
        env = learner_env(task, mode, flat=flat, frame_stack=frame_stack,
                          **dict(env_kwargs or {}))
    except ValueError as e:
        if frame_stack == 1:
            raise
        raise TrainInputError(str(e)) from None
    try:
        if mode == "shared":
            check_shared_spaces(env, task)
        agents = list(env.possible_agents)
        per_agent = {a: (env.observation_space(a), env.action_space(a)) for a in agents}
    finally:
        env.close()
    if frame_stack > 1 and not uses_images(per_agent):
        raise TrainInputError(f"frame_stack={frame_stack} stacks eye images, but no agent of "
                              f"{task!r} has eyes (env_kwargs 'vision' turns them on)")
    return agents, per_agent


def flat_spaces(task: str, mode: str | None, env_kwargs: Mapping[str, Any] | None = None):
    """:func:`learner_spaces` of the flat path (every observation one Box)."""
    return learner_spaces(task, mode, env_kwargs, flat=True)


def uses_images(per_agent: Mapping[str, tuple]) -> bool:
    """Whether any agent of ``{agent: (observation space, action space)}`` sees an image
    Dict (the CNN module's input)."""
    from .module import has_images

    return any(has_images(obs) for obs, _ in per_agent.values())


def obs_filter(normalize_obs: bool, per_agent: Mapping[str, tuple]) -> bool:
    """Whether ``normalize_obs`` puts RLlib's MeanStdFilter on the observations: on the flat
    path (every observation a Box); image Dicts are normalised in the CNN module, and a mix of
    the two is a TrainInputError."""
    if not normalize_obs:
        return False
    from .module import has_images

    images = {a for a, (obs, _) in per_agent.items() if has_images(obs)}
    if not images:
        return True
    if len(images) < len(per_agent):
        raise TrainInputError(
            f"normalize_obs with agents that see images ({', '.join(sorted(images))}) and "
            f"agents that do not: not supported; pass flat_obs=True (--flat-obs) to normalise "
            "every observation as one flat Box")
    return False


def split_algo_kwargs(algo: str, algo_kwargs: Mapping[str, Any] | None):
    """``(model_config, training_kwargs)``: the defaults of ``algo`` with ``algo_kwargs`` over
    them (model keys to the model, the rest to ``training()``)."""
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig

    model_keys = {f.name for f in dataclasses.fields(DefaultModelConfig)} | set(EYES_KEYS)
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


def _eyes_kwargs(algo: str, model_config, eyes: Mapping[str, Any], normalize: bool) -> dict:
    """RLModuleSpec's module class and model config for an agent that sees an image Dict."""
    from .module import DEFAULTS, EyesAPPOModule, EyesPPOModule

    cfg = {**DEFAULTS, "fcnet_hiddens": list(model_config.fcnet_hiddens),
           "fcnet_activation": model_config.fcnet_activation,
           "free_log_std": bool(model_config.free_log_std), **dict(eyes),
           "normalize_vector": bool(normalize)}
    return {"module_class": EyesAPPOModule if algo == "appo" else EyesPPOModule,
            "model_config": cfg}


def build_config(task: str, mode: str | None = None, algo: str = "ppo", seed: int = 0, *,
                 num_env_runners: int = 1, num_envs_per_runner: int = 1,
                 env_kwargs: Mapping[str, Any] | None = None,
                 algo_kwargs: Mapping[str, Any] | None = None,
                 num_cpus_per_learner: int = 1, num_gpus_per_learner: float = 0,
                 normalize_obs: bool = False, flat_obs: bool = False, frame_stack: int = 1,
                 spaces: tuple | None = None):
    """The ``AlgorithmConfig`` (new API stack, torch) of a run; see the module docstring.
    ``spaces``: :func:`learner_spaces`'s answer (of the same ``flat_obs``, ``frame_stack``),
    when the caller has it already."""
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
    flat = is_flat(algo, flat_obs)
    if spaces is None:
        spaces = learner_spaces(task, mode, env_kwargs, flat=flat, frame_stack=frame_stack)
    agents, per_agent = spaces
    ids = module_ids(task, mode, agents)
    model, training = split_algo_kwargs(algo, algo_kwargs)
    eyes = {k: model.pop(k) for k in EYES_KEYS if k in model}
    if eyes and (flat or not uses_images(per_agent)):
        raise TrainInputError(f"algo_kwargs {', '.join(sorted(eyes))}: settings of the CNN of "
                              "an agent with eyes, and this run has none (no eyes, or flat)")
    use_filter = obs_filter(normalize_obs, per_agent)
    try:
        model_config = DefaultModelConfig(**model)
    except TypeError as e:
        raise TrainInputError(f"algo_kwargs: bad model setting: {e}") from None
    from .module import has_images

    specs = {}
    for a in agents:
        if ids[a] not in specs:
            obs_space, act_space = per_agent[a]
            kwargs = (_eyes_kwargs(algo, model_config, eyes, normalize_obs)
                      if has_images(obs_space) else
                      _module_kwargs(algo, model_config, act_space))
            specs[ids[a]] = RLModuleSpec(observation_space=obs_space, action_space=act_space,
                                         **kwargs)
    config = (_algo_config_class(algo)()
              .api_stack(enable_rl_module_and_learner=True,
                         enable_env_runner_and_connector_v2=True)
              .framework("torch")
              .environment(CatalogEnv,
                           env_config={"task": task, "mode": mode, "env_kwargs": env_kwargs,
                                       "flat": flat, "frame_stack": int(frame_stack)},
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
    if use_filter:
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
