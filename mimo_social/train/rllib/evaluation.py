"""Episodes with RLlib's trained RLModules: ``evaluate_rllib`` (``mimo-social eval DIR`` of a
run made with ``--engine rllib``) and :class:`ModulePolicy`, which the training run's own
evaluations use too.

``evaluate_rllib(run, episodes=10, *, model="final", seed=0, deterministic=True, record=None,
video=None, frames=None, frame_every=1, env_kwargs=None)`` reloads each agent's RLModule from
the run's checkpoint (``final``: ``checkpoint/``, ``best``: ``best_checkpoint/``, or a path to an
``algo.save`` folder), runs the episodes on the env of the run's mode and observations (its
``config.json``'s ``"observation"``: image Dicts or flat; runs without it were flat) in this
process (no Ray cluster is started) and writes ``eval_results.json``, a Rerun recording, a
video or frames as the SB3 path does (:class:`~mimo_social.train.evaluation.EvalOutputs`).
"""

from __future__ import annotations

import json
import pickle
from pathlib import Path
from typing import Any, Mapping

import numpy as np
from gymnasium import spaces

from ..evaluation import check_outputs, evaluate_with_outputs
from ..tasks import TrainInputError
from .env import learner_env

__all__ = ["ModulePolicy", "evaluate_rllib", "load_policies", "module_dir", "CHECKPOINTS",
           "FILTER_FILE", "filters_from_state"]

#: ``--model`` names -> checkpoint folders of a run
CHECKPOINTS = {"final": "checkpoint", "best": "best_checkpoint"}
_MODULES = Path("learner_group") / "learner" / "rl_module"
#: the observation filter's state (``--normalize-obs``), saved next to RLlib's checkpoint files
#: (RLlib keeps it in the env runners only)
FILTER_FILE = "mimo_obs_filter.pkl"


class ModulePolicy:
    """An RLModule with SB3's ``predict(obs, deterministic) -> (action, None)``, so that the
    project's episode runners (:func:`~mimo_social.train.rollouts.evaluate_agents`) drive it.
    ``normalize``: a function applied to the observation first (the run's MeanStdFilter). An
    image Dict observation goes in as a Dict of tensors (uint8 images, float32 vector)."""

    def __init__(self, module, action_space: spaces.Space, normalize=None):
        self.module, self.action_space, self.normalize = module, action_space, normalize

    def predict(self, obs, deterministic: bool = True):
        import torch

        if isinstance(obs, Mapping):
            x = {k: torch.from_numpy(np.asarray(v)[None].copy()) for k, v in obs.items()}
        else:
            x = np.asarray(obs, dtype=np.float32)
            if self.normalize is not None:
                x = np.asarray(self.normalize(x), dtype=np.float32)
            x = torch.from_numpy(x[None])
        batch = {"obs": x}
        with torch.no_grad():
            if deterministic:
                out = self.module.forward_inference(batch)
                dist_cls = self.module.get_inference_action_dist_cls()
            else:
                out = self.module.forward_exploration(batch)
                dist_cls = self.module.get_exploration_action_dist_cls()
            if "actions" in out and "action_dist_inputs" not in out:
                action = out["actions"][0]
            else:
                dist = dist_cls.from_logits(out["action_dist_inputs"])
                if deterministic:
                    dist = dist.to_deterministic()
                action = dist.sample()[0]
        action = action.cpu().numpy()
        if isinstance(self.action_space, spaces.Discrete):
            return int(np.asarray(action).reshape(-1)[0]), None
        low, high = self.action_space.low, self.action_space.high
        return np.clip(action.astype(np.float32), low, high), None


def module_dir(checkpoint: Path, module_id: str) -> Path:
    """The folder of one RLModule inside an ``algo.save`` checkpoint."""
    return Path(checkpoint) / _MODULES / module_id


def _checkpoint(run: Path, model: str) -> Path:
    path = run / CHECKPOINTS[model] if model in CHECKPOINTS else Path(model)
    if not (path / _MODULES).is_dir():
        raise FileNotFoundError(f"RLlib checkpoint {path} not found (--model final, best or "
                                "a folder written by algo.save)")
    return path


def filters_from_state(state: Mapping | None, obs_spaces: Mapping[str, spaces.Space]) -> dict:
    """agent -> observation normaliser (no update) of a MeanStdFilter's state (the
    ``"MeanStdFilter"`` entry of an env-to-module pipeline's state); {} for None."""
    if not state:
        return {}
    from ray.rllib.connectors.env_to_module import MeanStdFilter

    filt = MeanStdFilter(multi_agent=True)
    filt.input_observation_space = spaces.Dict(dict(obs_spaces))
    filt.set_state(dict(state))
    out = {}
    for a in obs_spaces:
        f = (filt._filters or {}).get(a)
        if f is not None:
            out[a] = (lambda x, f=f: f(x, update=False))
    return out


def _filters(checkpoint: Path, obs_spaces: Mapping[str, spaces.Space]) -> dict:
    """agent -> observation normaliser of the run's MeanStdFilter ({} without one)."""
    path = Path(checkpoint) / FILTER_FILE
    if not path.exists():
        return {}
    return filters_from_state(pickle.loads(path.read_bytes()), obs_spaces)


def load_policies(checkpoint: Path, agent_modules: Mapping[str, str], env) -> dict:
    """agent -> :class:`ModulePolicy` of the RLModules in ``checkpoint``."""
    from ray.rllib.core.rl_module.rl_module import RLModule

    loaded = {}
    for mid in sorted(set(agent_modules.values())):
        path = module_dir(checkpoint, mid)
        if not path.is_dir():
            raise FileNotFoundError(f"RLModule {mid!r} not found in {checkpoint} ({path})")
        # absolute: RLlib reads a checkpoint by URI, and a relative path has no scheme
        module = RLModule.from_checkpoint(path.resolve())
        module.eval()
        loaded[mid] = module
    agents = list(agent_modules)
    norm = _filters(checkpoint, {a: env.observation_space(a) for a in agents})
    return {a: ModulePolicy(loaded[agent_modules[a]], env.action_space(a), norm.get(a))
            for a in agents}


def evaluate_rllib(run: str | Path, episodes: int = 10, *, model: str = "final", seed: int = 0,
                   deterministic: bool = True, record: str | Path | None = None,
                   video: str | Path | None = None, frames: str | Path | None = None,
                   frame_every: int = 1, env_kwargs: Mapping[str, Any] | None = None) -> dict:
    """Reload an RLlib run's RLModules and run ``episodes`` episodes (module docstring)."""
    check_outputs(record, video, frames)        # before anything slow is loaded
    import torch

    from .config import quiet_rllib

    torch.set_num_threads(1)
    quiet_rllib()
    run = Path(run)
    config = json.loads((run / "config.json").read_text())
    if config.get("engine") != "rllib":
        raise TrainInputError(f"{run} is not a run of --engine rllib")
    checkpoint = _checkpoint(run, model)
    kw = dict(config.get("env_kwargs", {}))
    kw.update(env_kwargs or {})
    want_frames = video is not None or frames is not None
    observation = config.get("observation") or {"flat": True, "frame_stack": 1}
    env = learner_env(config["task"], config.get("mode"),
                      render_mode="rgb_array" if want_frames else None,
                      flat=bool(observation.get("flat", True)),
                      frame_stack=int(observation.get("frame_stack", 1)), **kw)
    try:
        policies = load_policies(checkpoint, config["modules"], env)
    except BaseException:
        env.close()
        raise
    res = evaluate_with_outputs(policies, env, env.unwrapped, episodes, seed, deterministic,
                                record, video, frames, frame_every)
    paths = {a: str(module_dir(checkpoint, mid)) for a, mid in config["modules"].items()}
    if config.get("mode") is None:
        res.pop("agents", None)
    res.update({"task": config["task"], "algo": config["algo"], "engine": "rllib",
                "mode": config.get("mode"), "model": str(checkpoint), "models": paths,
                "episodes": episodes, "deterministic": deterministic, "seed": seed})
    (run / "eval_results.json").write_text(json.dumps(res, indent=2, default=float))
    return res
