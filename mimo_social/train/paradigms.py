"""The classic paradigms of infant social development run with a learner of one's choice.

``run_paradigm(task, learners, episodes, seed)`` runs ``episodes`` episodes of one paradigm
(the catalogue's tasks with measures of their own, :data:`PARADIGMS`: ``still_face``,
``contingency``, ``imitation``; the scripted forms of their envs, ``infant_0`` the learner, the
caregiver scripted) with each learner and returns the paradigm's own summary per learner,
computed by the task's measures (``mimo_social/tasks/<task>/measures.py``, the catalogue entry's
``measures``: its ``run`` and, for the table, ``rows``; nothing is re-measured here):

* ``still_face``: per phase (interaction, still face, reunion) the share of the phase's steps
  with a smile, with the gaze on the caregiver's face and with self-touch;
* ``contingency``: blocks of a live, a replay (of that block's live episode) and a
  non-contingent episode; per condition the smile rates, response and baseline rates,
  contingency index, gaze and shared smiling;
* ``imitation``: per demonstrated action the success rate, the mean return and which act the
  learner answered with.

Still face and contingency also report the paradigm's effect, a difference within the same
episodes (the task's ``measures.effects``, whose episodes give the summary above too: they are
run once): still face, per episode, the still phase's drop of smiling and of gaze at the face,
their recovery in reunion and the rise of self-touch; contingency, per block, live minus replay
and live minus non-contingent of smiling, smile rate, gaze, contingency index and shared
smiling; mean and sd over episodes (blocks). Imitation has no such effect (its measures are per
demonstrated action, with no condition to set against another).

A learner (:func:`make_learner`) is ``"scripted"`` (the catalogue's controller of the task: the
scripted infant baseline), ``"random"`` (uniform samples of the learner's action space, seeded
per episode), ``"zero"`` (the resting action: no motor command, the neutral face) or the folder
of a run trained with ``mimo-social train`` / ``compare`` on the same task with ``--mode
scripted`` (its ``model.zip`` or ``best_model.zip``, deterministic, on the flat observation it
was trained on, normalisation inside the saved policy). Every learner has the
:class:`~mimo_social.partners.base.Partner` interface (``reset(env, agent, rng)``,
``act(env, agent, obs)``) and drives ``infant_0`` through its own action only.

:func:`side_by_side` formats the summaries as one markdown table, a column per learner.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Mapping, Sequence


from ..envs.catalog import CATALOG, entry
from ..partners.base import zero_action
from .tasks import TrainInputError

__all__ = ["PARADIGMS", "LEARNER_NAMES", "make_learner", "run_paradigm", "side_by_side",
           "check_learner"]

#: the paradigms this runs: the catalogue's tasks that have measures of their own
PARADIGMS = tuple(e.name for e in CATALOG if e.measures is not None)
#: the built-in learners (besides a run folder)
LEARNER_NAMES = ("scripted", "random", "zero")
AGENT = "infant_0"


class _Random:
    """Uniform samples of the learner's action space, the space seeded per episode."""

    def __init__(self, space):
        import copy
        self.space = copy.deepcopy(space)
        self.name = "random"

    def reset(self, env, agent, rng) -> None:
        self.space.seed(int(rng.integers(2**31)))

    def act(self, env, agent, obs):
        return self.space.sample()


class _Zero:
    def __init__(self, space):
        self.action = zero_action(space)
        self.name = "zero"

    def reset(self, env, agent, rng) -> None:
        pass

    def act(self, env, agent, obs):
        return self.action


def _shapes(space):
    """A space's shape, or a Dict's key -> shape (what a policy's input must match)."""
    if hasattr(space, "spaces") and isinstance(space.spaces, Mapping):
        return {k: _shapes(v) for k, v in space.spaces.items()}
    return space.shape


class _Trained:
    """A trained run's policy (SB3), deterministic, on the observation it was trained on
    (:class:`~mimo_social.train.envs.PolicyInput`: flat, or images and a vector for a run that
    saw through the CNN); its flat action decoded onto the learner's action space."""

    def __init__(self, run: Path, config: Mapping[str, Any], model: str, obs_space, act_space,
                 deterministic: bool = True):
        from ..core.wrappers import ActionDecoder
        from .envs import PolicyInput
        from .tasks import algo_class
        path = {"final": run / "model.zip", "best": run / "best_model.zip"}[model]
        if not path.exists():
            raise FileNotFoundError(f"run {run}: model {path.name} not found (model: final or "
                                    "best, the files 'mimo-social train' writes)")
        import torch
        torch.set_num_threads(1)
        self.model = algo_class(config["algo"]).load(str(path), device="cpu")
        from .rollouts import PolicyState, load_vecnormalize, vecnormalize_path
        self.memory = PolicyState(self.model, load_vecnormalize(vecnormalize_path(path)))
        self.observe, self.decode = PolicyInput(config, obs_space), ActionDecoder(act_space)
        self._first = True
        if _shapes(self.model.observation_space) != _shapes(self.observe.space):
            raise TrainInputError(f"run {run}: its policy observes "
                                  f"{_shapes(self.model.observation_space)}, the env gives "
                                  f"{_shapes(self.observe.space)}: evaluate with the env "
                                  "settings it was trained with (--env-kwargs)")
        self.deterministic = bool(deterministic)
        self.name = (f"{run.name} ({config['algo'].upper()}"
                     + ("" if self.deterministic else ", sampled") + ")")
        self.run = str(run)

    def reset(self, env, agent, rng) -> None:
        self._first = True
        self.memory.reset()   # (a recurrent model: a fresh state each episode)
        if not self.deterministic:   # the sampled actions: seeded per episode
            import torch
            torch.manual_seed(int(rng.integers(2**31)))

    def act(self, env, agent, obs):
        seen = self.observe(obs, self._first)
        self._first = False
        action = self.memory.predict(seen, self.deterministic)
        return self.decode(action, agent)


def _run_config(task: str, run: str | Path) -> dict:
    run = Path(run)
    if not (run / "config.json").is_file():
        raise FileNotFoundError(f"learner {str(run)!r}: no config.json in it; allowed: "
                                f"{', '.join(LEARNER_NAMES)} or a folder written by "
                                "'mimo-social train' / 'compare'")
    config = json.loads((run / "config.json").read_text())
    if config.get("task") != task:
        raise TrainInputError(f"learner {str(run)!r} was trained on {config.get('task')!r}, "
                              f"not {task!r}")
    if config.get("mode") not in (None, "scripted") or config.get("engine", "sb3") != "sb3":
        raise TrainInputError(f"learner {str(run)!r}: mode {config.get('mode')!r}, engine "
                              f"{config.get('engine', 'sb3')!r}; allowed: an SB3 run with "
                              "--mode scripted (one learner, the caregiver scripted)")
    return config


def check_learner(task: str, spec: str) -> str:
    """``spec`` if it is a built-in learner or a run folder of ``task``; else the error."""
    if spec not in LEARNER_NAMES:
        _run_config(task, spec)
    return spec


def make_learner(task: str, spec: str, env, model: str = "final", deterministic: bool = True):
    """The learner ``spec`` (one of :data:`LEARNER_NAMES` or a run folder) for ``infant_0`` of
    ``env`` (the paradigm's one-learner PettingZoo env, for the spaces). A run's policy acts
    deterministically (the mode of its action distribution), or with ``deterministic=False``
    samples its actions as in training (seeded per episode)."""
    if task not in PARADIGMS:
        raise TrainInputError(f"task {task!r} not allowed; allowed: {', '.join(PARADIGMS)}")
    if model not in ("final", "best"):
        raise TrainInputError(f"model {model!r} not allowed; allowed: final, best")
    space = env.action_space(AGENT)
    if spec == "scripted":
        controller = entry(task).controller()
        controller.name = f"scripted ({type(controller).__name__})"
        return controller
    if spec == "random":
        return _Random(space)
    if spec == "zero":
        return _Zero(space)
    config = _run_config(task, spec)
    return _Trained(Path(spec), config, model, env.observation_space(AGENT), space,
                    deterministic)


def _env_kwargs(task: str, specs: Sequence[str], env_kwargs) -> dict:
    """The env settings every learner runs with: ``env_kwargs``, else those the runs were
    trained with (which must agree), else the defaults."""
    if env_kwargs is not None:
        return dict(env_kwargs)
    kws = [dict(_run_config(task, s).get("env_kwargs", {})) for s in specs
           if s not in LEARNER_NAMES]
    if any(k != kws[0] for k in kws[1:]):
        raise TrainInputError("the runs were trained with different env settings ("
                              + "; ".join(map(str, kws)) + "); give --env-kwargs")
    return kws[0] if kws else {}


def run_paradigm(task: str, learners: Sequence[str] = LEARNER_NAMES, episodes: int = 5,
                 seed: int = 0, env_kwargs: Mapping[str, Any] | None = None,
                 model: str = "final", deterministic: bool = True,
                 progress: bool = False) -> dict:
    """Each learner on the same seeded episodes of ``task`` (one of :data:`PARADIGMS`);
    ``progress``: a progress bar over the learners (on stderr).

    ``episodes``: episodes per learner (contingency: blocks of a live, a replay and a
    non-contingent episode); seeds ``seed``, ``seed + 1``, ... Returns ``task``, ``episodes``,
    ``seed``, ``env_kwargs`` and ``learners``: a list of ``{"learner", "spec", "summary"}``,
    the summary being the task module's (see the module docstring), with ``"effects"`` for
    still face (``{name: (mean, sd)}``, the task's ``EFFECTS``) and contingency
    (``{"live_minus_replay": {measure: (mean, sd)}, "live_minus_non_contingent": ...}``): the
    task's ``measures.effects`` of the learner. ``deterministic``: see :func:`make_learner`
    (runs only)."""
    if task not in PARADIGMS:
        raise TrainInputError(f"task {task!r} not allowed; allowed: {', '.join(PARADIGMS)}")
    episodes, seed = int(episodes), int(seed)
    if episodes < 1:
        raise TrainInputError(f"episodes={episodes}; allowed: a positive integer")
    specs = [str(s) for s in learners]
    if not specs:
        raise TrainInputError("no learner; allowed: one or more of "
                              f"{', '.join(LEARNER_NAMES)} or run folders")
    for s in specs:
        check_learner(task, s)
    kw = _env_kwargs(task, specs, env_kwargs)
    measures = entry(task).measures
    effects = getattr(measures, "effects", None)   # still face, contingency
    results = []
    from tqdm import tqdm
    for spec in tqdm(specs, desc=f"paradigm {task}", unit="learner", disable=not progress,
                     dynamic_ncols=True):
        env = entry(task).scripted_env(**kw)   # the learner's spaces (and imitation's episodes)
        try:
            learner = make_learner(task, spec, env, model, deterministic)
            if effects is None:
                summ = measures.run(learner, episodes, seed, env)
        finally:
            env.close()
        row = {"learner": getattr(learner, "name", type(learner).__name__), "spec": spec}
        if effects is None:
            row["summary"] = summ
        else:   # the same episodes as measures.run, their summary and the effect
            eff = effects(learner, episodes, seed, kw)
            row["summary"] = eff["summary"]
            rest = {k: v for k, v in eff.items() if k not in ("summary", "return", "episodes")}
            row["effects"] = rest.get("effects", rest)   # still face's are under "effects"
        results.append(row)
    return {"task": task, "episodes": episodes, "seed": seed, "env_kwargs": kw,
            "deterministic": bool(deterministic), "learners": results}


# -- tables -----------------------------------------------------------------------------------
def side_by_side(result: Mapping[str, Any]) -> str:
    """:func:`run_paradigm`'s result as a markdown table: a row per measure (per phase,
    condition or demonstrated action), a column per learner (mean +- sd over episodes); for
    still face and contingency a second one of the paradigm's effect (a row per effect, nested
    ones labelled ``live minus replay: <measure>``); for imitation a line saying it has none."""
    task = result["task"]
    names = [r["learner"] for r in result["learners"]]
    summaries = [r["summary"] for r in result["learners"]]
    measures = entry(task).measures
    rows = measures.rows(summaries)
    unit = measures.UNIT
    lines = [f"{task}: {result['episodes']} {unit} per learner, seeds from {result['seed']}",
             "", "| measure | " + " | ".join(names) + " |",
             "|---" * (len(names) + 1) + "|"]
    lines += [f"| {label} | " + " | ".join(cells) + " |" for label, cells in rows]
    effects = [r.get("effects") for r in result["learners"]]
    if not hasattr(measures, "effects"):
        lines += ["", f"{task}: no paradigm effect (no condition to set against another)"]
    if not hasattr(measures, "effects") or any(e is None for e in effects):
        return "\n".join(lines) + "\n"
    flat = [dict(_flat(e)) for e in effects]
    lines += ["", f"{task}: the paradigm's effect, within each of the same "
              f"{unit.split(' (')[0]}, mean +- sd",
              "", "| effect | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
    lines += [f"| {label} | " + " | ".join(f"{f[label][0]:+.3f} +- {f[label][1]:.3f}"
                                           for f in flat) + " |" for label in flat[0]]
    return "\n".join(lines) + "\n"


def _flat(effects: Mapping[str, Any], prefix: str = ""):
    """(label, (mean, sd)) of an effects mapping, nested ones labelled ``outer: inner``."""
    for key, value in effects.items():
        if isinstance(value, Mapping):
            yield from _flat(value, f"{prefix}{key.replace('_', ' ')}: ")
        else:
            yield prefix + key, value


def to_json(result: Mapping[str, Any]) -> str:
    """The result as JSON (tuples as lists)."""
    return json.dumps(result, indent=1, default=lambda o: o.tolist() if hasattr(o, "tolist")
                      else str(o))
