"""Pilot (issue 30, twelfth session): is the partner's head turn visible to a learner that looks
at a toy? How many pixels of the learner's eyes a turn of the partner's head changes.

For each of ``--seeds`` layouts and each toy, the learner's head and eyes are set to fixate the
toy (``LookAt``: head turned fully, the eyes correcting), the partner's head faces the learner
(the task's start), and both eyes are rendered; then the partner's head swivel is turned by each
of ``--degrees`` (both ways) and the eyes rendered again. Printed per fovea and angle: the share
of the two eyes' pixels that changed (any channel by more than ``--threshold`` of 255), mean and
range over the layouts, toys and both directions; and the same with the learner fixating the
partner's face; per ``--field-of-view`` (the learner's eyes, degrees) and ``--fovea``.
Arguments: README.md beside it.
"""
import argparse

import mujoco
import numpy as np

from mimo_social.core.kinematics import LookAt
from mimo_social.senses.vision import eye_images, render_now
from mimo_social.train.envs import make_env


def changed(a: dict, b: dict, threshold: int) -> float:
    diff = [np.abs(a[k].astype(int) - b[k].astype(int)).max(axis=-1) > threshold
            for k in ("eye_left", "eye_right")]
    return float(np.mean(diff))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--seeds", type=int, default=10)
    p.add_argument("--degrees", type=float, nargs="+", default=[3.0, 10.0, 20.0])
    p.add_argument("--fovea", type=float, nargs="+", default=[1.0, 3.0])
    p.add_argument("--field-of-view", type=float, nargs="+", default=[60.0],
                   help="the learner's eyes' vertical field of view, degrees")
    p.add_argument("--size", type=int, default=96)
    p.add_argument("--threshold", type=int, default=16)
    a = p.parse_args(argv)
    for fov, fovea in [(v, f) for v in a.field_of_view for f in a.fovea]:
        vision = {"width": a.size, "height": a.size, "fovea": fovea, "field_of_view": fov}
        env = make_env("joint_attention", per_agent=[{"vision": vision}, {}])
        rows = {}
        for seed in range(a.seeds):
            env.reset(seed=1000 + seed)
            core = env.unwrapped.parallel.unwrapped
            w = core.world
            m, d = w.model, w.data
            swivel = m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT,
                                                     "infant_1/head_swivel")]
            look = LookAt(w, 0)
            start = d.qpos.copy()
            targets = [("toy", "body", int(t)) for t in core.task.toy_bodies]
            targets.append(("face", "site", int(w.agents[1].head_site)))
            for what, kind, obj in targets:
                d.qpos[:] = start
                mujoco.mj_forward(m, d)
                d.qpos[look.qpos] = look(m, d, kind, obj)
                mujoco.mj_forward(m, d)
                render_now(core, [0])
                before = eye_images(core, 0)
                for deg in a.degrees:
                    for sign in (-1, 1):
                        d.qpos[swivel] = start[swivel] + sign * np.deg2rad(deg)
                        mujoco.mj_forward(m, d)
                        render_now(core, [0])
                        rows.setdefault((what, deg), []).append(
                            changed(before, eye_images(core, 0), a.threshold))
                    d.qpos[swivel] = start[swivel]
        env.close()
        for (what, deg), v in sorted(rows.items()):
            v = np.array(v) * 100
            print(f"field of view {fov:g} deg, fovea {fovea:g}, {a.size}x{a.size}, learner on "
                  f"the {what}, partner's head turned {deg:g} deg: {v.mean():.2f} % of the eyes' pixels changed (min "
                  f"{v.min():.2f}, max {v.max():.2f}; {len(v)} renders)", flush=True)


if __name__ == "__main__":
    main()
