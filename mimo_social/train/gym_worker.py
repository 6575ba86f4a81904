"""The worker process of :class:`~mimo_social.train.workers.TimedSubprocVecEnv`.

One worker holds a block of envs and steps them one after the other for each message, so that a
pipe round trip (and the learner's policy call) serves several env steps. Each env follows SB3's
``SubprocVecEnv`` protocol: ``step`` resets a finished env and puts ``terminal_observation``
and ``TimeLimit.truncated`` in its info. The module imports neither SB3 nor torch, so that a
spawned worker starts in about a second.

Messages ``(command, data)``; ``data`` names the worker's own envs by their index in its block:
``step`` (one action per env) -> ``(obs, rewards, dones, infos, reset_infos)`` with the
observations stacked (an array, or a dict of arrays); ``reset`` (one ``(seed, options)`` per env)
-> ``(obs, reset_infos)``; ``render``, ``get_attr``, ``set_attr``, ``env_method``,
``is_wrapped`` -> one answer per env named; ``get_spaces``; ``close``.
"""

from __future__ import annotations

__all__ = ["gym_worker", "stack_obs"]


def stack_obs(obs):
    """Observations of several envs as one batch: an array, or for ``Dict`` observations (images
    and a vector) a dict key -> array, as SB3's VecEnvs give them."""
    import numpy as np
    if isinstance(obs[0], dict):
        return {k: np.stack([o[k] for o in obs]) for k in obs[0]}
    return np.stack(obs)


def _step(env, action):
    obs, reward, terminated, truncated, info = env.step(action)
    done = terminated or truncated
    info["TimeLimit.truncated"] = truncated and not terminated
    reset_info: dict = {}
    if done:
        info["terminal_observation"] = obs
        obs, reset_info = env.reset()
    return obs, reward, done, info, reset_info


def _is_wrapped(env, cls) -> bool:
    while env is not None:
        if isinstance(env, cls):
            return True
        env = getattr(env, "env", None)
    return False


def _has_attr(env, name) -> bool:
    try:
        env.get_wrapper_attr(name)
    except AttributeError:
        return False
    return True


def _answer(envs, cmd, data):
    if cmd == "step":
        import numpy as np
        obs, rews, dones, infos, resets = zip(*(_step(e, a) for e, a in zip(envs, data)))
        return (stack_obs(obs), np.asarray(rews, dtype=np.float32), np.asarray(dones, bool),
                infos, resets)
    if cmd == "reset":
        out = [e.reset(seed=s, **({"options": o} if o else {})) for e, (s, o) in zip(envs, data)]
        obs, infos = zip(*out)
        return stack_obs(obs), infos
    if cmd == "get_spaces":
        return envs[0].observation_space, envs[0].action_space
    indices, rest = data
    chosen = [envs[i] for i in indices]
    if cmd == "render":
        return [e.render() for e in chosen]
    if cmd == "env_method":
        name, args, kwargs = rest
        return [e.get_wrapper_attr(name)(*args, **kwargs) for e in chosen]
    if cmd == "get_attr":
        return [e.get_wrapper_attr(rest) for e in chosen]
    if cmd == "has_attr":
        return [_has_attr(e, rest) for e in chosen]
    if cmd == "set_attr":
        return [setattr(e, rest[0], rest[1]) for e in chosen]
    if cmd == "is_wrapped":
        return [_is_wrapped(e, rest) for e in chosen]
    raise NotImplementedError(f"`{cmd}` is not implemented in the worker")


def gym_worker(remote, parent_remote, payload: bytes) -> None:
    """Process entry point: the envs built by the cloudpickled list of functions ``payload``
    (one env each)."""
    import signal

    import cloudpickle

    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C reaches the whole process group:
    parent_remote.close()                          # the parent stops the run and closes us
    envs = [fn() for fn in cloudpickle.loads(payload)]
    while True:
        try:
            cmd, data = remote.recv()
        except (EOFError, KeyboardInterrupt):
            break
        try:
            if cmd == "close":
                for env in envs:
                    env.close()
                remote.close()
                break
            remote.send(_answer(envs, cmd, data))
        except KeyboardInterrupt:
            break
