"""Curricula: the env options of a one-learner run change by stage as it trains (issue 30).

A curriculum is data: a list of stages, each the run's ``--env-kwargs`` plus its own changes and
a condition that ends it. In TOML (``mimo_social/train/curricula/<name>.toml`` ships one per
task that has one; ``--curriculum FILE`` takes any file, ``.toml`` or ``.json``)::

    task = "selfbody"            # optional: the task the file is for (checked)
    evaluate = "final"           # or "current": the stage the evaluations run under
    growth = "forward:6-12"      # optional: the infant's age by step (mimo_social.train.growth)
    [[stages]]
    name = "4 targets"
    draw = { target = ["head", "chest_middle", "right_upper_leg", "left_upper_leg"] }
    until = { success = 0.7, window = 50, steps = 80000 }
    [[stages]]
    name = "all 28 targets"      # the last stage: no until, it lasts to the end

A stage's keys: ``name``; ``env_kwargs`` (keyword arguments of the env, over the run's:
``max_steps``, ``task_options`` ...; a ``task_options`` dict is merged option by option);
``options`` (task options: short for ``env_kwargs = {task_options = {...}}``); ``draw`` (task
option -> a list of values: each episode of the stage takes one of them, drawn uniformly by the
env's own seeded generator; e.g. self-body's ``target`` drawn from a few primitives while the
observation's one-hot stays over all 28 ``targets``); ``until`` (every stage but the last):
``steps`` (env steps spent in the stage) and / or ``success`` with ``window`` (the success rate
of the last ``window`` training episodes that ran under the stage, >= ``success``), whichever
comes first. Each stage is the run's env kwargs plus its own changes, not the previous stage's.

How a stage reaches the envs. The tasks cannot change an option at ``reset(options=...)``: the
core env ignores reset options, and most options shape the world or the spaces when the env is
made (SB3's ``VecEnv.set_options`` only stores options for the next explicit ``reset()``, which
PPO and SAC call once, when ``learn`` starts). So each training env is a :class:`CurriculumEnv`
(in the worker processes as everywhere): it makes the task's env anew with a stage's kwargs
(``make_env``, the learner's observation layout), one per drawn value kept while the stage
lasts, and switches at the next episode start after
``venv.env_method("set_curriculum_stage", k)`` (:class:`CurriculumController` calls it from
the SB3 callback; an episode running then finishes under its stage). Every stage must give the
same observation and action spaces (a policy cannot change its input): checked, with every
option and drawn value, by :func:`check_curriculum` before anything is written, by making each
stage's env once (the env's own errors name the option, the value and what is allowed).

What a run records: ``config.json["curriculum"]`` (the source, every stage as given and as
resolved, ``evaluate``, and ``history``: when each stage started, in env steps and seconds, and
why); ``progress.csv`` columns ``curriculum_stage`` (the training stage at that row) and
``eval_curriculum_stage`` (the stage the evaluation ran under: by default the final one, so
that success numbers measure the real task); a line on stderr at every stage change. Every
step's info carries ``curriculum_stage`` (episodes are counted for the stage they ran under).
"""

from __future__ import annotations

import copy
import functools
import json
import time
import tomllib
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import gymnasium as gym
import numpy as np

from .envs import make_env
from .tasks import TrainInputError

__all__ = ["Stage", "Curriculum", "CurriculumEnv", "CurriculumController", "DIRECTORY",
           "shipped_curricula", "load_curriculum", "check_curriculum", "prepare_curriculum",
           "curriculum_env", "curriculum_envs", "monitored_curriculum_env", "merge_kwargs"]

#: where the shipped curricula live (package data)
DIRECTORY = Path(__file__).parent / "curricula"
STAGE_KEYS = ("name", "env_kwargs", "options", "draw", "until")
UNTIL_KEYS = ("steps", "success", "window")
TOP_KEYS = ("task", "evaluate", "description", "stages", "growth")
EVALUATE = ("final", "current")
#: mixed into a reset seed for the generator of the drawn values
DRAW_SALT = 30


def shipped_curricula() -> list[str]:
    """The names of the shipped curricula (``curricula/<name>.toml``)."""
    return sorted(p.stem for p in DIRECTORY.glob("*.toml"))


@dataclass(frozen=True)
class Stage:
    """One stage, checked: its ``env_kwargs`` (over the run's), the task options it ``draw``s
    per episode, and when it ends (``until_steps``, ``until_success`` over ``window``)."""

    index: int
    name: str
    env_kwargs: dict = field(default_factory=dict)
    draw: dict = field(default_factory=dict)
    until_steps: int | None = None
    until_success: float | None = None
    window: int | None = None

    def kwargs(self, base: Mapping[str, Any]) -> dict:
        """The env kwargs of this stage: ``base`` with the stage's (``task_options`` merged
        option by option)."""
        return merge_kwargs(base, self.env_kwargs)

    def describe(self) -> dict:
        until = {k: v for k, v in (("steps", self.until_steps), ("success", self.until_success),
                                   ("window", self.window)) if v is not None}
        return {"name": self.name, "env_kwargs": copy.deepcopy(self.env_kwargs),
                "draw": copy.deepcopy(self.draw), "until": until or None}


@dataclass(frozen=True)
class Curriculum:
    """Checked stages (:func:`load_curriculum`); ``source``: the shipped name, a file, or
    ``"inline"``; ``evaluate``: ``"final"`` or ``"current"``."""

    stages: tuple[Stage, ...]
    source: str
    evaluate: str = "final"
    description: str = ""
    #: the infant's age by training step (:mod:`~mimo_social.train.growth`; None: none)
    growth: Any = None

    @property
    def final(self) -> int:
        return len(self.stages) - 1

    def plan(self, base: Mapping[str, Any]) -> list[dict]:
        """Per stage: the env kwargs and the draws (plain data for the worker processes)."""
        return [{"env_kwargs": s.kwargs(base), "draw": copy.deepcopy(s.draw)}
                for s in self.stages]

    def describe(self) -> dict:
        """What config.json records (``history`` is added as the run goes)."""
        out = {"source": self.source, "evaluate": self.evaluate,
               "description": self.description,
               "stages": [s.describe() for s in self.stages]}
        if self.growth is not None:
            out["growth"] = self.growth.spec
        return out


def merge_kwargs(base: Mapping[str, Any], extra: Mapping[str, Any]) -> dict:
    """``base`` updated by ``extra``; their ``task_options`` dicts merged option by option."""
    out = copy.deepcopy(dict(base))
    for k, v in extra.items():
        if k == "task_options" and isinstance(out.get(k), Mapping) and isinstance(v, Mapping):
            out[k] = {**out[k], **copy.deepcopy(dict(v))}
        else:
            out[k] = copy.deepcopy(v)
    return out


# -- reading and checking ------------------------------------------------------------------------
def _read(spec) -> tuple[dict, str]:
    """(the curriculum's data, its source) from a shipped name, a file or a dict."""
    if isinstance(spec, Mapping):
        return copy.deepcopy(dict(spec)), "inline"
    if not isinstance(spec, (str, Path)) or not str(spec):
        raise TrainInputError(f"curriculum={spec!r}; allowed: a shipped curriculum's name "
                              f"({', '.join(shipped_curricula()) or 'none'}), a .toml or .json "
                              "file, or a dict")
    path = Path(spec)
    if str(spec) in shipped_curricula() and not path.exists():
        path, source = DIRECTORY / f"{spec}.toml", str(spec)
    elif path.is_file():
        source = str(path)
    else:
        raise TrainInputError(f"curriculum {str(spec)!r}: no such file nor shipped curriculum; "
                              f"allowed: a shipped name ({', '.join(shipped_curricula())}) or a "
                              ".toml / .json file")
    text = path.read_text()
    try:
        data = json.loads(text) if path.suffix == ".json" else tomllib.loads(text)
    except (ValueError, tomllib.TOMLDecodeError) as exc:
        kind = "JSON" if path.suffix == ".json" else "TOML"
        raise TrainInputError(f"curriculum {source}: not valid {kind} ({exc})") from None
    if not isinstance(data, dict):
        raise TrainInputError(f"curriculum {source}: {type(data).__name__} at the top; allowed: "
                              f"a table with {', '.join(TOP_KEYS)}")
    return data, source


def _stage(k: int, raw, last: bool, where: str) -> Stage:
    if not isinstance(raw, Mapping):
        raise TrainInputError(f"{where}: stage {k} is {raw!r}; allowed: a table with "
                              f"{', '.join(STAGE_KEYS)}")
    name = raw.get("name", f"stage {k}")
    here = f"{where}: stage {k} ({name})"
    unknown = sorted(set(raw) - set(STAGE_KEYS))
    if unknown:
        raise TrainInputError(f"{here}: unknown field(s) {', '.join(unknown)}; allowed: "
                              f"{', '.join(STAGE_KEYS)}")
    if not isinstance(name, str) or not name:
        raise TrainInputError(f"{here}: name={name!r}; allowed: a non-empty string")
    for key in ("env_kwargs", "options", "draw"):
        if not isinstance(raw.get(key, {}), Mapping):
            raise TrainInputError(f"{here}: {key}={raw[key]!r}; allowed: a table of "
                                  f"{'option' if key != 'env_kwargs' else 'keyword'} -> value")
    kwargs = copy.deepcopy(dict(raw.get("env_kwargs", {})))
    if "task_options" in kwargs and not isinstance(kwargs["task_options"], Mapping):
        raise TrainInputError(f"{here}: env_kwargs.task_options={kwargs['task_options']!r}; "
                              "allowed: a table of task option -> value")
    if raw.get("options"):
        kwargs = merge_kwargs(kwargs, {"task_options": dict(raw["options"])})
    draw = {}
    for opt, values in dict(raw.get("draw", {})).items():
        if not isinstance(values, list) or not values:
            raise TrainInputError(f"{here}: draw.{opt}={values!r}; allowed: a non-empty list of "
                                  "the option's values (one drawn per episode)")
        draw[str(opt)] = copy.deepcopy(values)
    until = raw.get("until")
    if last:
        if until is not None:
            raise TrainInputError(f"{here}: until={until!r}; the last stage lasts to the end of "
                                  "training: leave until out")
        return Stage(k, name, kwargs, draw)
    if not isinstance(until, Mapping) or not until:
        raise TrainInputError(f"{here}: until={until!r}; allowed (every stage but the last): "
                              "{steps = N} and / or {success = 0.8, window = 50}")
    bad = sorted(set(until) - set(UNTIL_KEYS))
    if bad:
        raise TrainInputError(f"{here}: until has unknown field(s) {', '.join(bad)}; allowed: "
                              f"{', '.join(UNTIL_KEYS)}")
    steps, success, window = until.get("steps"), until.get("success"), until.get("window")
    if steps is not None and (isinstance(steps, bool) or not isinstance(steps, int) or steps < 1):
        raise TrainInputError(f"{here}: until.steps={steps!r}; allowed: an integer >= 1 (env "
                              "steps spent in the stage)")
    if success is not None:
        if isinstance(success, bool) or not isinstance(success, (int, float)) \
                or not 0 < success <= 1:
            raise TrainInputError(f"{here}: until.success={success!r}; allowed: a number in "
                                  "(0, 1] (the success rate of the last `window` episodes)")
        if isinstance(window, bool) or not isinstance(window, int) or window < 1:
            raise TrainInputError(f"{here}: until.window={window!r}; allowed: an integer >= 1 "
                                  "(training episodes of the stage the success rate is over)")
    elif window is not None:
        raise TrainInputError(f"{here}: until.window={window!r} without until.success; allowed: "
                              "window only with success")
    if steps is None and success is None:
        raise TrainInputError(f"{here}: until={dict(until)!r} ends nothing; allowed: steps "
                              "and / or success (with window)")
    return Stage(k, name, kwargs, draw, steps, None if success is None else float(success),
                 window)


def load_curriculum(spec, task: str) -> Curriculum:
    """A curriculum from a shipped name, a ``.toml`` / ``.json`` file or a dict, its structure
    checked (every error names the stage, the field, the value and what is allowed); the
    options themselves are checked by :func:`check_curriculum`."""
    data, source = _read(spec)
    where = f"curriculum {source}"
    unknown = sorted(set(data) - set(TOP_KEYS))
    if unknown:
        raise TrainInputError(f"{where}: unknown field(s) {', '.join(unknown)}; allowed: "
                              f"{', '.join(TOP_KEYS)}")
    if data.get("task", task) != task:
        raise TrainInputError(f"{where}: task={data['task']!r}, but the run trains {task!r}; "
                              "allowed: a curriculum for the run's task")
    evaluate = data.get("evaluate", "final")
    if evaluate not in EVALUATE:
        raise TrainInputError(f"{where}: evaluate={evaluate!r}; allowed: {', '.join(EVALUATE)}")
    stages = data.get("stages")
    if not isinstance(stages, list) or not stages:
        raise TrainInputError(f"{where}: stages={stages!r}; allowed: a non-empty list of stages "
                              "([[stages]] tables in TOML)")
    out = tuple(_stage(k, s, k == len(stages) - 1, where) for k, s in enumerate(stages))
    description = data.get("description", "")
    if not isinstance(description, str):
        raise TrainInputError(f"{where}: description={description!r}; allowed: a string")
    from .growth import parse_growth
    try:
        growth = parse_growth(data.get("growth"))
    except TrainInputError as e:
        raise TrainInputError(f"{where}: {e}") from None
    return Curriculum(out, source, evaluate, description, growth)


def check_curriculum(cur: Curriculum, task: str, observation: Mapping[str, Any],
                     env_kwargs: Mapping[str, Any]) -> None:
    """Makes every stage's env (with each drawn value) once: an option or value the task does
    not take, a success condition on a task that reports no success, or spaces that differ from
    the first stage's are a TrainInputError naming the stage, the field and the value."""
    spaces = None
    for st, plan in zip(cur.stages, cur.plan(env_kwargs)):
        here = f"curriculum {cur.source}: stage {st.index} ({st.name})"
        variants = [({}, "env_kwargs", plan["env_kwargs"])]
        variants += [({opt: v}, f"draw.{opt}", v) for opt, vs in st.draw.items() for v in vs]
        for choice, what, value in variants:
            try:
                env = make_env(task, **observation, **with_choice(plan["env_kwargs"], choice))
            except Exception as exc:   # the env's own error names the option and what is allowed
                raise TrainInputError(f"{here}: {what}={value!r}: {exc}") from None
            try:
                got = (env.observation_space, env.action_space)
                if spaces is None:
                    spaces = got
                elif got != spaces:
                    raise TrainInputError(
                        f"{here}: {what}={value!r} gives observation {got[0]} / action "
                        f"{got[1]}, stage 0 gives {spaces[0]} / {spaces[1]}; allowed: options "
                        "that keep the spaces (a policy cannot change its input or output)")
                if st.until_success is not None and not choice:
                    env.reset(seed=0)
                    info = env.step(np.zeros_like(env.action_space.sample()))[-1]
                    if info.get("is_success") is None:
                        raise TrainInputError(f"{here}: until.success={st.until_success}: "
                                              f"{task} reports no is_success; allowed: "
                                              "until.steps")
            finally:
                env.close()


def prepare_curriculum(spec, task: str, mode: str | None, observation: Mapping[str, Any],
                       env_kwargs: Mapping[str, Any]) -> Curriculum | None:
    """``train``'s ``curriculum`` argument (None, a shipped name, a file or a dict) loaded and
    checked (:func:`load_curriculum`, :func:`check_curriculum`), before anything is written.
    One learner only: a one-agent task, or ``--mode scripted`` with an ``evaluate = "final"``
    curriculum whose last stage draws nothing (its evaluation env is the scripted ParallelEnv,
    made with the last stage's kwargs)."""
    if spec is None:
        return None
    if mode not in (None, "scripted"):
        raise TrainInputError(f"curriculum with --mode {mode}; allowed: one learner (a one-agent "
                              "task, or --mode scripted)")
    cur = load_curriculum(spec, task)
    if mode == "scripted" and (cur.evaluate != "final" or cur.stages[-1].draw):
        raise TrainInputError(f"curriculum {cur.source} with --mode scripted: evaluate="
                              f"{cur.evaluate!r}, last stage draw={cur.stages[-1].draw!r}; "
                              "allowed there: evaluate = \"final\" and a last stage that draws "
                              "nothing")
    check_curriculum(cur, task, observation, env_kwargs)
    return cur


def with_choice(kwargs: Mapping[str, Any], choice: Mapping[str, Any]) -> dict:
    """``kwargs`` with the drawn task options ``choice`` set."""
    return merge_kwargs(kwargs, {"task_options": dict(choice)}) if choice else dict(kwargs)


# -- the env in the workers ------------------------------------------------------------------------
class CurriculumEnv(gym.Wrapper):
    """The learner's env (:func:`~mimo_social.train.envs.make_env`) under a curriculum's stages
    (``plan``: :meth:`Curriculum.plan`), at stage ``stage``.

    :meth:`set_curriculum_stage` takes effect at the next reset: the stage's env is made anew
    (the former ones closed), one per drawn value, kept while the stage lasts. Each reset draws
    the stage's ``draw`` options with a generator seeded by the reset's seed (``seed`` given:
    the inner env is reset with it; otherwise, where the inner env changed or values are drawn,
    with a seed from that generator, so that a run is reproducible). Every info carries
    ``curriculum_stage``: the stage of the running episode (:attr:`curriculum_stage`)."""

    def __init__(self, task: str, observation: Mapping[str, Any], plan: list[dict],
                 stage: int = 0):
        self.task, self.observation, self.plan = task, dict(observation), list(plan)
        self.rng = np.random.default_rng(DRAW_SALT)
        self.envs: dict[str, gym.Env] = {}
        self.curriculum_stage = self.pending = self.check_stage(stage)
        first, _ = self.variant(self.choose())
        self.spaces = (first.observation_space, first.action_space)
        super().__init__(first)

    def check_stage(self, stage) -> int:
        if isinstance(stage, bool) or not isinstance(stage, (int, np.integer)) \
                or not 0 <= stage < len(self.plan):
            raise ValueError(f"curriculum stage {stage!r} not allowed; allowed: 0 to "
                             f"{len(self.plan) - 1}")
        return int(stage)

    def set_curriculum_stage(self, stage: int) -> int:
        """Stage ``stage`` from the next reset on (the running episode finishes as it is)."""
        self.pending = self.check_stage(stage)
        return self.pending

    def choose(self) -> dict:
        draw = self.plan[self.curriculum_stage]["draw"]
        return {opt: values[int(self.rng.integers(len(values)))] for opt, values in draw.items()}

    def variant(self, choice: dict) -> tuple[gym.Env, bool]:
        """The env of the current stage with the drawn ``choice`` (made if new; new: True)."""
        key = json.dumps(choice, sort_keys=True, default=str)
        if key in self.envs:
            return self.envs[key], False
        kwargs = with_choice(self.plan[self.curriculum_stage]["env_kwargs"], choice)
        env = make_env(self.task, **self.observation, **kwargs)
        spaces = getattr(self, "spaces", None)
        if spaces is not None and (env.observation_space, env.action_space) != spaces:
            env.close()
            raise ValueError(f"curriculum stage {self.curriculum_stage} ({choice or kwargs}) "
                             "changes the observation or action space; allowed: options that "
                             "keep them")
        self.envs[key] = env
        return env, True

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self.rng = np.random.default_rng([int(seed), DRAW_SALT])
        if self.pending != self.curriculum_stage:
            self.close_all()
            self.curriculum_stage = self.pending
        drawn = bool(self.plan[self.curriculum_stage]["draw"])
        env, new = self.variant(self.choose())
        switched = new or env is not self.env
        self.env = env
        if seed is None and (switched or drawn):
            seed = int(self.rng.integers(2**31 - 1))
        obs, info = env.reset(seed=seed, options=options)
        info["curriculum_stage"] = self.curriculum_stage
        return obs, info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        info["curriculum_stage"] = self.curriculum_stage
        return obs, reward, terminated, truncated, info

    def close_all(self) -> None:
        for env in self.envs.values():
            env.close()
        self.envs = {}

    def close(self):
        self.close_all()


def curriculum_env(task: str, observation: Mapping[str, Any], plan: list[dict],
                   stage: int = 0) -> CurriculumEnv:
    """A :class:`CurriculumEnv` (module-level: picklable for the workers)."""
    return CurriculumEnv(task, observation, plan, stage)


def monitored_curriculum_env(task: str, observation: Mapping[str, Any], plan: list[dict],
                             stage: int = 0):
    """:func:`curriculum_env` with Gymnasium's ``RecordEpisodeStatistics`` (the episodes SB3
    logs), as :func:`~mimo_social.train.single.monitored_env` for one env."""
    from gymnasium.wrappers import RecordEpisodeStatistics
    return RecordEpisodeStatistics(CurriculumEnv(task, observation, plan, stage))


def curriculum_envs(cur: Curriculum, task: str, observation: Mapping[str, Any],
                    env_kwargs: Mapping[str, Any]):
    """``(eval_env, env_fn)`` of a one-learner run under ``cur``: the evaluation env at the
    stage evaluated (the final one, or the first with ``evaluate = "current"``) and the
    picklable function making each training env (at stage 0, with episode statistics)."""
    plan = cur.plan(env_kwargs)
    first = cur.final if cur.evaluate == "final" else 0
    return (CurriculumEnv(task, observation, plan, first),
            functools.partial(monitored_curriculum_env, task, dict(observation), plan))


# -- the training side -------------------------------------------------------------------------
class CurriculumController:
    """Advances the stages of a run from the SB3 callback (:meth:`on_step`), sets them in the
    training envs (``venv.env_method("set_curriculum_stage", k)``; and in ``eval_env`` with
    ``evaluate = "current"``), records each start in ``config["curriculum"]["history"]``
    (rewriting config.json through ``write``) and says so on stderr through ``note``.
    :meth:`columns` gives a progress row's ``curriculum_stage`` and ``eval_curriculum_stage``."""

    def __init__(self, cur: Curriculum, venv, eval_env, config: dict, write, note,
                 t_start: float | None = None):
        self.cur, self.venv, self.eval_env = cur, venv, eval_env
        self.config, self.write, self.note = config, write, note
        self.t_start = time.perf_counter() if t_start is None else t_start
        self.stage, self.started = 0, 0
        self.outcomes: deque = deque(maxlen=max(1, cur.stages[0].window or 1))
        config["curriculum"] = {**cur.describe(), "history": [
            {"stage": 0, "name": cur.stages[0].name, "step": 0, "wall_time_s": 0.0,
             "why": "start"}]}

    @property
    def eval_stage(self) -> int:
        return self.cur.final if self.cur.evaluate == "final" else self.stage

    def columns(self) -> dict:
        return {"curriculum_stage": self.stage, "eval_curriculum_stage": self.eval_stage}

    def on_step(self, n: int, infos) -> None:
        """After each vector step at env step ``n``: count the episodes that ended under the
        current stage, then advance when the stage's condition holds."""
        for info in infos:
            if "episode" in info and info.get("curriculum_stage") == self.stage \
                    and info.get("is_success") is not None:
                self.outcomes.append(bool(info["is_success"]))
        why = self.due(n)
        if why:
            self.advance(n, why)

    def due(self, n: int) -> str | None:
        st = self.cur.stages[self.stage]
        if self.stage == self.cur.final:
            return None
        if st.until_steps is not None and n - self.started >= st.until_steps:
            return f"{n - self.started} steps in stage {self.stage} (until.steps={st.until_steps})"
        if st.until_success is not None and len(self.outcomes) >= st.window:
            rate = float(np.mean(self.outcomes))
            if rate >= st.until_success:
                return (f"success {rate:.0%} over the last {st.window} episodes of stage "
                        f"{self.stage} (until.success={st.until_success:g})")
        return None

    def advance(self, n: int, why: str) -> None:
        self.stage += 1
        self.started = n
        st = self.cur.stages[self.stage]
        self.outcomes = deque(maxlen=max(1, st.window or 1))
        self.venv.env_method("set_curriculum_stage", self.stage)
        if self.cur.evaluate == "current" and self.eval_env is not None:
            self.eval_env.get_wrapper_attr("set_curriculum_stage")(self.stage)
        wall = round(time.perf_counter() - self.t_start, 1)
        self.config["curriculum"]["history"].append(
            {"stage": self.stage, "name": st.name, "step": int(n), "wall_time_s": wall,
             "why": why})
        self.note(f"curriculum: stage {self.stage} ({st.name}) from step {n}: {why}")
        self.write()
