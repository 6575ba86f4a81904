"""How well does joint attention go on what face perception gives? (issue 30)

The follower :class:`~mimo_social.tasks.joint_attention.sensed.SensedFollowController` reads the
partner's gaze only on the steps its ``faces`` sense sees the partner's face, keeps the toy read
while the face is out of view and looks back after ``--look-back-s``: the ceiling of a learner
with that sense and a memory (the recipe's demonstrator, ``bc_kwargs`` ``demonstrator =
"sensed"``). Per field of view and look-back time it prints the success rate, the share of
target steps on target per episode (the task's success needs 0.6) and the share of steps the
face was seen, on seeds 1000.. (the task's baselines' seeds); the learner's eyes are off.

    OMP_NUM_THREADS=1 python3 scripts/joint_attention_sensed.py --episodes 20 \\
        --field-of-view 120 160 --look-back-s 0.3 0.5 1 2
"""

from __future__ import annotations

import argparse

import numpy as np

from mimo_social.core.episodes import run_episodes
from mimo_social.envs import joint_attention_v0
from mimo_social.tasks.joint_attention import SensedFollowController


def measure(fov: float, look_back_s: float, episodes: int, seed: int) -> dict:
    env = joint_attention_v0.scripted_env(per_agent=[
        {"vision": False, "faces": {"field_of_view": fov}}, {}])
    seen = []
    eps = run_episodes(env, {"infant_0": SensedFollowController(look_back_s=look_back_s)},
                       episodes, seed,
                       on_step=lambda e, o, r, te, tr, i: seen.append(o["infant_0"]["faces"][0]))
    last = [e.last_infos["infant_0"] for e in eps]
    return {"success": float(np.mean([i["is_success"] for i in last])),
            "on_target": [round(float(i["on_target_fraction"]), 2) for i in last],
            "seen": float(np.mean(seen)),
            "return": float(np.mean([e.returns["infant_0"] for e in eps]))}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--episodes", type=int, default=20)
    p.add_argument("--seed", type=int, default=1000)
    p.add_argument("--field-of-view", type=float, nargs="+", default=[160.0])
    p.add_argument("--look-back-s", type=float, nargs="+", default=[0.5])
    a = p.parse_args(argv)
    print("| field of view | look back (s) | success | on target, least / mean | face seen | "
          "return |")
    print("|---|---|---|---|---|---|")
    for fov in a.field_of_view:
        for lb in a.look_back_s:
            r = measure(fov, lb, a.episodes, a.seed)
            print(f"| {fov:g} | {lb:g} | {r['success']:.0%} | {min(r['on_target']):.2f} / "
                  f"{np.mean(r['on_target']):.2f} | {r['seen']:.2f} | {r['return']:.1f} |",
                  flush=True)


if __name__ == "__main__":
    main()
