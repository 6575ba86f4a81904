"""How much a clone's error costs a task's scripted controller: its success with an action error.

A cloned policy is its demonstrator plus an error. This script adds one to the demonstrator:
for each controller setting and error size, the task's catalogue controller (made with the
setting, as ``bc_kwargs`` ``controller`` makes it for a warm start) plays ``--episodes``
episodes (seeds ``--seed`` onwards) on the learner's flat env, every action it takes shifted by
an error drawn once per episode (normal, sd ``--error``, per action dimension; a systematic
error, as a clone's is) and by fresh noise each step (sd ``--noise``), then clipped to the
action box. It prints success and mean return per row. docs/training.md (``controller``) cites:

    python3 scripts/demonstrator_tolerance.py social_touch --set '{}' '{"frequency": 6.0}'
    python3 scripts/demonstrator_tolerance.py selfbody --set '{}' '{"frequency": 6.0}'
"""

from __future__ import annotations

import argparse
import json

import numpy as np
from tqdm import tqdm

from mimo_social.core.episodes import run_episode
from mimo_social.train.demonstrations import Demonstrator, demonstrator
from mimo_social.train.envs import make_env


class ErringDemonstrator(Demonstrator):
    """The controller's action plus a per-episode error and per-step noise, clipped."""

    def __init__(self, controller, env, error: float, noise: float, seed: int):
        super().__init__(controller, env)
        self.error, self.noise = error, noise
        self.rng = np.random.default_rng(seed)
        self.shift = np.zeros(env.action_space.shape)

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        self.shift = self.rng.normal(0.0, self.error, self.shift.shape)

    def act(self, env, agent, obs):
        a = super().act(env, agent, obs) + self.shift
        a = a + self.rng.normal(0.0, self.noise, a.shape)
        return np.clip(a, self.space.low, self.space.high).astype(np.float32)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("task", help="a task with a scripted controller (a one-agent env, or the "
                   "scripted env of a social task)")
    p.add_argument("--set", nargs="+", default=["{}"], metavar="JSON",
                   help="controller settings, one JSON dict per row group (default: '{}')")
    p.add_argument("--error", nargs="+", type=float, default=[0.0, 0.03, 0.06],
                   help="sd of the per-episode action error (default: 0 0.03 0.06)")
    p.add_argument("--noise", type=float, default=0.0, help="sd of per-step noise (0)")
    p.add_argument("--episodes", type=int, default=30)
    p.add_argument("--seed", type=int, default=1000)
    args = p.parse_args()
    env = make_env(args.task, flat=True)
    print(f"{args.task}: {args.episodes} episodes per row, seeds {args.seed}.."
          f"{args.seed + args.episodes - 1}, per-step noise sd {args.noise}\n")
    print("| controller settings | error sd | success | return |\n|---|---|---|---|")
    try:
        for given in args.set:
            settings = json.loads(given)
            for error in args.error:
                rec = ErringDemonstrator(demonstrator(args.task, {"controller": settings}), env,
                                         error, args.noise, args.seed)
                ok, ret = [], []
                for s in tqdm(range(args.seed, args.seed + args.episodes), leave=False,
                              desc=f"{given} error {error}"):
                    ep = run_episode(env, rec, s, on_step=rec.on_step)
                    agent = next(iter(ep.returns))
                    ok.append(bool(ep.success(agent)))
                    ret.append(float(ep.returns[agent]))
                print(f"| {given} | {error} | {np.mean(ok):.0%} ({sum(ok)}/{len(ok)}) | "
                      f"{np.mean(ret):.1f} |", flush=True)
    finally:
        env.close()


if __name__ == "__main__":
    main()
