"""What the social touch toucher can do without seeing the partner: the scripted plan made for
the partner it cannot see.

The toucher observes its own arm (proprioception, skin) and the instruction, nothing of the
partner; the task draws the distance between the two (``distance_spread``) and the partner's
arm posture (``partner_spread``) every episode. ``SocialTouchController`` plans on the world
itself, so it sees both. Here, per episode, the controller plans on a twin episode (the same
seed) in which the unseen draws are left at their means (the spread option set to 0; the
toucher's own start, drawn from the same seed, is the episode's), and its waypoints are then
played in the real episode with its own PD law, which reads only the toucher's joints. Rows:

* ``scripted``: planned on the real episode (the catalogue controller);
* ``unseen distance``: planned with ``distance_spread`` 0;
* ``unseen arms``: planned with ``partner_spread`` 0;
* ``unseen both``: both at 0: what the toucher's observation allows this plan;
* ``blind 6``, ``blind 12``: ``SocialTouchController(twins=K)``, the plan chosen over K twin
  worlds with the partner's arms drawn again (the distance kept: the toucher senses it through
  its eyes' vergence);
* ``blind 6, mean start``: the same with ``twin_start="mean"`` (one plan per target and
  distance, whatever the toucher's start).

docs/baselines.md (social touch) cites:

    python3 scripts/social_touch_unseen_partner.py --episodes 60 --seed 1000
    python3 scripts/social_touch_unseen_partner.py --episodes 60 --seed 1000 \
        --rows "blind 6" "blind 12" "blind 6, mean start"
    python3 scripts/social_touch_unseen_partner.py --episodes 60 --seed 1000 --positional \
        --rows scripted "blind 6"
"""

from __future__ import annotations

import argparse
from collections import defaultdict

import numpy as np
from tqdm import tqdm

from mimo_social.envs import social_touch_v0
from mimo_social.tasks.social_touch.controller import SocialTouchController

ROWS = {"scripted": None, "unseen distance": {"distance_spread": 0.0},
        "unseen arms": {"partner_spread": 0.0},
        "unseen both": {"distance_spread": 0.0, "partner_spread": 0.0}}
#: rows of the blind plan: the controller's own keyword arguments
BLIND = {"blind 6": {"twins": 6}, "blind 12": {"twins": 12},
         "blind 6, mean start": {"twins": 6, "twin_start": "mean"}}
AGENT = "infant_0"


def play(real, twin, seed: int, blind=None) -> tuple[str, bool, float]:
    """One episode: (target part, success, return)."""
    controller = SocialTouchController(**(blind or {}))
    obs, _ = real.reset(seed=seed)
    rng = np.random.default_rng(seed)
    if twin is None:
        controller.reset(real.env, AGENT, rng)
    else:
        twin.reset(seed=seed)
        controller.reset(twin.env, AGENT, rng)       # the plan for the partner at its means
        waypoints = controller.waypoints
        controller.bind(real.env, AGENT)              # its motors and gains in the real world
        controller.follow(waypoints)
    total, done, info = 0.0, False, {}
    while not done:
        obs, rewards, term, trunc, infos = real.step(
            {AGENT: controller.act(real.env, AGENT, obs[AGENT])})
        total += float(rewards[AGENT])
        info, done = infos[AGENT], term[AGENT] or trunc[AGENT]
    return real.env.task.target, bool(info.get("is_success")), total


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--episodes", type=int, default=60)
    p.add_argument("--seed", type=int, default=1000)
    p.add_argument("--rows", nargs="+", default=list(ROWS), choices=list(ROWS) + list(BLIND))
    p.add_argument("--positional", action="store_true",
                   help="the toucher's arm with positional actuation (the controller's targets)")
    args = p.parse_args()
    per_agent = [{"actuation": "positional"}, {}] if args.positional else None
    real = social_touch_v0.scripted_env(per_agent=per_agent)
    print(f"social_touch: {args.episodes} episodes per row, seeds {args.seed}.."
          f"{args.seed + args.episodes - 1}")
    for row in args.rows:
        options = ROWS.get(row)
        twin = None if options is None else social_touch_v0.scripted_env(
            task_options=options, per_agent=per_agent)
        per_target, returns = defaultdict(list), []
        for k in tqdm(range(args.episodes), desc=row, leave=False):
            target, ok, ret = play(real, twin, args.seed + k, BLIND.get(row))
            per_target[target].append(ok)
            returns.append(ret)
        wins = sum(sum(v) for v in per_target.values())
        parts = ", ".join(f"{t} {sum(v)}/{len(v)}" for t, v in sorted(per_target.items()))
        print(f"{row:16s} success {wins}/{args.episodes} ({100 * wins / args.episodes:.0f} %), "
              f"return {np.mean(returns):.1f} +- {np.std(returns):.1f}; {parts}")
        if twin is not None:
            twin.close()
    real.close()


if __name__ == "__main__":
    main()
