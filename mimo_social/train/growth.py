"""Growth curricula: the learner infant's age as a function of the training steps (issue 32).

A schedule (:class:`Growth`, made by :func:`parse_growth` from a spec) is one of

``forward:A-B`` (or ``forward:A-B:STEPS``)
    young to old: A months at step 0, B months at the end of the run (or at env step ``STEPS``,
    then B to the end), linear in between;
``inverse:A-B`` (or ``inverse:A-B:STEPS``)
    old to young: B months at step 0, A months at the end (or at step ``STEPS``);
``stochastic:A-B``
    each training episode's age drawn uniformly from [A, B] by the env's own seeded generator.

Ages are months, 0 to 33, the range written low-high (``A < B``; ``A = B`` is allowed for
``stochastic`` and means a fixed age). In TOML (a recipe's ``[train]`` table or a curriculum
file) the spec is the same string, or a table ``{kind = "forward", ages = [1, 12], steps =
200000}``. :func:`age` is the pure function ``age(growth, step, rng)``.

How an age reaches the envs: each training env is wrapped in :class:`GrowthEnv`. For
``forward`` / ``inverse`` the :class:`GrowthController` (called from the SB3 callback) sets the
age in force in every training env, ``VecEnv.env_method("set_age", age_months=x)``, whenever it
has moved by :data:`RESOLUTION` months; the core env applies it at each env's next reset (an
episode running finishes at its age). For ``stochastic`` the wrapper draws the age of each
episode before its reset, from a generator seeded by the reset's seed (so that a run is
reproducible under its seed), and sets it with the same ``set_age``. Every info carries
``age_months``: the age of the running episode.

What a run records: ``config.json["growth"]`` (the schedule, as given and resolved, and its
``history``: the step of every whole month crossed), ``progress.csv`` columns ``age_months``
(``forward`` / ``inverse``: the age in force at the row; ``stochastic``: the mean age of the
training episodes that ended since the previous row) and ``eval_age_months`` (the age the
evaluation ran at; ``stochastic``: the evaluation episodes draw theirs from the range, the same
draws each time, and the column is their mean), and a line on stderr at every whole month
crossed (``forward`` / ``inverse`` only).
"""

from __future__ import annotations

import math
import time
from collections import deque
from dataclasses import dataclass
from typing import Any, Callable, Mapping

import gymnasium as gym
import numpy as np

from .tasks import TrainInputError

__all__ = ["Growth", "KINDS", "AGE_RANGE", "RESOLUTION", "parse_growth", "age", "check_ages",
           "GrowthEnv", "GrowthController", "growth_env", "monitored_growth_env",
           "wrap_growth", "check_set_age", "evaluation_ages"]

KINDS = ("forward", "inverse", "stochastic")
#: the ages an infant body takes, in months
AGE_RANGE = (0.0, 33.0)
#: forward / inverse: the age in force is set again in the envs when it has moved this much
RESOLUTION = 0.1
#: mixed into a reset seed for the generator of the drawn ages
DRAW_SALT = 32
#: keys config.json's growth record has besides the schedule's own (read back, ignored)
RECORDED = ("spec", "resolution_months", "span", "history")
SPEC_HELP = ("forward:A-B, inverse:A-B (each optionally :STEPS, the env steps the change takes) "
             "or stochastic:A-B, ages in months 0-33 written low-high, e.g. forward:1-12")


@dataclass(frozen=True)
class Growth:
    """A checked growth schedule: ``kind`` (:data:`KINDS`), the age range ``low`` - ``high``
    (months) and ``steps`` (forward / inverse: env steps the change takes; None: the run's)."""

    kind: str
    low: float
    high: float
    steps: int | None = None

    @property
    def spec(self) -> str:
        """The schedule as a command-line spec (``forward:1-12:200000``)."""
        span = "" if self.steps is None else f":{self.steps}"
        return f"{self.kind}:{self.low:g}-{self.high:g}{span}"

    def describe(self) -> dict:
        """What config.json records."""
        return {"spec": self.spec, "kind": self.kind, "ages": [self.low, self.high],
                "steps": self.steps, "resolution_months": RESOLUTION}

    def span(self, total: int) -> int:
        """The env steps the change takes in a run of ``total`` steps."""
        return int(self.steps if self.steps is not None else total)


def _number(text: Any, what: str, spec: Any) -> float:
    if isinstance(text, bool):
        raise TrainInputError(f"growth {spec!r}: {what}={text!r}; allowed: {SPEC_HELP}")
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise TrainInputError(f"growth {spec!r}: {what} {text!r} is not a number; allowed: "
                              f"{SPEC_HELP}") from None
    if not math.isfinite(value) or not AGE_RANGE[0] <= value <= AGE_RANGE[1]:
        raise TrainInputError(f"growth {spec!r}: {what} {text!r} not allowed; allowed: an age "
                              f"in months from {AGE_RANGE[0]:g} to {AGE_RANGE[1]:g}")
    return value


def _steps(value: Any, spec: Any) -> int | None:
    if value is None:
        return None
    if isinstance(value, str) and value.strip().isdigit():
        value = int(value.strip())
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise TrainInputError(f"growth {spec!r}: steps {value!r} not allowed; allowed: an "
                              "integer >= 1 (the env steps the change takes)")
    return value


def _make(kind: Any, low: Any, high: Any, steps: Any, spec: Any) -> Growth:
    if kind not in KINDS:
        raise TrainInputError(f"growth {spec!r}: kind {kind!r} not allowed; allowed: "
                              f"{', '.join(KINDS)} ({SPEC_HELP})")
    lo, hi = _number(low, "age", spec), _number(high, "age", spec)
    if lo > hi or (lo == hi and kind != "stochastic"):
        flip = f"; for old to young use inverse:{hi:g}-{lo:g}" if kind == "forward" else ""
        raise TrainInputError(f"growth {spec!r}: ages {lo:g}-{hi:g} not allowed; allowed: the "
                              f"range written low-high, the low age first (e.g. {kind}:1-12)"
                              + flip)
    steps = _steps(steps, spec)
    if kind == "stochastic" and steps is not None:
        raise TrainInputError(f"growth {spec!r}: a step span is for forward and inverse; "
                              "stochastic draws each episode's age from the range all run long")
    return Growth(kind, lo, hi, steps)


def parse_growth(spec: Any) -> Growth | None:
    """A :class:`Growth` from a spec string (``forward:1-12``, ``inverse:1-12:200000``,
    ``stochastic:3-9``), a mapping (``{"kind", "ages": [low, high], "steps"}``, TOML's and
    config.json's form), a :class:`Growth` or None (no growth). Any other input is a
    TrainInputError naming it and saying what is allowed."""
    if spec is None or isinstance(spec, Growth):
        return spec
    if isinstance(spec, Mapping):
        unknown = sorted(set(spec) - {"kind", "ages", "steps", *RECORDED})
        if unknown:
            raise TrainInputError(f"growth {dict(spec)!r}: unknown key(s) {', '.join(unknown)};"
                                  " allowed: kind, ages (a [low, high] pair), steps")
        ages = spec.get("ages")
        if not isinstance(ages, (list, tuple)) or len(ages) != 2:
            raise TrainInputError(f"growth {dict(spec)!r}: ages={ages!r}; allowed: a [low, "
                                  "high] pair of ages in months, e.g. [1, 12]")
        return _make(spec.get("kind"), ages[0], ages[1], spec.get("steps"), dict(spec))
    if not isinstance(spec, str):
        raise TrainInputError(f"growth={spec!r}; allowed: {SPEC_HELP}, or a table {{kind, ages, "
                              "steps}}")
    parts = spec.strip().split(":")
    if len(parts) not in (2, 3):
        raise TrainInputError(f"growth {spec!r}: not KIND:A-B[:STEPS]; allowed: {SPEC_HELP}")
    low, dash, high = parts[1].strip().partition("-")
    if not dash:
        raise TrainInputError(f"growth {spec!r}: ages {parts[1]!r} are not A-B; allowed: "
                              f"{SPEC_HELP}")
    return _make(parts[0].strip(), low.strip(), high.strip(),
                 parts[2].strip() if len(parts) == 3 else None, spec)


def age(growth: Growth, step: int, rng: np.random.Generator | None = None,
        total: int | None = None) -> float:
    """The age (months) ``growth`` gives at env step ``step`` of a run of ``total`` steps
    (forward / inverse without a step span need ``total``): linear from one end of the range to
    the other over the span, the far end after it. ``stochastic``: a uniform draw from the range
    by ``rng`` (the step does not matter)."""
    if growth.kind == "stochastic":
        if rng is None:
            raise ValueError("a stochastic growth draws its ages: give rng, a "
                             "numpy.random.Generator")
        return float(rng.uniform(growth.low, growth.high)) if growth.high > growth.low \
            else growth.low
    if growth.steps is None and total is None:
        raise ValueError(f"growth {growth.spec}: no step span; give total, the run's steps")
    span = growth.span(total if total is not None else 0)
    frac = min(max(float(step) / span, 0.0), 1.0)
    start, end = ((growth.low, growth.high) if growth.kind == "forward"
                  else (growth.high, growth.low))
    return float(start + (end - start) * frac)


def check_ages(values: Any, what: str = "ages") -> list[float]:
    """Ages in months (a list, or a comma-separated string ``1,3,6``), each 0-33, none
    repeated; a TrainInputError naming the value and what is allowed otherwise."""
    if isinstance(values, str):
        values = [v.strip() for v in values.split(",") if v.strip()]
    if isinstance(values, (int, float)) and not isinstance(values, bool):
        values = [values]
    if not isinstance(values, (list, tuple)) or not values:
        raise TrainInputError(f"{what}={values!r}; allowed: one or more ages in months "
                              f"{AGE_RANGE[0]:g}-{AGE_RANGE[1]:g}, e.g. 1,3,6,9,12")
    out = []
    for v in values:
        bad = isinstance(v, bool)
        try:
            x = float(v)
        except (TypeError, ValueError):
            bad, x = True, float("nan")
        if bad or not math.isfinite(x) or not AGE_RANGE[0] <= x <= AGE_RANGE[1]:
            raise TrainInputError(f"{what}: {v!r} not allowed; allowed: ages in months from "
                                  f"{AGE_RANGE[0]:g} to {AGE_RANGE[1]:g}")
        if x in out:
            raise TrainInputError(f"{what}: {v!r} given twice; allowed: each age once")
        out.append(x)
    return out


# -- the env side ---------------------------------------------------------------------------------
class GrowthEnv(gym.Wrapper):
    """A learner's env whose infant's age follows a growth schedule.

    :meth:`set_age` (what ``env_method("set_age", ...)`` finds first) records the age and passes
    it on to the env below; it takes effect at the next reset. With ``draw`` (``[low, high]``,
    a stochastic schedule) each reset first draws the age uniformly from the range with the
    wrapper's generator, seeded by the reset's seed (``np.random.default_rng([seed,
    DRAW_SALT])``), and sets it. Each reset also passes the age in force in its ``options``
    (``{"age_months": x}``, the core env's other way to set it), so that an env below made anew
    (a curriculum's next stage) takes it too. Every info carries ``age_months``."""

    def __init__(self, env: gym.Env, age_months: float | None = None,
                 draw: tuple[float, float] | None = None):
        super().__init__(env)
        self.draw = None if draw is None else (float(draw[0]), float(draw[1]))
        self.rng = np.random.default_rng(DRAW_SALT)
        self.pending = None if age_months is None else float(age_months)
        self.age_months = self.pending
        #: the ages drawn since :meth:`take_drawn` last emptied it (stochastic)
        self.drawn: deque = deque(maxlen=100_000)

    def set_age(self, age_months: float | None = None, motor_age_months: float | None = None,
                agent: str | None = None):
        """The infant's age from the next reset on (the core env's ``set_age``)."""
        self.pending = None if age_months is None else float(age_months)
        self._apply(motor_age_months, agent)
        return self.pending

    def _apply(self, motor_age_months=None, agent=None) -> None:
        inner = self.env.get_wrapper_attr("set_age")
        inner(age_months=self.pending, motor_age_months=motor_age_months, agent=agent)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self.rng = np.random.default_rng([int(seed), DRAW_SALT])
        if self.draw is not None:
            low, high = self.draw
            self.pending = float(self.rng.uniform(low, high)) if high > low else low
            self.drawn.append(self.pending)
            self._apply()
        if self.pending is not None:
            # the age in the reset's options too: an env below made anew since (a curriculum's
            # next stage) takes it as well; an age given in ``options`` wins
            options = {"age_months": self.pending, **(options or {})}
        self.age_months = (options or {}).get("age_months", self.pending)
        obs, info = self.env.reset(seed=seed, options=options)
        if self.age_months is not None:
            info["age_months"] = self.age_months
        return obs, info

    def take_drawn(self) -> list[float]:
        """The ages drawn since the last call (stochastic), emptied."""
        out = list(self.drawn)
        self.drawn.clear()
        return out

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if self.age_months is not None:
            info["age_months"] = self.age_months
        return obs, reward, terminated, truncated, info


def wrap_growth(env: gym.Env, growth: Growth | Mapping | str, total: int) -> GrowthEnv:
    """``env`` in a :class:`GrowthEnv` at the schedule's first age (a stochastic schedule:
    drawing every episode's)."""
    g = parse_growth(growth)
    if g.kind == "stochastic":
        return GrowthEnv(env, draw=(g.low, g.high))
    return GrowthEnv(env, age_months=round(age(g, 0, total=total), 6))


def growth_env(make: Callable[[], gym.Env], growth: Growth | Mapping | str,
               total: int) -> GrowthEnv:
    """:func:`wrap_growth` of ``make()``; module-level: picklable for the worker processes."""
    return wrap_growth(make(), growth, total)


def monitored_growth_env(make: Callable[[], gym.Env], growth, total: int):
    """:func:`growth_env` with Gymnasium's ``RecordEpisodeStatistics`` (the episodes SB3 logs)."""
    from gymnasium.wrappers import RecordEpisodeStatistics
    return RecordEpisodeStatistics(growth_env(make, growth, total))


# -- the training side ----------------------------------------------------------------------------
class GrowthController:
    """Sets the age of a run's training envs (``venv.env_method("set_age", age_months=x)``) and
    of its evaluation env as the schedule says (:meth:`on_step`, from the SB3 callback), records
    each whole month crossed in ``config["growth"]["history"]`` (rewriting config.json through
    ``write``) and says so on stderr through ``note``. :meth:`columns`: a progress row's
    ``age_months`` and ``eval_age_months``."""

    def __init__(self, growth: Growth, venv, eval_env, total: int, config: dict, write,
                 note, t_start: float | None = None):
        self.growth, self.venv, self.eval_env, self.total = growth, venv, eval_env, int(total)
        self.write, self.note, self.config = write, note, config
        self.t_start = time.perf_counter() if t_start is None else t_start
        self.ages_ended: list[float] = []
        self.current = None if growth.kind == "stochastic" else self.at(0)
        self.month = None if self.current is None else self._month(self.current)
        first = {"step": 0, "age_months": self.current, "wall_time_s": 0.0}
        config["growth"] = {**growth.describe(), "span": growth.span(total),
                            "history": [] if self.current is None else [first]}

    def at(self, n: int) -> float:
        """The schedule's age at env step ``n`` on the :data:`RESOLUTION` grid, rounded towards
        the starting age (a whole month is set when the schedule reaches it, not before)."""
        x = age(self.growth, n, total=self.total) / RESOLUTION
        k = math.floor(x + 1e-6) if self.growth.kind == "forward" else math.ceil(x - 1e-6)
        return round(k * RESOLUTION, 6)

    def _month(self, value: float) -> int:
        # forward: the whole months reached; inverse: the whole months gone below
        return math.floor(value + 1e-9) if self.growth.kind == "forward" \
            else math.ceil(value - 1e-9)

    def on_step(self, n: int, infos) -> None:
        """After each vector step at env step ``n``: note the ages of the episodes that ended,
        then set the age in force if it has moved."""
        for info in infos:
            if "episode" in info and info.get("age_months") is not None:
                self.ages_ended.append(float(info["age_months"]))
        if self.current is None:
            return
        new = self.at(n)
        if abs(new - self.current) < RESOLUTION / 2:
            return
        self.current = new
        self.venv.env_method("set_age", age_months=new)
        if self.eval_env is not None:
            self.eval_env.get_wrapper_attr("set_age")(age_months=new)
        month = self._month(new)
        if month != self.month:
            self.month = month
            wall = round(time.perf_counter() - self.t_start, 1)
            self.config["growth"]["history"].append(
                {"step": int(n), "age_months": new, "wall_time_s": wall})
            self.note(f"growth: the infant is {new:g} month{'' if new == 1 else 's'} old "
                      f"from step {n} ({self.growth.spec})")
            self.write()

    def columns(self) -> dict:
        if self.current is not None:
            row = {"age_months": self.current, "eval_age_months": self.current}
        else:
            ended = self.ages_ended
            row = {"age_months": float(np.mean(ended)) if ended else float("nan"),
                   "eval_age_months": self.eval_mean()}
        self.ages_ended = []
        return row

    def eval_mean(self) -> float:
        """The mean age the evaluation episodes drew (stochastic: the same draws each time)."""
        take = getattr(self.eval_env, "take_drawn", None)
        drawn = take() if take is not None else []
        return float(np.mean(drawn)) if drawn else float("nan")


def check_set_age(env: gym.Env, growth: Growth) -> None:
    """A TrainInputError unless ``env`` (a learner's env, e.g. of
    :func:`~mimo_social.train.envs.make_env`) can change its infant's age between episodes
    (the core env's ``set_age``)."""
    try:
        env.get_wrapper_attr("set_age")
    except AttributeError:
        raise TrainInputError(f"growth {growth.spec}: this env has no set_age (the core env's "
                              "age change between episodes); allowed: no growth with this "
                              "version of the env") from None


def evaluation_ages(config: Mapping[str, Any], env_kwargs: Mapping[str, Any]):
    """How ``eval`` runs a growth run (``config``: its config.json), as its last training
    evaluation did: ``(kwargs, wrap)``, the env kwargs to add (``forward`` / ``inverse``: the age
    the schedule ends at) and a function wrapping each env (``stochastic``: a
    :class:`GrowthEnv` drawing each episode's age by its seed). No growth, or an ``age_months``
    in ``env_kwargs`` (the caller's): ``({}, identity)``."""
    growth = parse_growth(config.get("growth"))
    if growth is None or "age_months" in (env_kwargs or {}):
        return {}, (lambda env: env)
    if growth.kind == "stochastic":
        return {}, (lambda env: wrap_growth(env, growth, 1))
    return {"age_months": growth.high if growth.kind == "forward" else growth.low}, \
        (lambda env: env)
