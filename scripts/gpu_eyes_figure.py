"""docs/gpu_eyes.png: what an infant's eye sees of its partner's face, on the CPU (MuJoCo's
OpenGL renderer, top row) and on the Warp backend (MuJoCo Warp's batch renderer, bottom row),
for four expressions of the partner; 96 x 96 pixels, 32-degree eyes on the partner's face.

    python3 scripts/gpu_eyes_figure.py [--out docs/gpu_eyes.png]

Runs on Warp's CPU device (no GPU needed): one batched env of four worlds, the partner showing
expression w in world w, beside a CPU env per expression.
"""

from __future__ import annotations

import argparse

import numpy as np

from mimo_social.envs import high_five_v0
from mimo_social.expressions.faces import EXPRESSIONS
from mimo_social.gpu import BatchedEnv
from mimo_social.render.png import write_png

SHOWN = ("neutral", "happy", "surprised", "angry")
EYES = {"width": 96, "height": 96, "field_of_view": 32}


def cpu_view(expression: int) -> np.ndarray:
    env = high_five_v0.parallel_env(vision=EYES)
    env.reset(seed=0)
    n = {a: env.action_space(a)["motors"].shape[0] for a in env.possible_agents}
    for _ in range(2):
        obs, *_ = env.step({a: {"motors": np.zeros(n[a], np.float32),
                                "expression": expression if a == "infant_1" else 0}
                            for a in env.possible_agents})
    return obs["infant_0"]["eye_left"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="docs/gpu_eyes.png")
    args = parser.parse_args()
    ids = np.array([EXPRESSIONS.index(e) for e in SHOWN])
    b = BatchedEnv(high_five_v0.parallel_env(vision=EYES), len(ids), device="cpu", seed=0)
    b.reset()
    zero = {a: np.zeros((len(ids), b.n_controls(a)), np.float32) for a in b.agents}
    for _ in range(2):
        obs, _ = b.step(zero, expressions={"infant_1": ids})
    device = obs["infant_0"]["eye_left"].numpy()
    gap = np.full((96, 4, 3), 255, np.uint8)
    rows = []
    for images in ([cpu_view(int(e)) for e in ids], list(device)):
        row = []
        for img in images:
            row += [img, gap]
        rows.append(np.concatenate(row[:-1], axis=1))
    sheet = np.concatenate([rows[0], np.full((4, rows[0].shape[1], 3), 255, np.uint8), rows[1]])
    write_png(args.out, np.kron(sheet, np.ones((2, 2, 1), np.uint8)))
    print(f"wrote {args.out}: top the CPU's eye, bottom the device's; {', '.join(SHOWN)}")


if __name__ == "__main__":
    main()
