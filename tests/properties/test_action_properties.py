"""Random actions of every kind against every env of the catalogue (and one with tiny eyes):
``step()`` either raises a ValueError/RuntimeError whose message names the agent and the field
(``'motors'``, ``expression``, the keys of a dict action, or ``actions`` itself), leaving the env
as it was, or accepts the action, clipping the motors into the action space's Box (then
``env.controls`` equals the clipped values and the observations are finite); never a raw error
from numpy, MuJoCo or GL, and never a change to the caller's action.

What is accepted (the rule this suite holds the env to, :func:`motor_rule` and
:func:`expression_rule`): motors are anything numpy reads as an array of shape ``(n,)`` of
integers or floats of any width (Python numbers too, ints beyond 64 bits included), every value
finite in float64; bools, complex numbers, strings, bytes, dates, masked entries, tensors that
need a gradient and NaN/inf are refused. An expression is an integer 0..6 (a Python, numpy or
tensor integer, a scalar or a one-element array); floats, bools and strings are refused.

The default run draws few examples per env and test (derandomized: CI sees the same ones);
``-m slow`` runs the same properties with many more.
"""

from __future__ import annotations

import copy
import math
import numbers
import types
from collections import OrderedDict

import numpy as np
import pytest
from gymnasium import spaces
from hypothesis import HealthCheck, Phase, given, settings, strategies as st
from hypothesis.extra import numpy as hnp

from mimo_social.envs.catalog import CATALOG, entry
from mimo_social.expressions.faces import EXPRESSIONS

try:
    import torch
except ImportError:  # the tensors are left out where torch is not installed
    torch = None

_COMMON = dict(deadline=None, derandomize=True, database=None,
               phases=[Phase.explicit, Phase.generate, Phase.shrink],
               suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                      HealthCheck.filter_too_much])
FAST = settings(max_examples=12, **_COMMON)
DEEP = settings(max_examples=300, **_COMMON)

#: every env of the catalogue without eyes (cheap), and mirror with 8x8 eyes
ENVS = [e.name for e in CATALOG] + ["mirror_8x8_eyes"]


def make_env(name: str, **kwargs):
    kwargs = {"info_text": True, **kwargs}   # the checks read the text infos
    if name == "mirror_8x8_eyes":
        return entry("mirror").parallel_env(vision={"width": 8, "height": 8}, **kwargs)
    return entry(name).parallel_env(vision=False, **kwargs)


@pytest.fixture(scope="module", params=ENVS)
def env(request):
    e = make_env(request.param)
    e.reset(seed=0)
    yield e
    e.close()


def live(env):
    if not env.agents:
        env.reset(seed=0)
    return env


def motor_box(env, agent) -> spaces.Box:
    space = env.action_space(agent)
    return space["motors"] if isinstance(space, spaces.Dict) else space


# -- the rules ------------------------------------------------------------------------------------
def motor_rule(value, n: int):
    """The float64 motor values the env must accept ``value`` as, or None if it must refuse it."""
    if torch is not None and isinstance(value, torch.Tensor):
        if value.requires_grad:
            return None
        value = value.numpy()
    if isinstance(value, np.ma.MaskedArray) and np.ma.is_masked(value):
        return None
    try:
        arr = np.asarray(value)
    except Exception:  # noqa: BLE001  (ragged lists and the like)
        return None
    if arr.dtype.kind == "O":
        if not all(isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))
                   for v in arr.flat):
            return None
        try:
            arr = np.array([float(v) for v in arr.flat]).reshape(arr.shape)
        except OverflowError:
            return None
    if arr.dtype.kind not in "iuf" or arr.shape != (n,):
        return None
    with np.errstate(over="ignore", invalid="ignore"):
        f = arr.astype(np.float64)
    return f if np.isfinite(f).all() else None


def expression_rule(value, n_expressions: int = 7):
    """The expression id the env must accept ``value`` as, or None if it must refuse it."""
    if torch is not None and isinstance(value, torch.Tensor):
        if value.requires_grad:
            return None
        value = value.numpy()
    try:
        e = np.asarray(value)
    except Exception:  # noqa: BLE001
        return None
    if e.shape not in ((), (1,)) or e.dtype.kind not in "iu":
        return None
    k = int(e.reshape(()))
    return k if 0 <= k < n_expressions else None


# -- values of every kind -------------------------------------------------------------------------
FLOAT_DTYPES = [np.float16, np.float32, np.float64]
INT_DTYPES = [np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16, np.uint32, np.uint64]
ODD_FLOATS = [0.0, -0.0, 5e-324, -2.2250738585072014e-308, 1e-310, 1.0, -1.0, 1.0000001, 3.0,
              -7.5, 1e300, -1.7976931348623157e308, 3.5e38, 65504.0, 7e4]


def floats_of(dtype, special: bool):
    width = np.dtype(dtype).itemsize * 8
    base = st.floats(width=width, allow_nan=special, allow_infinity=special,
                     allow_subnormal=True)
    with np.errstate(over="ignore"):
        odd = st.sampled_from([x for x in ODD_FLOATS          # those the dtype holds
                               if np.isfinite(np.asarray(x).astype(dtype))])
    return st.one_of(base, st.floats(-2, 2, width=width), odd)


def numeric_arrays(shape):
    return st.one_of(
        st.sampled_from(FLOAT_DTYPES).flatmap(
            lambda d: hnp.arrays(d, shape, elements=floats_of(d, special=False))),
        st.sampled_from(FLOAT_DTYPES).flatmap(
            lambda d: hnp.arrays(d, shape, elements=floats_of(d, special=True))),
        st.sampled_from(INT_DTYPES).flatmap(lambda d: hnp.arrays(d, shape)),
        hnp.arrays(np.longdouble, shape, elements=st.floats(-1e308, 1e308)),
    )


def views(arrays):
    """Arrays as callers hand them over: as they are, read-only, non-contiguous (every second
    element of a bigger array), Fortran-ordered, or a numpy subclass (matrix-free: a recarray
    view is not numeric, a masked array is)."""
    def read_only(a):
        a = a.copy()
        a.flags.writeable = False
        return a

    def strided(a):
        big = np.repeat(a[..., None], 2, axis=-1) if a.ndim else np.stack([a, a])
        return big[..., 0] if a.ndim else big[0]

    def masked(a, with_mask):
        mask = np.zeros(a.shape, bool)
        if with_mask and a.size:
            mask.flat[0] = True
        return np.ma.masked_array(a, mask=mask)

    return st.one_of(arrays, arrays.map(read_only), arrays.map(strided),
                     arrays.map(np.asfortranarray),
                     st.tuples(arrays, st.booleans()).map(lambda t: masked(*t)))


def python_numbers():
    return st.one_of(st.floats(-3, 3), st.floats(), st.integers(-5, 5),
                     st.integers(min_value=2 ** 63, max_value=2 ** 70), st.just(10 ** 400),
                     st.sampled_from([np.float32(0.5), np.int64(1), np.uint8(200),
                                      np.float16(-0.0), np.float64("nan")]))


class Hostile:
    """An object whose array conversion raises (an error of its own kind)."""

    def __array__(self, *args, **kwargs):
        raise KeyError("no array here")


class NoRepr(Hostile):
    """... and whose repr raises too (hypothesis shows what it draws: used outside it)."""

    def __repr__(self):
        raise RuntimeError("no repr either")


def not_numbers():
    return st.one_of(st.none(), st.booleans(), st.just(np.bool_(False)), st.text(max_size=4),
                     st.sampled_from(["0.5", "nan", "1e3", b"\x00", 1j, complex(0.5, 0),
                                      object(), {"a": 1}, {0.5}, ..., Hostile()]))


def torch_tensors(n: int):
    if torch is None:
        return st.nothing()
    shapes = st.sampled_from([(n,), (n,), (1, n), (max(n - 1, 0),), (n + 1,), ()])
    kinds = st.sampled_from(["float32", "float64", "float16", "int64", "bool", "complex64",
                             "grad"])

    def build(args):
        shape, kind, x = args
        if kind == "grad":
            return torch.full(shape, x, requires_grad=True)
        t = torch.full(shape, x, dtype=torch.float64)
        return t.to({"float32": torch.float32, "float64": torch.float64,
                     "float16": torch.float16, "int64": torch.int64, "bool": torch.bool,
                     "complex64": torch.complex64}[kind])
    return st.tuples(shapes, kinds, st.floats(-5, 5) | st.sampled_from([math.nan, math.inf])
                     ).map(build)


def motor_values(n: int):
    """Anything a caller might give as an agent's motors."""
    right = st.just((n,))
    odd = [s for s in [(), (n - 1,), (n + 1,), (1, n), (n, 1), (0,), (2, n)] if min(s, default=0) >= 0]
    wrong = st.one_of(st.sampled_from(odd),
                      hnp.array_shapes(max_dims=3, max_side=4))
    return st.one_of(
        views(numeric_arrays(right)),
        views(numeric_arrays(right)),                       # twice: the common case
        numeric_arrays(wrong),
        hnp.arrays(st.sampled_from([np.bool_, np.complex64, np.complex128, "U3", "S2",
                                    "datetime64[s]", "timedelta64[ms]"]), right),
        st.lists(python_numbers(), min_size=n, max_size=n),
        st.lists(python_numbers(), min_size=n, max_size=n).map(tuple),
        st.lists(python_numbers(), min_size=n, max_size=n).map(
            lambda v: np.array(v, dtype=object)),
        st.lists(st.one_of(python_numbers(), not_numbers()), min_size=n, max_size=n),
        st.lists(python_numbers(), max_size=n + 2),
        st.lists(st.lists(st.floats(-1, 1), max_size=3), min_size=1, max_size=3),  # ragged
        python_numbers(),
        not_numbers(),
        torch_tensors(n),
    )


def expressions():
    tensors = st.nothing() if torch is None else st.integers(-2, 9).map(torch.tensor)
    return st.one_of(
        st.integers(0, 6), st.integers(-3, 10), st.integers(min_value=2 ** 64),
        st.sampled_from([np.int64(3), np.uint8(6), np.int8(-1), np.uint64(7), np.int32(0)]),
        st.sampled_from([2.0, np.float32(1), True, np.bool_(True), "happy", "3", None,
                         np.array([2]), np.array([[2]]), np.array([1, 2]), [3], [[1], [2, 3]],
                         math.nan, {"id": 1}]),
        tensors)


def agent_actions(env, agent):
    """A random action for ``agent``: mostly well-formed, with bad motors or expressions, and,
    for a Dict action space, dicts with missing, extra or misnamed keys and non-dicts."""
    n = motor_box(env, agent).shape[0]
    if not isinstance(env.action_space(agent), spaces.Dict):
        return motor_values(n)
    good_motors = views(numeric_arrays(st.just((n,))))
    keys = set(env.action_space(agent).spaces)
    if keys != {"motors", "expression"}:    # the voice on: the keys of the space
        return st.one_of(voice_actions(keys, st.one_of(good_motors, motor_values(n))),
                         st.builds(lambda m: {"motors": m}, good_motors), not_numbers())
    well_formed = st.builds(lambda m, e: {"motors": m, "expression": e},
                            st.one_of(good_motors, motor_values(n)),
                            st.one_of(st.integers(0, 6), expressions()))
    odd_dicts = st.one_of(
        st.builds(lambda m: {"motors": m}, good_motors),
        st.builds(lambda e: {"expression": e}, st.integers(0, 6)),
        st.builds(lambda m, e, k: {"motors": m, "expression": e, k: 0}, good_motors,
                  st.integers(0, 6), st.sampled_from(["extra", "motor", 0, None])),
        st.builds(lambda m, e: {"motor": m, "expressions": e}, good_motors, st.integers(0, 6)),
        st.builds(lambda m, e: OrderedDict(expression=e, motors=m), good_motors,
                  st.integers(0, 6)),
        st.builds(lambda m, e: types.MappingProxyType({"motors": m, "expression": e}),
                  good_motors, st.integers(0, 6)))
    return st.one_of(well_formed, well_formed, odd_dicts, motor_values(n), not_numbers())


LOUDNESS = [0.0, 1.0, 0.5, np.float32(0.3), [0.2], np.array([0.7], np.float32), 1.5, -0.1,
            math.nan, math.inf, "loud", [0.1, 0.2], None, True]


def voice_actions(keys, motors):
    """Dict actions of a space with the voice on: well-formed keys, any expression, voice id
    and loudness (some bad)."""
    def build(m, e, v, loud):
        return {k: x for k, x in (("motors", m), ("expression", e), ("voice", v),
                                  ("loudness", loud)) if k in keys}
    return st.builds(build, motors, st.one_of(st.integers(0, 6), expressions()),
                     st.one_of(st.integers(0, 5), expressions()), st.sampled_from(LOUDNESS))


def loudness_rule(value):
    """The loudness the env must accept, or None."""
    if value is None or isinstance(value, (str, bool)):
        return None
    v = np.asarray(value, dtype=float)
    return float(v.ravel()[0]) if v.size == 1 and np.isfinite(v).all() \
        and 0.0 <= v.ravel()[0] <= 1.0 else None


def action_rule(env, agent, action):
    """(expression or None, float64 motors) the env must accept, or (fields, None): the fields
    that are wrong (its error must name one of them)."""
    n = motor_box(env, agent).shape[0]
    space = env.action_space(agent)
    if isinstance(space, spaces.Dict) and set(space.spaces) != {"motors", "expression"}:
        keys = set(space.spaces)
        if not isinstance(action, dict) or set(action) != keys:
            return ("'loudness'",), None
        e = expression_rule(action["expression"], 7) if "expression" in keys else None
        m = motor_rule(action["motors"], n)
        fields = (("'motors'",) if m is None else ()) + (
            ("expression",) if "expression" in keys and e is None else ()) + (
            ("voice",) if expression_rule(action["voice"], 6) is None else ()) + (
            ("loudness",) if loudness_rule(action["loudness"]) is None else ())
        return (e, m) if not fields else (fields, None)
    if isinstance(space, spaces.Dict):
        if not isinstance(action, (dict, OrderedDict, types.MappingProxyType)) \
                or set(action) != {"motors", "expression"}:
            return ("'motors' and 'expression'",), None
        e = expression_rule(action["expression"], space["expression"].n)
        m = motor_rule(action["motors"], n)
        fields = (("'motors'",) if m is None else ()) + (("expression",) if e is None else ())
        return (e, m) if not fields else (fields, None)
    m = motor_rule(action, n)
    return (None, m) if m is not None else (("'motors'",), None)


# -- comparing the caller's values before and after ------------------------------------------------
def snapshot(value):
    if torch is not None and isinstance(value, torch.Tensor):
        return ("tensor", value.detach().clone(), value.requires_grad)
    if isinstance(value, np.ndarray):
        return ("array", type(value), value.copy(), value.flags.writeable,
                np.ma.getmaskarray(value).copy() if isinstance(value, np.ma.MaskedArray) else None)
    if isinstance(value, (dict, OrderedDict, types.MappingProxyType)):
        return ("dict", type(value), [(k, snapshot(v)) for k, v in value.items()])
    if isinstance(value, (list, tuple)):
        return ("seq", type(value), [snapshot(v) for v in value])
    try:
        return ("other", repr(value))
    except Exception:  # noqa: BLE001  (NoRepr)
        return ("other", id(value))


def same(a, b) -> bool:
    if a[0] != b[0]:
        return False
    if a[0] == "tensor":
        return a[2] == b[2] and a[1].dtype == b[1].dtype and a[1].shape == b[1].shape and \
            bool(torch.equal(a[1], b[1]) or torch.allclose(a[1], b[1], equal_nan=True,
                                                           rtol=0, atol=0))
    if a[0] == "array":
        x, y = a[2], b[2]
        if a[1] is not b[1] or a[3] != b[3] or x.dtype != y.dtype or x.shape != y.shape:
            return False
        if (a[4] is None) != (b[4] is None) or (a[4] is not None and
                                                not np.array_equal(a[4], b[4])):
            return False
        if x.dtype.kind == "O":
            return repr(x.tolist()) == repr(y.tolist())
        return np.asarray(x).tobytes() == np.asarray(y).tobytes()
    if a[0] in ("dict", "seq"):
        if a[1] is not b[1] or len(a[2]) != len(b[2]):
            return False
        if a[0] == "dict":
            return all(ka == kb and same(va, vb) for (ka, va), (kb, vb) in zip(a[2], b[2]))
        return all(same(x, y) for x, y in zip(a[2], b[2]))
    return a == b


def env_state(env):
    d = env.world.data
    return (env.steps, float(d.time), d.qpos.copy(), d.ctrl.copy(),
            [c.copy() for c in env.controls], list(env.agents))


def assert_state_unchanged(before, after):
    assert before[0] == after[0] and before[1] == after[1] and before[5] == after[5]
    np.testing.assert_array_equal(before[2], after[2])
    np.testing.assert_array_equal(before[3], after[3])
    for x, y in zip(before[4], after[4]):
        np.testing.assert_array_equal(x, y)


def assert_finite_observations(env, obs):
    for agent, o in obs.items():
        for key, v in o.items():
            v = np.asarray(v)
            if v.dtype.kind == "f":
                assert np.isfinite(v).all(), f"{agent}: observation {key} not finite"
            assert env.observation_space(agent)[key].contains(v), \
                f"{agent}: observation {key} outside its space"


# -- the properties -------------------------------------------------------------------------------
def check_step(env, actions):
    """Step ``env`` with ``actions`` and check the outcome against the rules."""
    expected = {a: action_rule(env, a, actions[a]) for a in env.agents}
    bad = {a: field for a, (field, m) in expected.items() if m is None}
    before = env_state(env)
    snaps = {a: snapshot(actions[a]) for a in env.agents}
    try:
        obs, rewards, term, trunc, infos = env.step(actions)
    except (ValueError, RuntimeError) as e:
        msg = str(e)
        assert bad, f"a good action was refused: {msg}"
        assert any(a in msg and any(f in msg for f in fields) for a, fields in bad.items()), \
            f"the error does not name the agent and the field ({bad}): {msg}"
        assert_state_unchanged(before, env_state(env))
    else:
        assert not bad, f"accepted, though {bad} should be refused: {actions!r:.300}"
        for a, (expression, m) in expected.items():
            i = env.possible_agents.index(a)
            box = motor_box(env, a)
            c = env.controls[i]
            np.testing.assert_allclose(c, np.clip(m, box.low, box.high), rtol=1e-6, atol=1e-9)
            assert np.all(c >= box.low) and np.all(c <= box.high), f"{a}: controls outside the Box"
            if expression is not None and a in infos:
                assert infos[a]["expression"] == EXPRESSIONS[expression]
        assert all(math.isfinite(r) for r in rewards.values())
        if not any("instability" in infos[a] for a in infos):
            assert_finite_observations(env, obs)
    for a in snaps:
        assert same(snaps[a], snapshot(actions[a])), f"{a}: step() changed the caller's action"


def one_bad_agent(env, data):
    """Well-formed actions for every live agent, but a random one for one of them."""
    acts = {}
    for k, a in enumerate(env.agents):
        space = env.action_space(a)
        space.seed(k)
        acts[a] = space.sample()
    target = data.draw(st.sampled_from(env.agents), label="agent")
    acts[target] = data.draw(agent_actions(env, target), label="action")
    return acts


@FAST
@given(data=st.data())
def test_any_action_is_clipped_or_refused_naming_agent_and_field(env, data):
    live(env)
    check_step(env, one_bad_agent(env, data))


@FAST
@given(data=st.data())
def test_random_actions_for_every_agent_at_once(env, data):
    live(env)
    check_step(env, {a: data.draw(agent_actions(env, a), label=a) for a in env.agents})


def structures(env):
    """The actions argument itself: not a mapping, unknown or missing agents, odd keys."""
    good = st.just(None).map(lambda _: {a: env.action_space(a).sample() for a in env.agents})
    return st.one_of(
        st.sampled_from([None, [], (), "infant_0", 0, 1.5, np.zeros(3)]),
        good.map(lambda d: list(d.values())),
        good.map(lambda d: list(d.items())),
        st.tuples(good, st.sampled_from(["infant_9", "infant", 0, None, ("infant_0",),
                                         "INFANT_0", b"infant_0"])).map(
            lambda t: {**t[0], t[1]: next(iter(t[0].values()))}),
        st.tuples(good, st.integers(0, 7)).map(
            lambda t: {k: v for i, (k, v) in enumerate(t[0].items()) if i != t[1] % len(t[0])}),
        good.map(OrderedDict), good.map(types.MappingProxyType),
        good.map(lambda d: {np.str_(k): v for k, v in d.items()}),
    )


@FAST
@given(data=st.data())
def test_the_actions_argument_itself(env, data):
    live(env)
    acts = data.draw(structures(env))
    before = env_state(env)
    from collections.abc import Mapping
    if not isinstance(acts, Mapping):
        with pytest.raises(ValueError, match=r"actions must be a dict agent -> action"):
            env.step(acts)
        assert_state_unchanged(before, env_state(env))
        return
    unknown = [k for k in acts if k not in env.possible_agents]
    missing = [a for a in env.agents if a not in acts]
    if unknown or missing:
        with pytest.raises(ValueError) as e:
            env.step(acts)
        name = repr(unknown[0]) if unknown else repr(missing[0])
        assert name in str(e.value), str(e.value)
        assert_state_unchanged(before, env_state(env))
    else:
        env.step(acts)


@pytest.mark.slow
@DEEP
@given(data=st.data())
def test_deep_any_action_is_clipped_or_refused(env, data):
    live(env)
    check_step(env, {a: data.draw(agent_actions(env, a), label=a) for a in env.agents})


def test_the_rules_are_what_the_docstring_says():
    """The rules themselves, on hand-picked values (so the properties test what is meant)."""
    n = 3
    assert motor_rule(np.ones(3, np.float16), n) is not None
    assert motor_rule([2 ** 70, 0, 1], n) is not None                # big ints are numbers
    assert motor_rule(np.array([0.5, 1, 2], object), n) is not None
    assert motor_rule(np.full(3, 1e300), n) is not None               # clipped, not refused
    assert motor_rule([True, 0.0, 1.0], n) is not None    # numpy reads it as floats
    for bad in (np.ones(3, bool), [True, False, True], np.zeros(3, complex), ["1", "2", "3"],
                [10 ** 400, 0, 0], [0.0, math.nan, 0.0], np.full(3, np.inf), np.zeros((1, 3)),
                0.5, None, np.ma.masked_array(np.zeros(3), [1, 0, 0]),
                np.full(3, np.longdouble("1e400"))):
        assert motor_rule(bad, n) is None, bad
    assert expression_rule(np.uint8(6)) == 6 and expression_rule(np.array([2])) == 2
    for bad in (7, -1, 2.0, True, "3", None, [[1], [2, 3]], np.array([1, 2])):
        assert expression_rule(bad) is None, bad
    assert motor_rule(Hostile(), n) is None and expression_rule(Hostile()) is None
    snap = snapshot(np.zeros(2))
    assert same(snap, snapshot(np.zeros(2))) and not same(snap, snapshot(np.ones(2)))
    assert copy.deepcopy(snap)[0] == "array"


@pytest.mark.parametrize("name", ["reach", "free_play"])
def test_a_value_whose_conversion_and_repr_raise_is_refused_naming_agent_and_field(name):
    env = make_env(name)
    env.reset(seed=0)
    agent = env.possible_agents[0]
    n = motor_box(env, agent).shape[0]
    dict_action = isinstance(env.action_space(agent), spaces.Dict)
    cases = ([({"motors": NoRepr(), "expression": 0}, "'motors'"),
              ({"motors": np.zeros(n), "expression": NoRepr()}, "expression"),
              (NoRepr(), "'motors' and 'expression'")] if dict_action
             else [(NoRepr(), "'motors'")])
    others = {a: env.action_space(a).sample() for a in env.agents if a != agent}
    for action, field in cases:
        before = env_state(env)
        with pytest.raises(ValueError) as e:
            env.step({**others, agent: action})
        assert agent in str(e.value) and field in str(e.value) and "repr" in str(e.value)
        assert_state_unchanged(before, env_state(env))
    env.close()
