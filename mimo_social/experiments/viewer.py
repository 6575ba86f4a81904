"""Watch any catalogue env live in MuJoCo's own viewer (``mimo-social view``).

:func:`view_env` builds a catalogue env with every agent under one control:

* ``scripted``: the task's scripted controller (the catalogue entry's ``controller``) drives each
  learner of the task's one-learner env (``scripted_env``: a social task's partner is scripted by
  the task itself); a task without one (free play) falls back to zero actions, with a note;
* ``zero``: the resting action of every agent (:func:`~mimo_social.partners.base.zero_action`);
* ``random``: actions sampled from each agent's action space (seeded).

``age_months`` sets the age of every infant agent (adults keep theirs). :func:`run_viewer` steps
the env in real time (one control step per ``env.dt`` of wall time), syncing a viewer handle
after each step and resetting at the end of each episode (episode ``k`` seeded ``seed + k``);
the handle is anything with ``is_running()``, ``sync()`` and ``lock()`` (a context manager), so
the loop runs headless in tests with a stand-in. :func:`open_viewer` opens the real one
(``mujoco.viewer.launch_passive``) or raises :class:`ViewerUnavailable` saying why and what to
do instead.
"""

from __future__ import annotations

import copy
import os
import threading
import time
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..envs.catalog import entry
from ..partners.base import zero_action

__all__ = ["CONTROLS", "ViewerUnavailable", "ViewSetup", "ViewRun", "display_problem",
           "view_env", "open_viewer", "run_viewer", "frame_agents", "INSTEAD"]

#: the controls every agent can be put under
CONTROLS = ("scripted", "zero", "random")
#: what to do where no viewer can open
INSTEAD = ("run it on a machine with a display, or record an episode with 'mimo-social demo' "
           "(or a recorder) and watch it in Rerun")


class ViewerUnavailable(RuntimeError):
    """MuJoCo's viewer cannot open here; the message says why and what to do instead."""


class _Zero:
    def __init__(self, space):
        self.action = zero_action(space)

    def reset(self, env, agent: str, rng: np.random.Generator) -> None:
        pass

    def act(self, env, agent: str, obs):
        return self.action


class _Random:
    def __init__(self, space):
        self.space = copy.deepcopy(space)

    def reset(self, env, agent: str, rng: np.random.Generator) -> None:
        self.space.seed(int(rng.integers(2 ** 31)))

    def act(self, env, agent: str, obs):
        return self.space.sample()


@dataclass
class ViewSetup:
    """An env ready to watch: ``env`` (a PettingZoo ParallelEnv of the package), ``policies``
    (agent -> policy with ``reset(env, agent, rng)`` and ``act(env, agent, obs)``), ``notes``
    (things to tell the user, e.g. a fallback)."""

    task: str
    control: str
    env: Any
    policies: dict
    notes: list[str] = field(default_factory=list)


@dataclass
class ViewRun:
    """What :func:`run_viewer` did: control ``steps`` taken, ``episodes`` started (resets,
    the first included) and the seeds they were reset with."""

    steps: int = 0
    episodes: int = 0
    seeds: list[int] = field(default_factory=list)


def display_problem(environ=None) -> str | None:
    """Why no window can open here (None: a display is named)."""
    environ = os.environ if environ is None else environ
    if environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY"):
        return None
    return "no display (DISPLAY and WAYLAND_DISPLAY are unset)"


def _age_settings(make: Callable, age_months: float | None) -> tuple[dict, list[str]]:
    """The env keyword arguments giving every infant agent ``age_months``, and notes."""
    if age_months is None:
        return {}, []
    probe = make()
    bodies = [c.body for c in probe.agent_configs]
    probe.close()
    if "infant" not in bodies:
        return {}, [f"no infant agent: age {age_months:g} months not applied"]
    return {"per_agent": [{"age_months": float(age_months)} if b == "infant" else {}
                          for b in bodies]}, []


def view_env(task: str, control: str = "scripted", age_months: float | None = None,
             **env_kwargs) -> ViewSetup:
    """The catalogue env of ``task`` with every agent under ``control`` (one of
    :data:`CONTROLS`) and every infant aged ``age_months`` (None: the task's default)."""
    e = entry(task)
    if control not in CONTROLS:
        raise ValueError(f"control {control!r} not allowed; allowed: {', '.join(CONTROLS)}")
    notes = []
    scripted = control == "scripted" and e.controller is not None
    if control == "scripted" and e.controller is None:
        notes.append(f"{task} has no scripted controller: its agents take zero actions")
    factory = e.scripted_env if scripted else e.parallel_env
    age_kw, age_notes = _age_settings(lambda: factory(**env_kwargs), age_months)
    env = factory(**env_kwargs, **age_kw)
    notes += age_notes
    policies = {}
    for agent in env.possible_agents:
        if scripted:
            policies[agent] = e.controller()
        elif control == "random":
            policies[agent] = _Random(env.action_space(agent))
        else:
            policies[agent] = _Zero(env.action_space(agent))
    return ViewSetup(task, control, env, policies, notes)


def open_viewer(model, data):
    """MuJoCo's passive viewer on ``model`` and ``data``; a :class:`ViewerUnavailable` saying
    why (no display, or the viewer failed to open) and what to do instead."""
    problem = display_problem() or _glfw_problem()
    if problem is not None:
        raise ViewerUnavailable(f"{problem}; {INSTEAD}")
    try:
        import mujoco.viewer

        before = set(threading.enumerate())
        handle = mujoco.viewer.launch_passive(model, data, show_left_ui=False,
                                              show_right_ui=False)
        return _Window(handle, [t for t in threading.enumerate() if t not in before])
    except Exception as e:  # noqa: BLE001 - any failure to open is reported the same way
        why = " ".join(str(e).split()) or type(e).__name__
        raise ViewerUnavailable(f"MuJoCo's viewer did not open ({type(e).__name__}: {why}); "
                                f"{INSTEAD}") from None


class _Window:
    """The viewer's handle, whose :meth:`close` also waits for the viewer's thread to end (else
    the thread may still be tearing its window down when the interpreter ends GLFW at exit:
    a crash)."""

    def __init__(self, handle, threads):
        self.handle, self.threads = handle, threads

    def is_running(self) -> bool:
        return self.handle.is_running()

    def sync(self) -> None:
        self.handle.sync()

    def lock(self):
        return self.handle.lock()

    @property
    def cam(self):
        """The viewer's free camera (``mujoco.MjvCamera``)."""
        return self.handle.cam

    def close(self) -> None:
        self.handle.close()
        for thread in self.threads:
            thread.join(timeout=10.0)


def _glfw_problem() -> str | None:
    """Why GLFW (the viewer's windows) cannot start here, if it cannot. Asked first: the
    viewer's own start, failing, ends the process from MuJoCo's C code."""
    try:
        import glfw
    except Exception as e:  # noqa: BLE001 - any import failure means no windows
        return f"GLFW, which the viewer needs, is not available ({type(e).__name__}: {e})"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ok = glfw.init()
    if ok:
        glfw.terminate()
        return None
    why = "; ".join(" ".join(str(w.message).split()) for w in caught) or "glfw.init() failed"
    return f"no window can be opened on the display ({why})"


def frame_agents(handle, env) -> None:
    """Point the viewer's free camera at the agents (their root bodies' middle), from far
    enough away to see them all, a little from above."""
    world = env.unwrapped.world
    roots = np.array([world.data.xpos[a.root_body] for a in world.agents])
    with handle.lock():
        cam = handle.cam
        cam.lookat[:] = roots.mean(axis=0)
        cam.distance = 1.5 + 1.5 * float(np.ptp(roots[:, :2], axis=0).max())
        cam.azimuth, cam.elevation = 150.0, -20.0


def _reset(setup: ViewSetup, seed: int) -> dict:
    obs, _ = setup.env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    for agent, policy in setup.policies.items():
        policy.reset(setup.env.unwrapped, agent, rng)
    return obs


def run_viewer(setup: ViewSetup, handle, seed: int = 0, steps: int | None = None,
               realtime: bool = True, sleep: Callable[[float], None] = time.sleep,
               clock: Callable[[], float] = time.perf_counter) -> ViewRun:
    """Step ``setup.env`` under its policies while ``handle.is_running()`` (and, with
    ``steps``, for that many control steps), the physics under ``handle.lock()``, then
    ``handle.sync()``; with ``realtime`` each step lasts at least ``env.dt`` of wall time.
    At the end of an episode the env is reset with the next seed."""
    env, run = setup.env, ViewRun()
    core = env.unwrapped        # what policies get (a scripted env's partners act inside it)
    obs = _reset(setup, seed)
    run.episodes, run.seeds = 1, [seed]
    handle.sync()
    while handle.is_running() and (steps is None or run.steps < steps):
        start = clock()
        actions = {a: setup.policies[a].act(core, a, obs[a]) for a in env.agents}
        with handle.lock():
            obs, _, terms, truncs, _ = env.step(actions)
            if not env.agents or all(terms[a] or truncs[a] for a in terms):
                run.seeds.append(seed + run.episodes)
                run.episodes += 1
                obs = _reset(setup, run.seeds[-1])
        handle.sync()
        run.steps += 1
        if realtime:
            left = env.dt - (clock() - start)
            if left > 0:
                sleep(left)
    return run
