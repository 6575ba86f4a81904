"""What sensorimotor delays cost per step: two infants in free play with touch, undelayed, with
proprioception, vestibular and touch delayed 100 ms, and with the motor command delayed too
(docs/bodies.md, "Sensorimotor delays"). The envs take turns under the same actions; the fastest
and the median turn are shown (the fastest is the least disturbed by other jobs on the machine).
Then the buffers alone, in microseconds.

    python examples/delay_cost.py            # 300 steps per turn, 20 turns
    python examples/delay_cost.py 100 5
"""

import sys
import time

import numpy as np

from mimo_social.core.delays import MotorDelay, SenseDelay
from mimo_social.envs import free_play_v0

SENSES_MS = {"proprioception": 100.0, "vestibular": 100.0, "touch": 100.0}
VARIANTS = {"no delays": None, "senses 100 ms": SENSES_MS,
            "senses + motor 100 ms": {**SENSES_MS, "motor": 100.0}}


def per_step_ms(steps: int, rounds: int) -> dict:
    envs = {name: free_play_v0.parallel_env(n_agents=2, touch=True, expressions=False,
                                            delays=delays, max_steps=10 ** 6)
            for name, delays in VARIANTS.items()}
    space = envs["no delays"].action_space("infant_0")
    rng = np.random.default_rng(0)
    actions = [{a: 0.3 * rng.uniform(space.low, space.high) for a in ("infant_0", "infant_1")}
               for _ in range(steps)]
    times = {name: [] for name in envs}
    for _ in range(rounds):
        for name, env in envs.items():
            env.reset(seed=0)
            t0 = time.perf_counter()
            for a in actions:
                env.step(a)
            times[name].append(1e3 * (time.perf_counter() - t0) / steps)
    return times


def buffers_us(n: int = 200_000) -> dict:
    ring = SenseDelay(10)
    ring.reset({"x": np.zeros(100, np.float32)})
    reading = {"x": np.zeros(100, np.float32)}
    t0 = time.perf_counter()
    for _ in range(n):
        ring.push(reading)
    push = time.perf_counter() - t0
    motor, u, c = MotorDelay(10, 44), np.ones(44), np.zeros(44)
    lo, hi = -np.ones(44), np.ones(44)
    motor.reset(c)
    t0 = time.perf_counter()
    for _ in range(n):
        np.clip(u, lo, hi, out=motor.slot())
        np.copyto(c, motor.advance())
    delayed = time.perf_counter() - t0
    t0 = time.perf_counter()
    for _ in range(n):
        np.clip(u, lo, hi, out=c)
    plain = time.perf_counter() - t0
    return {"sense ring push": push, "motor ring clip + copy": delayed,
            "clip without a delay": plain, "n": n}


if __name__ == "__main__":
    steps = int(sys.argv[1]) if len(sys.argv) > 1 else 300
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    for name, t in per_step_ms(steps, rounds).items():
        print(f"{name:24s} fastest {min(t):.3f} ms/step, median {np.median(t):.3f}")
    b = buffers_us()
    for name in ("sense ring push", "motor ring clip + copy", "clip without a delay"):
        print(f"{name:24s} {1e6 * b[name] / b['n']:.2f} us")
