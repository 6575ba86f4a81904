"""What MuJoCo's native ``touch`` sensor would cost as a skin, and what it senses.

A free box (0.2 x 0.1 x 0.1 m, 2 kg) rests on a plane; its faces carry ``n`` sphere sites of
1 cm radius (placed on a grid just inside the faces, as skin points sit on a body's surface),
each with a ``<touch>`` sensor. For each ``n`` the script prints the CPU microseconds of one
``mj_step`` with and without the sensors (``time.thread_time`` over ``--steps`` steps, after
the box settled) and the summed normal force the sensors report against the box's weight.
docs/senses.md cites it:

    python3 scripts/native_touch_cost.py --sites 1000,6000,48000
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

SIZE = np.array([0.1, 0.05, 0.05])   # half sizes of the box
MASS = 2.0


def _face_points(n: int) -> np.ndarray:
    """About ``n`` points on a grid over the box's six faces, 1 mm inside them."""
    area = 8 * (SIZE[0] * SIZE[1] + SIZE[1] * SIZE[2] + SIZE[0] * SIZE[2])
    step = np.sqrt(area / n)
    pts = []
    for axis in range(3):
        u, v = [a for a in range(3) if a != axis]
        gu = np.arange(-SIZE[u] + step / 2, SIZE[u], step)
        gv = np.arange(-SIZE[v] + step / 2, SIZE[v], step)
        uu, vv = np.meshgrid(gu, gv)
        for sign in (-1.0, 1.0):
            p = np.zeros((uu.size, 3))
            p[:, u], p[:, v] = uu.ravel(), vv.ravel()
            p[:, axis] = sign * (SIZE[axis] - 0.001)
            pts.append(p)
    return np.concatenate(pts)


def model(n_sites: int, sensors: bool) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[1, 1, 0.1])
    box = spec.worldbody.add_body(name="box", pos=[0, 0, SIZE[2] + 0.001])
    box.add_freejoint()
    box.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=SIZE, mass=MASS)
    for k, p in enumerate(_face_points(n_sites)):
        box.add_site(name=f"s{k}", pos=p, size=[0.01, 0, 0])
        if sensors:
            spec.add_sensor(type=mujoco.mjtSensor.mjSENS_TOUCH, objtype=mujoco.mjtObj.mjOBJ_SITE,
                            objname=f"s{k}")
    return spec.compile()


def measure(n_sites: int, sensors: bool, steps: int) -> tuple[float, float, int]:
    """CPU µs per mj_step, the summed sensed force (N), the number of sites."""
    m = model(n_sites, sensors)
    d = mujoco.MjData(m)
    for _ in range(500):                 # settle on the plane
        mujoco.mj_step(m, d)
    t0 = time.thread_time()
    for _ in range(steps):
        mujoco.mj_step(m, d)
    us = (time.thread_time() - t0) / steps * 1e6
    return us, float(d.sensordata.sum()) if sensors else 0.0, m.nsite


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sites", default="1000,6000,48000", help="site counts, comma-separated")
    p.add_argument("--steps", type=int, default=2000, help="timed steps per configuration")
    args = p.parse_args(argv)
    weight = MASS * 9.81
    print("| sites | µs / mj_step without sensors | with touch sensors | ns per sensor | "
          "sensed N (weight %.1f N) |" % weight)
    print("|---|---|---|---|---|")
    for n in (int(x) for x in args.sites.split(",")):
        bare, _, _ = measure(n, False, args.steps)
        with_s, sensed, sites = measure(n, True, args.steps)
        print(f"| {sites} | {bare:.0f} | {with_s:.0f} | {(with_s - bare) / sites * 1e3:.0f} | "
              f"{sensed:.2f} |")


if __name__ == "__main__":
    main()
