"""Smooth random actions: what the benchmark, the demo, the recorder's cost measurement and the
muscle calibration drive the infants with (one implementation for all of them)."""

from __future__ import annotations

import numpy as np

__all__ = ["smooth_random_actions", "agent_seeds", "to_bounds", "random_action_block",
           "random_voice"]


def smooth_random_actions(n_steps: int, n_motors: int, seed, dt: float = 0.01,
                          tau: float = 0.1, n_expressions: int = 7,
                          expression_period: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Low-pass filtered uniform noise per motor and a slowly switching expression id.

    Uniform noise ``w ~ U(-1, 1)`` through two cascaded first-order low-pass filters
    ``x[k+1] = a x[k] + (1 - a) in[k]``, ``a = exp(-dt / tau)`` (so the motors move smoothly,
    like a slow policy, not like white noise), rescaled to the spread of ``U(-1, 1)`` and clipped
    to [-1, 1]. The filters run ``10 tau`` first so the block starts in their steady state. The
    expression changes on average every ``expression_period`` seconds. Returns ``(motors
    (n_steps, n_motors) float32, expressions (n_steps,) int64)``; the same ``seed`` gives the
    same actions.
    """
    rng = np.random.default_rng(seed)
    a = float(np.exp(-dt / tau))
    # steady-state std of the cascade's output, relative to its input's
    gain = np.sqrt((1.0 + a) ** 3 / ((1.0 - a) * (1.0 + a * a)))
    burn = int(np.ceil(10 * tau / dt))
    noise = rng.uniform(-1.0, 1.0, (burn + n_steps, n_motors))
    x1 = np.zeros(n_motors)
    x2 = np.zeros(n_motors)
    motors = np.empty((n_steps, n_motors))
    for k in range(burn + n_steps):
        x1 = a * x1 + (1.0 - a) * noise[k]
        x2 = a * x2 + (1.0 - a) * x1
        if k >= burn:
            motors[k - burn] = x2
    motors = np.clip(motors * gain, -1.0, 1.0).astype(np.float32)
    switch = rng.random(n_steps) < dt / expression_period
    switch[0] = True
    draws = rng.integers(0, n_expressions, n_steps)
    expressions = draws[np.maximum.accumulate(np.where(switch, np.arange(n_steps), 0))]
    return motors, expressions.astype(np.int64)


def random_voice(n_steps: int, seed, dt: float = 0.01, n_sounds: int = 6,
                 period: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """A sound kind that switches on average every ``period`` seconds and a loudness drawn
    uniformly in [0, 1] at each switch: ``(kinds (n_steps,) int64, loudness (n_steps, 1)
    float32)``; the same ``seed`` gives the same sounds."""
    rng = np.random.default_rng(seed)
    switch = rng.random(n_steps) < dt / period
    switch[:1] = True
    held = np.maximum.accumulate(np.where(switch, np.arange(n_steps), 0))
    kinds = rng.integers(0, n_sounds, n_steps)[held]
    loudness = rng.random(n_steps)[held].astype(np.float32)
    return kinds.astype(np.int64), loudness.reshape(n_steps, 1)


def agent_seeds(seed: int, n_agents: int):
    return np.random.SeedSequence(seed).spawn(n_agents)


def to_bounds(motors: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Map actions in [-1, 1] linearly onto [low, high] per column (unchanged when the bounds
    are already [-1, 1], e.g. spring-damper; [0, 1] for muscles)."""
    low = np.asarray(low, np.float32)
    high = np.asarray(high, np.float32)
    if np.all(low == -1.0) and np.all(high == 1.0):
        return motors
    out = low + (motors + np.float32(1.0)) * np.float32(0.5) * (high - low)
    return np.clip(out, low, high).astype(np.float32)


def random_action_block(env, n_steps: int, seed: int, **options) -> list[dict]:
    """Every action dict of the run, built before timing (agent i always gets stream i);
    ``options`` (``tau``, ``expression_period``) go to :func:`smooth_random_actions`."""
    from gymnasium import spaces

    per_agent = []
    for name, s in zip(env.possible_agents, agent_seeds(seed, len(env.possible_agents))):
        space = env.action_space(name)
        keys = set(space.spaces) if isinstance(space, spaces.Dict) else set()
        box = space["motors"] if keys else space
        n_expr = space["expression"].n if "expression" in keys else 7
        motors, expr = smooth_random_actions(n_steps, box.shape[0], s, env.dt,
                                             n_expressions=n_expr, **options)
        motors = to_bounds(motors, box.low, box.high)
        # the voice from a stream of its own: the motors and faces stay those without a voice
        voice = (random_voice(n_steps, s.spawn(1)[0], env.dt, space["voice"].n)
                 if "voice" in keys else None)
        per_agent.append((name, keys, motors, expr, voice))
    block = []
    for k in range(n_steps):
        step = {}
        for name, keys, motors, expr, voice in per_agent:
            if not keys:
                step[name] = motors[k]
                continue
            step[name] = action = {"motors": motors[k]}
            if "expression" in keys:
                action["expression"] = int(expr[k])
            if voice is not None:
                action["voice"], action["loudness"] = int(voice[0][k]), voice[1][k]
        block.append(step)
    return block
