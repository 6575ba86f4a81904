"""The envs SB3 learns on, built from a task name of the catalogue.

``make_env(task)``
    The one path for one learner: a one-agent task and the scripted form of a social task (its
    learner, the partner scripted) are both ``gym.make(entry.gym_id, **env_kwargs)`` (the
    catalogue registers every id), then :func:`make_sb3_single`.
``make_parallel_env(task)`` / ``make_scripted_env(task)``
    A social task's ParallelEnv (every agent, or the learner only) as ``FlattenParallel``.
``make_sb3_single(env_id_or_env, flat=False, frame_stack=1)``
    A Gymnasium env with a ``Box`` action (expression logits, when the env has a ``Dict``
    action), or a ``Discrete`` expression for a face-only agent (the flat wrappers of
    :mod:`mimo_social.core.wrappers`). The observation: when the learner sees images (its eyes)
    a ``Dict`` of channel-first ``uint8`` images plus one float32 ``"vector"`` (for
    ``MultiInputPolicy`` and the CNN of :mod:`mimo_social.train.encoders`, see
    :func:`~mimo_social.train.encoders.policy_spec`), optionally the last ``frame_stack``
    frames of each image; without images, or with ``flat=True``, one float32 ``Box``.

The worker side of :class:`~mimo_social.train.vector.SpawnConcatVecEnv` lives here too: a spawned
worker imports the module of its target function, and this one imports neither SB3 nor torch.
"""

from __future__ import annotations

import traceback
from typing import Any, Callable, Mapping

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from ..core.wrappers import (DictObservationWrapper, ExpressionActionWrapper, FlatActionWrapper,
                             FlatObservationWrapper, FlattenParallel, ImageDict, ObsFlattener,
                             image_keys, is_expression_only)
from ..envs.catalog import entry, register_envs
from .tasks import check_task, task_module

__all__ = ["run_observation", "PolicyInput", "make_env", "make_parallel_env", "make_scripted_env",
           "make_sb3_single", "with_render", "world_vec_env", "call_world", "vec_worker",
           "stop_workers"]


def with_render(env_kwargs: Mapping[str, Any], render_mode: str | None) -> dict:
    """``env_kwargs`` plus ``render_mode`` when one is given."""
    kw = dict(env_kwargs)
    if render_mode is not None:
        kw["render_mode"] = render_mode
    return kw


def make_env(task: str, render_mode: str | None = None, *, flat: bool = False,
             frame_stack: int = 1, **env_kwargs):
    """The task's one-learner Gymnasium env for SB3: the catalogue's Gymnasium id of the task
    (for a social task: its learner, the partner scripted) in :func:`make_sb3_single`: Box
    actions; a ``Dict`` observation (images + ``"vector"``) when the learner sees images and
    ``flat`` is False, else one Box; ``frame_stack`` frames of each image."""
    check_task(task)
    return make_sb3_single(entry(task).gym_id, flat=flat, frame_stack=frame_stack,
                           **with_render(env_kwargs, render_mode))


def make_parallel_env(task: str, render_mode: str | None = None, *, flat: bool = True,
                      frame_stack: int = 1, **env_kwargs):
    """``FlattenParallel(parallel_env(...))``: all agents, Box actions; Box observations, or
    (``flat=False``) for agents with eyes the image ``Dict`` of :class:`ImageDict` with
    ``frame_stack`` frames."""
    return FlattenParallel(task_module(task).parallel_env(**with_render(env_kwargs, render_mode)),
                           keep_images=not flat, frame_stack=frame_stack)


def make_scripted_env(task: str, render_mode: str | None = None, *, flat: bool = False,
                      frame_stack: int = 1, **env_kwargs):
    """``FlattenParallel(scripted_env(...))``: the learner only (its partner scripted), with the
    observations of :func:`make_env` (the image ``Dict`` when it has eyes, unless ``flat``)."""
    return FlattenParallel(task_module(task).scripted_env(**with_render(env_kwargs, render_mode)),
                           keep_images=not flat, frame_stack=frame_stack)


def run_observation(config: Mapping[str, Any]) -> dict:
    """The observation layout a run was trained on (``make_env``'s ``flat`` and
    ``frame_stack``), from its ``config.json``; runs written before it was recorded were flat."""
    obs = dict(config.get("observation") or {})
    return {"flat": bool(obs.get("flat", True)), "frame_stack": int(obs.get("frame_stack", 1))}


class PolicyInput:
    """What a run's policy observes, made from one agent's observation as the env gives it:
    the flat vector (:class:`ObsFlattener`), or for a run trained on images the
    :class:`ImageDict` (``frame_stack`` frames). ``self(obs, first)``; ``first``: an episode's
    first observation. ``space``: the policy's observation space."""

    def __init__(self, config: Mapping[str, Any], space: spaces.Space):
        layout = run_observation(config)
        self._images = None
        if not layout["flat"] and image_keys(space):
            self._images = ImageDict(space, layout["frame_stack"])
            self.space = self._images.space
        else:
            self._flat = ObsFlattener(space)
            self.space = self._flat.space

    def __call__(self, obs, first: bool):
        return self._images(obs, first) if self._images is not None else self._flat(obs)


def make_sb3_single(env_id_or_env, *, flat: bool = False, frame_stack: int = 1,
                    **make_kwargs) -> gym.Env:
    """A one-agent Gymnasium env for SB3: a ``Box`` action (or a ``Discrete`` expression) and a
    ``Dict`` observation with images, or a ``Box`` one.

    ``env_id_or_env``: a registered id (``"mimo_social/Reach-v0"``; ``make_kwargs`` go to
    ``gymnasium.make``) or a ``gymnasium.Env``. A ``Dict`` observation with images (the eyes)
    becomes, unless ``flat``, the ``Dict`` of :class:`DictObservationWrapper` (each image
    channel-first ``uint8``, the last ``frame_stack`` frames stacked along the channels; the
    other keys one float32 ``"vector"``), for ``MultiInputPolicy``
    (:func:`mimo_social.train.encoders.policy_spec`). Any other non-Box observation, or any with
    ``flat=True``, is flattened by :class:`FlatObservationWrapper` (images scaled to [0, 1]).
    ``frame_stack > 1`` needs images and ``flat=False``. A ``Dict(motors, expression)`` action
    becomes the flat Box of :class:`FlatActionWrapper`, or, when the agent has no motors, the
    ``Discrete`` expression of :class:`ExpressionActionWrapper`.
    """
    if isinstance(env_id_or_env, str):
        register_envs()
        env = gym.make(env_id_or_env, **make_kwargs)
    elif isinstance(env_id_or_env, gym.Env):
        if make_kwargs:
            raise TypeError("keyword arguments are only used with an env id, not with an env")
        env = env_id_or_env
    else:
        raise TypeError(f"make_sb3_single takes an env id or a gymnasium.Env, got "
                        f"{type(env_id_or_env).__name__}")
    images = bool(image_keys(env.observation_space))
    if frame_stack != 1 and (flat or not images):
        if isinstance(env_id_or_env, str):
            env.close()     # made here
        why = "flat=True" if flat else f"an observation without images ({env.observation_space})"
        raise ValueError(f"frame_stack = {frame_stack!r} not allowed with {why}; frame "
                         "stacking stacks the images of a Dict observation (flat=False)")
    if images and not flat:
        env = DictObservationWrapper(env, frame_stack=frame_stack)
    elif (not isinstance(env.observation_space, spaces.Box)
          or env.observation_space.dtype == np.uint8):
        env = FlatObservationWrapper(env)
    if is_expression_only(env.action_space):
        env = ExpressionActionWrapper(env)
    elif not isinstance(env.action_space, spaces.Box):
        env = FlatActionWrapper(env)
    return env


def stop_workers(conns, procs, broken=()) -> None:
    """End spawned worker processes: ask each live one to close (``("close", None)``), then wait
    for their answers together (10 s each at most), join them (5 s) and terminate any still
    running; workers whose index is in ``broken`` are terminated without asking. Closes every
    connection."""
    asked = []
    for p, (conn, proc) in enumerate(zip(conns, procs)):
        if p in broken:
            proc.terminate()
            continue
        try:
            if proc.is_alive():
                conn.send(("close", None))
                asked.append(conn)
        except OSError:
            pass
    for conn in asked:
        try:
            if conn.poll(10):
                conn.recv()
        except (OSError, EOFError):
            pass
    for proc in procs:
        proc.join(5)
        if proc.is_alive():
            proc.terminate()
            proc.join(1)
    for conn in conns:
        conn.close()


# -- worker side of ``vector.SpawnConcatVecEnv`` ------------------------------------------------
def world_vec_env(env_fn: Callable[[], ParallelEnv]):
    """One world as SuperSuit's gymnasium vector env (one slot per agent)."""
    import supersuit as ss
    return ss.pettingzoo_env_to_vec_env_v1(FlattenParallel(env_fn()))


def call_world(par_env: FlattenParallel, kind: str, name: str, args: tuple = (),
               kwargs: dict | None = None):
    """Get or set an attribute of, or call a method of, one world (a FlattenParallel)."""
    if kind == "get":
        return getattr(par_env, name)
    if kind == "set":
        setattr(par_env.unwrapped, name, args[0])
        return None
    if kind == "call":
        return getattr(par_env, name)(*args, **(kwargs or {}))
    raise ValueError(f"unknown world call {kind!r}")


def vec_worker(conn, payload: bytes, n_worlds: int) -> None:
    """Process entry point: SuperSuit's in-process vector env of ``n_worlds`` worlds built from
    the cloudpickled ``env_fn`` in ``payload``; every answer on ``conn`` is ``(status, value)``."""
    try:
        import cloudpickle
        import supersuit as ss
        env_fn = cloudpickle.loads(payload)
        venv = ss.concat_vec_envs_v1(world_vec_env(env_fn), n_worlds, num_cpus=0,
                                     base_class="gymnasium")
        par_envs = [m.par_env for m in venv.vec_envs]
        conn.send(("ok", (venv.num_envs, venv.observation_space, venv.action_space,
                          dict(venv.metadata), venv.render_mode)))
    except BaseException:
        conn.send(("error", traceback.format_exc()))
        conn.close()
        return
    try:
        while True:
            try:
                cmd, data = conn.recv()
            except EOFError:  # the parent is gone
                break
            if cmd == "close":
                venv.close()
                conn.send(("ok", None))
                break
            try:
                if cmd == "step":
                    out = venv.step(data)
                elif cmd == "reset":
                    out = venv.reset(seed=data[0], options=data[1])
                elif cmd == "world":
                    out = [call_world(p, *data) for p in par_envs]
                else:
                    raise ValueError(f"unknown command {cmd!r}")
            except Exception:
                conn.send(("error", traceback.format_exc()))
            else:
                conn.send(("ok", out))
    except KeyboardInterrupt:
        pass
    finally:
        conn.close()
