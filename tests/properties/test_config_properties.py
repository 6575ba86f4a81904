"""Every setting of the package, fed random bad values, is refused with a ConfigError that names
the setting (and its owner), or is accepted and stored as a canonical value of its declared type;
never a raw TypeError, AttributeError, numpy or MuJoCo error.

The settings are discovered, not listed: the fields of AgentConfig, of every registered sense's
config, of PhysicsConfig and of every catalogue task's Options, the env's own arguments, reset
seeds and the partners' constructor arguments. Cheap checks (dataclasses alone) run many
examples; env construction runs few (each env is built, reset and stepped once when a value is
accepted)."""

from __future__ import annotations

import dataclasses
import inspect
import sys
import math
import types
import typing
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from mimo_social import partners as partners_pkg
from mimo_social.core.config import AgentConfig, PhysicsConfig, parse_physics, resolve_agents
from mimo_social.envs.catalog import CATALOG
from mimo_social.senses import SENSES
from mimo_social.util.checks import ConfigError

CHEAP = settings(max_examples=40, deadline=None, derandomize=True,
                 suppress_health_check=[HealthCheck.too_slow])
ENV = settings(max_examples=40, deadline=None, derandomize=True,
               suppress_health_check=[HealthCheck.too_slow])

# -- bad (and some good) values of any kind ------------------------------------------------------
NUMBERS = st.one_of(
    st.integers(-10**6, 10**6), st.integers(min_value=2**70).map(lambda v: v),
    st.floats(allow_nan=True, allow_infinity=True), st.floats(-3, 3),
    st.sampled_from([np.float64(0.5), np.float32(1.0), np.int64(2), np.int32(0), 1e300, -1e-9]))
STRINGS = st.sampled_from(["", "yes", "no", "0", "1", "1.5", "true", "False", "nan", "abc",
                           "mitten", "standing", "sparse"])
WEIRD = st.one_of(
    st.none(), st.booleans(), st.just(np.bool_(True)), NUMBERS, STRINGS,
    st.lists(st.one_of(NUMBERS, st.none(), STRINGS), max_size=5),
    st.lists(st.floats(-2, 2), min_size=1, max_size=5).map(tuple),
    st.lists(st.floats(0, 1), min_size=2, max_size=4).map(np.array),
    st.dictionaries(STRINGS, NUMBERS, max_size=2), st.just(object()), st.just(b"bytes"),
    st.just(np.zeros((2, 2))), st.just({1, 2}))


def near(default):
    """Values shaped like the default: the default itself, sequences of its length with odd
    entries, numbers of its type out of range."""
    out = [WEIRD]
    if isinstance(default, tuple) and default:
        n = len(default)
        out.append(st.lists(st.one_of(NUMBERS, STRINGS, st.none()), min_size=n, max_size=n)
                   .map(tuple))
        out.append(st.lists(st.floats(-20, 20), min_size=n, max_size=n).map(tuple))
    elif isinstance(default, (int, float)) and not isinstance(default, bool):
        out.append(st.floats(-4 * abs(default) - 1, 4 * abs(default) + 1))
    return st.one_of(*out)


# -- what a stored value of a declared type may be -----------------------------------------------
def conforms(value, hint) -> bool:
    """``value`` is canonical for the type hint: a float is a finite Python float, an int a
    Python int (not a bool), a bool a Python bool, tuples typed element by element."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if hint is type(None):
        return value is None
    if origin in (typing.Union, types.UnionType):
        return any(conforms(value, a) for a in args)
    if hint is typing.Any:
        return True
    if hint is float:
        return type(value) is float and math.isfinite(value)
    if hint is int:
        return type(value) is int
    if hint is bool:
        return type(value) is bool
    if hint is str:
        return isinstance(value, str)
    if hint is tuple:
        return type(value) is tuple
    if origin is tuple:
        if type(value) is not tuple:
            return False
        if len(args) == 2 and args[1] is Ellipsis:
            return all(conforms(v, args[0]) for v in value)
        return len(value) == len(args) and all(conforms(v, a) for v, a in zip(value, args))
    if isinstance(hint, type):
        return isinstance(value, hint)
    raise AssertionError(f"no rule for the type hint {hint!r}")


def hints(cls) -> dict:
    return typing.get_type_hints(cls)


def refused_or_canonical(build, cls, name, value, *words):
    """``build(value)`` -> the object holding ``name``: a ConfigError naming ``name`` (and each
    of ``words``), or the stored value canonical for its type, stored the same when given
    again."""
    try:
        obj = build(value)
    except ConfigError as e:
        for w in (name, *words):
            assert w in str(e), f"{cls.__name__}.{name}={value!r}: error {e} does not name {w!r}"
        return None
    stored = getattr(obj, name)
    hint = hints(cls)[name]
    assert conforms(stored, hint), f"{cls.__name__}.{name}={value!r} stored as {stored!r} ({hint})"
    assert getattr(build(stored), name) == stored
    return obj


# -- the dataclasses ------------------------------------------------------------------------------
AGENT_FIELDS = [f.name for f in dataclasses.fields(AgentConfig)]
SENSE_FIELDS = [(s, f.name) for s, entry in SENSES.items() for f in dataclasses.fields(entry.config)]
PHYSICS_FIELDS = [f.name for f in dataclasses.fields(PhysicsConfig)]


@lru_cache(maxsize=None)
def task_of(name):
    """The task object of a catalogue env (its Options class, its n_agents range)."""
    return next(e for e in CATALOG if e.name == name).parallel_env().task


OPTION_FIELDS = [(e.name, f.name) for e in CATALOG
                 for f in dataclasses.fields(task_of(e.name).Options)]


@pytest.mark.parametrize("name", AGENT_FIELDS)
@CHEAP
@given(data=st.data())
def test_agent_settings(name, data):
    default = getattr(AgentConfig(), name)
    value = data.draw(near(default), label=name)

    def build(v):   # the second agent's own setting: the error names infant_1
        return resolve_agents(2, {}, [{}, {name: v}])[1]
    refused_or_canonical(build, AgentConfig, name, value, "infant_1")


@pytest.mark.parametrize("sense,name", SENSE_FIELDS)
@CHEAP
@given(data=st.data())
def test_sense_settings(sense, name, data):
    cls = SENSES[sense].config
    value = data.draw(near(getattr(cls(), name)), label=name)

    def build(v):
        return getattr(resolve_agents(1, {sense: {name: v}})[0], sense)
    refused_or_canonical(build, cls, name, value, "infant_0", sense)


@pytest.mark.parametrize("name", PHYSICS_FIELDS)
@CHEAP
@given(data=st.data())
def test_physics_settings(name, data):
    value = data.draw(near(getattr(PhysicsConfig(), name)), label=name)
    refused_or_canonical(lambda v: parse_physics({name: v}), PhysicsConfig, name, value,
                         "physics")


@pytest.mark.parametrize("task,name", OPTION_FIELDS)
@CHEAP
@given(data=st.data())
def test_task_options(task, name, data):
    cls = task_of(task).Options
    value = data.draw(near(getattr(cls(), name)), label=name)
    obj = refused_or_canonical(lambda v: cls.of({name: v}), cls, name, value, task)
    if obj is not None:   # replace() checks again and keeps the canonical value
        assert getattr(dataclasses.replace(obj, **{name: getattr(obj, name)}), name) \
            == getattr(obj, name)


# -- whole envs -----------------------------------------------------------------------------------
ENV_ARGS = ("max_steps", "render_size", "render_mode", "n_agents", "physics", "per_agent",
            "task_options", "scene")


def _zero_step(env):
    env.reset(seed=0)
    env.step({a: env.action_space(a).sample() * 0 if not hasattr(env.action_space(a), "spaces")
              else {k: np.zeros(s.shape, s.dtype) if hasattr(s, "shape") and s.shape
                    else 0 for k, s in env.action_space(a).spaces.items()}
              for a in env.agents})


@pytest.mark.parametrize("entry", CATALOG, ids=lambda e: e.name)
@ENV
@given(data=st.data())
def test_env_settings(entry, data):
    """One setting of one kind (an env argument, an agent's, physics, a task option) with a
    random value, given to the env or its scripted form: a ConfigError naming it, or an env that
    resets and steps."""
    task = task_of(entry.name)
    kind = data.draw(st.sampled_from(["env", "agent", "physics", "option"]), label="kind")
    if kind == "env":
        name = data.draw(st.sampled_from(ENV_ARGS), label="name")
        value = data.draw(WEIRD if name != "n_agents" else st.one_of(WEIRD, st.integers(0, 9)),
                          label="value")
        kwargs, words = {name: value}, (name,)
    elif kind == "agent":
        name = data.draw(st.sampled_from([n for n in AGENT_FIELDS if n not in SENSES]),
                         label="name")
        value = data.draw(near(getattr(AgentConfig(), name)), label="value")
        kwargs, words = {name: value}, (name,)
    elif kind == "physics":
        name = data.draw(st.sampled_from(PHYSICS_FIELDS), label="name")
        value = data.draw(near(getattr(PhysicsConfig(), name)), label="value")
        kwargs, words = {"physics": {name: value}}, ("physics", name)
    else:
        fields = [f.name for f in dataclasses.fields(task.Options)]
        name = data.draw(st.sampled_from(fields), label="name")
        value = data.draw(near(getattr(task.Options(), name)), label="value")
        kwargs, words = {"task_options": {name: value}}, (entry.name, name)
    scripted = data.draw(st.booleans(), label="scripted form")
    try:
        made = (entry.scripted_env if scripted else entry.parallel_env)(**kwargs)
    except ConfigError as e:
        text = str(e)
        if "overlap" in text:   # a body setting that makes the task's placement collide
            assert "infant_" in text and "position" in text and name in text, text
        else:
            for w in words:
                assert w in text, f"{kwargs}: error {text} does not name {w!r}"
        return
    env = made.unwrapped
    if kind == "agent":
        for cfg in env.agent_configs:
            assert conforms(getattr(cfg, name), hints(AgentConfig)[name]), (kwargs, cfg)
    elif kind == "physics":
        assert conforms(getattr(env.physics, name), hints(PhysicsConfig)[name])
    elif kind == "option":
        assert conforms(getattr(env.task.options, name), hints(task.Options)[name])
    else:
        assert type(env.max_steps) is int and env.max_steps >= 1
        assert len(env.render_size) == 2 and all(type(v) is int for v in env.render_size)
    _zero_step(made)
    made.close()


SEEDS = st.one_of(WEIRD, st.integers(0, 2**70), st.integers(-2**70, -1),
                  st.sampled_from([np.int64(7), np.uint32(3), np.int8(-1)]))


@lru_cache(maxsize=None)
def seeded_forms(name):
    """The env, its scripted form and its Gymnasium form (made once: resets are what is tested)."""
    e = next(e for e in CATALOG if e.name == name)
    return e.parallel_env(), e.scripted_env(), e.gym_env()


@pytest.mark.parametrize("entry", CATALOG, ids=lambda e: e.name)
@settings(max_examples=10, deadline=None, derandomize=True)
@given(seed=SEEDS)
def test_reset_seeds(entry, seed):
    """reset(seed=...) of the env, its scripted form and its Gymnasium form: a ConfigError naming
    ``seed`` unless the seed is None or an integer >= 0 (numpy's too)."""
    envs = seeded_forms(entry.name)
    ok = seed is None or (isinstance(seed, (int, np.integer)) and not isinstance(seed, bool)
                          and seed >= 0)
    for env in envs:
        if ok:
            env.reset(seed=seed)
        else:
            with pytest.raises(ConfigError, match="seed"):
                env.reset(seed=seed)


# -- partners -------------------------------------------------------------------------------------
def _partner_classes():
    out = {}
    # the reusable partners, and every task's scripted solution and other policies (what its
    # package exports: e.g. imitation's demonstrator)
    tasks = [sys.modules[e.controller.__module__.rsplit(".", 1)[0]] for e in CATALOG if e.controller]
    for mod in (partners_pkg, *tasks):
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name)
            if inspect.isclass(obj) and callable(getattr(obj, "act", None)) \
                    and callable(getattr(obj, "reset", None)):
                out[obj.__name__] = obj
    return out


PARTNER_ARGS = [(cls, p.name) for cls in _partner_classes().values()
                for p in inspect.signature(cls).parameters.values()
                if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


#: valid values of the arguments a partner cannot be made without (the others are fuzzed one at
#: a time with these in place; a required argument itself is fuzzed like the rest)
REQUIRED_EXAMPLES = {
    "ReplayCaregiver": {"stream": {"motors": np.zeros((3, 2), np.float32),
                                   "expression": np.zeros(3, np.int64), "dt": 0.01}},
}


def test_every_required_partner_argument_has_an_example():
    for cls in _partner_classes().values():
        required = [p.name for p in inspect.signature(cls).parameters.values()
                    if p.default is inspect.Parameter.empty
                    and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
        assert set(required) <= set(REQUIRED_EXAMPLES.get(cls.__name__, {})), (cls, required)


@pytest.mark.parametrize("cls,name", PARTNER_ARGS, ids=lambda v: getattr(v, "__name__", v))
@settings(max_examples=25, deadline=None, derandomize=True)
@given(data=st.data())
def test_partner_settings(cls, name, data):
    """A partner made with one odd argument: a ValueError naming the argument, or made."""
    default = inspect.signature(cls).parameters[name].default
    value = data.draw(near(default if default is not inspect.Parameter.empty else None))
    try:
        partner = cls(**{**REQUIRED_EXAMPLES.get(cls.__name__, {}), name: value})
    except ValueError as e:
        assert name in str(e), f"{cls.__name__}({name}={value!r}): {e}"
        return
    stored = getattr(partner, name, None)
    if isinstance(default, bool):
        assert type(stored) is bool, (name, value, stored)
    elif isinstance(default, (int, float)) and stored is not None:   # numbers stay numbers
        assert type(stored) in (int, float) and math.isfinite(stored), (name, value, stored)
    elif isinstance(default, tuple) and all(isinstance(v, (int, float)) for v in default) \
            and isinstance(stored, tuple):
        assert all(type(v) is float and math.isfinite(v) for v in stored), (name, value, stored)
