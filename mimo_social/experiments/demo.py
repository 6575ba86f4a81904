"""``mimo-social demo``: infants face to face in free play, recorded to a Rerun ``.rrd`` file.

Every motor follows its own low-pass filtered Ornstein-Uhlenbeck process (smooth, seeded random
movement) and every infant switches to a new facial expression about every 1.5 simulated seconds.
The run is recorded with :class:`mimo_social.recording.recorder.Recorder`; open the file with
``rerun FILE.rrd``.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from gymnasium import spaces
from tqdm import tqdm

from ..expressions.faces import EXPRESSIONS

__all__ = ["add_parser", "run", "SmoothNoise", "ExpressionSchedule"]

DEFAULT_RECORDING = "recordings/demo.rrd"


class SmoothNoise:
    """Smooth random commands in [-1, 1], one per motor: low-pass filtered Ornstein-Uhlenbeck noise.

    The OU process ``x += -x / tau * dt + sigma * sqrt(2 dt / tau) * N(0, 1)`` wanders with a
    standard deviation of ``sigma`` and a correlation time of ``tau`` seconds; a first-order
    low-pass filter with time constant ``smoothing`` takes the jitter out of its steps. Starts at
    rest (0).
    """

    def __init__(self, n: int, dt: float, rng: np.random.Generator, tau: float = 0.5,
                 sigma: float = 0.5, smoothing: float = 0.15):
        self.x = np.zeros(n)
        self.y = np.zeros(n)
        self.decay = dt / tau
        self.scale = sigma * math.sqrt(2.0 * dt / tau)
        self.blend = min(1.0, dt / smoothing)
        self.rng = rng

    def __call__(self) -> np.ndarray:
        self.x += -self.decay * self.x + self.scale * self.rng.standard_normal(self.x.shape)
        self.y += self.blend * (self.x - self.y)
        return np.clip(self.y, -1.0, 1.0).astype(np.float32)


class ExpressionSchedule:
    """Per agent, a new (different) expression every ``period`` +- ``jitter`` seconds."""

    def __init__(self, n_agents: int, rng: np.random.Generator, period: float = 1.5,
                 jitter: float = 0.3):
        self.rng, self.period, self.jitter = rng, period, jitter
        self.current = np.zeros(n_agents, dtype=np.int64)          # everyone starts neutral
        self.next_switch = np.array([self._interval() for _ in range(n_agents)])

    def _interval(self) -> float:
        return self.period + self.rng.uniform(-self.jitter, self.jitter)

    def __call__(self, i: int, t: float) -> int:
        """The expression of agent ``i`` at simulated time ``t`` (call with increasing ``t``)."""
        if t >= self.next_switch[i]:
            choices = [e for e in range(len(EXPRESSIONS)) if e != self.current[i]]
            self.current[i] = self.rng.choice(choices)
            self.next_switch[i] = t + self._interval()
        return int(self.current[i])


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo", help="record a short free-play demo to a Rerun .rrd file",
        description="Infants face to face in free play with smooth random movements and "
                    "changing facial expressions, recorded to a Rerun .rrd file.")
    parser.add_argument("--record", metavar="FILE.rrd", default=DEFAULT_RECORDING,
                        help=f"where to write the recording (default: {DEFAULT_RECORDING}; "
                             "the folder is created)")
    parser.add_argument("--seconds", type=float, default=10.0,
                        help="simulated seconds to run (default: 10)")
    parser.add_argument("--n-agents", type=int, default=2, help="number of infants (default: 2)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default: 0)")
    parser.set_defaults(func=run)
    return parser


def _open_hint(path: Path) -> str:
    return f"  rerun {path}\n  mimo-social replay {path}"


def run(args: argparse.Namespace) -> int:
    from ..envs import free_play_v0
    from ..recording.recorder import Recorder

    if not args.seconds > 0:
        raise SystemExit(f"mimo-social demo: --seconds {args.seconds}: must be positive")
    if not 1 <= args.n_agents <= 8:
        raise SystemExit(f"mimo-social demo: --n-agents {args.n_agents}: allowed 1 to 8")
    path = Path(args.record)
    env = free_play_v0.parallel_env(n_agents=args.n_agents, max_steps=10**9)
    steps = max(1, round(args.seconds / env.dt))
    rng = np.random.default_rng(args.seed)
    env.reset(seed=args.seed)
    with_face = {a: isinstance(env.action_space(a), spaces.Dict) for a in env.possible_agents}
    motor_spaces = {a: env.action_space(a)["motors"] if with_face[a] else env.action_space(a)
                    for a in env.possible_agents}
    noise = {a: SmoothNoise(motor_spaces[a].shape[0], env.dt, rng) for a in env.possible_agents}
    faces = ExpressionSchedule(len(env.possible_agents), rng)
    done = 0
    stopped = None
    with Recorder(env, path, recording_name=f"mimo-social demo (seed {args.seed})") as rec:
        rec.log_reset()
        for k in tqdm(range(steps), desc="demo", unit="step"):
            t = k * env.dt
            actions = {}
            for i, a in enumerate(env.possible_agents):
                if a not in env.agents:
                    continue
                u = noise[a]()
                actions[a] = {"motors": u, "expression": faces(i, t)} if with_face[a] else u
            _, rewards, _, _, infos = env.step(actions)
            rec.log_step(actions, rewards)
            done = k + 1
            if not env.agents:
                stopped = next((info.get("instability") for info in infos.values()
                                if info.get("instability")), "every agent is done")
                break
    env.close()
    size = path.stat().st_size
    print(f"Recorded {done * env.dt:.2f} s of simulated time ({done} steps, {args.n_agents} "
          f"infant{'s' if args.n_agents != 1 else ''}) to {path} ({size / 1e6:.1f} MB).")
    if stopped:
        print(f"The episode ended early: {stopped}")
    print("Open it with:\n" + _open_hint(path))
    return 0
