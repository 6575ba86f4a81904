"""A copy of an env taken at any step (``pickle`` or ``copy.deepcopy``) continues exactly as the
original: the same observations, rewards, terminations, truncations and infos, bit for bit, in
this episode and the next ones (unseeded resets continue the env's and the partners' random
streams).

Every env of the catalogue is run in each of its forms: every agent learning (random actions),
the one-learner form with the scripted partner (social tasks), the task's catalogued controller
driving ``infant_0`` (it reads MuJoCo's bias forces and mass matrix, so a copy whose last-step
quantities were recomputed acts differently), and the Gymnasium id through ``gym.make``; and one
free play with props, touch, three body sizes, five-fingered hands and muscles. Copies
are taken at several steps of one run, one of them in the second episode (tasks write model
fields at reset: the catch ball's size, mass and inertia, the standup rail's contact bits and
weld stiffness, the faces' textures), and each replays the original's actions to the end.
"""

from __future__ import annotations

import copy
import pickle

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from mimo_social.envs.catalog import CATALOG, register_envs

MAX_STEPS = 10          # short episodes: every run crosses two resets
TOTAL = 26              # control steps of the original
COPIES = ((0, pickle), (8, copy.deepcopy), (15, pickle))   # (step, how): 15 is in episode 2
#: controllers that plan for seconds at every reset: their runs keep to one episode, in the slow set
SLOW_CONTROLLERS = ("selfbody", "social_touch")


def _sample(space, rng):
    if isinstance(space, spaces.Dict):
        return {k: _sample(s, rng) for k, s in space.spaces.items()}
    if isinstance(space, spaces.Discrete):
        return int(space.start + rng.integers(space.n))
    return rng.uniform(space.low, space.high).astype(space.dtype)


def _flat(x, out, key=""):
    if isinstance(x, dict):
        for k in sorted(x, key=str):
            _flat(x[k], out, f"{key}/{k}")
    elif isinstance(x, (list, tuple)):
        for k, v in enumerate(x):
            _flat(v, out, f"{key}/{k}")
    else:
        out.append((key, x))
    return out


def _difference(a, b) -> str | None:
    """Where two step results differ (exactly: arrays by value and dtype), else None."""
    fa, fb = _flat(a, []), _flat(b, [])
    if [k for k, _ in fa] != [k for k, _ in fb]:
        return f"keys {[k for k, _ in fa]} != {[k for k, _ in fb]}"
    for (k, x), (_, y) in zip(fa, fb):
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            x, y = np.asarray(x), np.asarray(y)
            if x.dtype != y.dtype or not np.array_equal(x, y, equal_nan=x.dtype.kind in "fc"):
                return f"{k}: {x!r:.200} != {y!r:.200}"
        elif type(x) is not type(y) or (x != y and not (x != x and y != y)):
            return f"{k}: {x!r} != {y!r}"
    return None


class _Run:
    """An env and everything that picks its actions (one object, so one copy takes it all)."""

    def __init__(self, entry, form: str, seed: int, **kwargs):
        self.form = form
        if kwargs:
            self.env = entry.parallel_env(max_steps=MAX_STEPS, **kwargs)
        elif form == "gym":
            register_envs()
            self.env = gym.make(entry.gym_id, max_steps=MAX_STEPS)
        elif form == "parallel":
            self.env = entry.parallel_env(max_steps=MAX_STEPS)
        elif form == "scripted":   # the one-learner form (social tasks)
            self.env = entry.scripted_env(max_steps=MAX_STEPS)
        else:   # "controller": one episode (its copies' continuation is what is tested here)
            self.env = entry.scripted_env(max_steps=TOTAL + 1)
        self.controller = entry.controller() if form == "controller" else None
        self.rng = np.random.default_rng(seed + 1)
        self.result = self._reset(seed)

    def _reset(self, seed=None):
        if self.form == "gym":
            obs, info = self.env.reset(seed=seed)
            self.obs, self.done = obs, False
            return obs, info
        obs, infos = self.env.reset(seed=seed)
        self.obs = obs
        if self.controller is not None:
            self.controller.reset(self.env.unwrapped, "infant_0", self.rng)
        return obs, infos

    def step(self):
        """One control step (a reset first when the episode ended); its result."""
        env = self.env
        if self.form == "gym":
            if self.done:
                return self._reset()
            out = env.step(_sample(env.action_space, self.rng))
            self.done = out[2] or out[3]
            return out
        if not env.agents:
            return self._reset()
        actions = {}
        for a in env.agents:
            if self.controller is not None and a == "infant_0":
                actions[a] = self.controller.act(env.unwrapped, a, self.obs[a])
            else:
                actions[a] = _sample(env.action_space(a), self.rng)
        out = env.step(actions)
        self.obs = out[0]
        return out


def _cases():
    for e in CATALOG:
        forms = ["parallel", "gym"]
        if e.social:
            forms.append("scripted")
        for form in forms:
            yield pytest.param(e, form, id=f"{e.name}-{form}")
        if e.controller is not None:
            marks = [pytest.mark.slow] if e.name in SLOW_CONTROLLERS else []
            yield pytest.param(e, "controller", id=f"{e.name}-controller", marks=marks)


#: free play with a bit of everything: props, touch, bodies of three sizes, five-fingered hands,
#: muscles
VARIETY = dict(n_agents=3, touch=True, task_options={"props": True},
               per_agent=[{"scale": 0.6, "hands": "five_fingers"}, {"actuation": "muscle"},
                          {"scale": 2.0, "strength": 2.0, "expressions": False}])


@pytest.mark.parametrize("entry,form", [*_cases(), pytest.param(
    next(e for e in CATALOG if e.name == "free_play"), "variety", id="free_play-variety")])
def test_a_copy_taken_at_any_step_continues_exactly(entry, form):
    run = _Run(entry, form, seed=3, **(VARIETY if form == "variety" else {}))
    results = [copy.deepcopy(run.result)]
    copies = []
    for t in range(TOTAL):
        for k, how in COPIES:
            if k == t:
                copies.append((k, how.__name__, pickle.loads(pickle.dumps(run)) if how is pickle
                               else copy.deepcopy(run)))
        results.append(copy.deepcopy(run.step()))
    for k, how, twin in copies:
        for t in range(k, TOTAL):
            diff = _difference(results[t + 1], twin.step())
            assert diff is None, (f"{entry.name} ({form}): a copy taken by {how} at step {k} "
                                  f"differs from the original at step {t + 1}: {diff}")


def test_the_copy_is_independent_of_the_original():
    """A copy has its own model: a task writing model fields at reset in one (the catch ball's
    size) leaves the other's alone."""
    e = next(e for e in CATALOG if e.name == "catch")
    env = e.parallel_env()
    env.reset(seed=0)
    for how in (pickle, copy.deepcopy):
        twin = pickle.loads(pickle.dumps(env)) if how is pickle else copy.deepcopy(env)
        assert twin.world.model is not env.world.model
        assert twin.world.data.model is twin.world.model
        before = env.world.model.geom_size.copy()
        np.testing.assert_array_equal(twin.world.model.geom_size, before)
        twin.reset(seed=1)
        assert not np.array_equal(twin.world.model.geom_size, before)
        np.testing.assert_array_equal(env.world.model.geom_size, before)
