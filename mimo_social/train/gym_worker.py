"""The worker process of :class:`~mimo_social.train.workers.TimedSubprocVecEnv`.

SB3's ``SubprocVecEnv`` protocol (``step`` resets a finished env and puts
``terminal_observation`` and ``TimeLimit.truncated`` in its info), in a module that imports
neither SB3 nor torch, so that a spawned worker starts in about a second.
"""

from __future__ import annotations

__all__ = ["gym_worker"]


def gym_worker(remote, parent_remote, payload: bytes) -> None:
    """Process entry point: the env built by the cloudpickled function ``payload``."""
    import signal

    import cloudpickle

    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C reaches the whole process group:
    parent_remote.close()                          # the parent stops the run and closes us
    env = cloudpickle.loads(payload)()
    reset_info: dict = {}
    while True:
        try:
            cmd, data = remote.recv()
        except (EOFError, KeyboardInterrupt):
            break
        try:
            if cmd == "step":
                obs, reward, terminated, truncated, info = env.step(data)
                done = terminated or truncated
                info["TimeLimit.truncated"] = truncated and not terminated
                if done:
                    info["terminal_observation"] = obs
                    obs, reset_info = env.reset()
                remote.send((obs, reward, done, info, reset_info))
            elif cmd == "reset":
                options = {"options": data[1]} if data[1] else {}
                obs, reset_info = env.reset(seed=data[0], **options)
                remote.send((obs, reset_info))
            elif cmd == "render":
                remote.send(env.render())
            elif cmd == "close":
                env.close()
                remote.close()
                break
            elif cmd == "get_spaces":
                remote.send((env.observation_space, env.action_space))
            elif cmd == "env_method":
                remote.send(env.get_wrapper_attr(data[0])(*data[1], **data[2]))
            elif cmd == "get_attr":
                remote.send(env.get_wrapper_attr(data))
            elif cmd == "has_attr":
                try:
                    env.get_wrapper_attr(data)
                    remote.send(True)
                except AttributeError:
                    remote.send(False)
            elif cmd == "set_attr":
                remote.send(setattr(env, data[0], data[1]))
            elif cmd == "is_wrapped":
                w, found = env, False
                while w is not None and not found:
                    found = isinstance(w, data)
                    w = getattr(w, "env", None)
                remote.send(found)
            else:
                raise NotImplementedError(f"`{cmd}` is not implemented in the worker")
        except KeyboardInterrupt:
            break
