"""One scene through an infant's eye at several ages: the acuity blur (``vision={"acuity": "age"}``)
of 0, 3, 6, 12 and 24 months.

Two infants face to face, a ball and a cube held up between them, infant_1 smiling (the scene of
``examples/anaglyph.py``). infant_0's left eye is rendered once, sharp, at ``--size`` pixels
(default 2048, where a pixel is 1/31 degree on the line of sight, so even 12 months' 11 cycles
per degree is below the image's Nyquist frequency and blurs), and each age's blur is the filter
the env applies (:class:`mimo_social.senses.acuity.AcuityBlur` of :func:`acuity_at`). Top row:
the whole 60 degree view, shrunk; bottom row: the centre at one image pixel per screen pixel.

    python examples/acuity_by_age.py [--size 2048] [--out docs/acuity_by_age.png]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import mimo_social  # noqa: F401 (chooses the headless OpenGL backend before mujoco loads)
import mujoco
import numpy as np

from mimo_social.envs import free_play_v0
from mimo_social.senses.acuity import AcuityBlur, acuity_at, acuity_table
from mimo_social.senses.vision import eye_images, render_now

AGES = (0, 3, 6, 12, 24)


def scene_image(size: int) -> np.ndarray:
    """infant_0's sharp left-eye image of the face-to-face scene, ``size`` pixels square."""
    env = free_play_v0.parallel_env(
        n_agents=2, task_options={"props": True},
        per_agent=[{"vision": {"width": size, "height": size}}, {"vision": False}])
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    env.world.set_expression(1, 1)
    right_cam, left_cam = env.world.agents[0].eye_cameras
    eyes = (d.cam_xpos[right_cam] + d.cam_xpos[left_cam]) / 2
    R = d.cam_xmat[left_cam].reshape(3, 3)           # columns: right, up, backwards
    for prop, dist, side in (("ball", 0.25, -0.035), ("cube", 0.4, 0.06)):
        adr = env.world.prop_qpos[prop]
        d.qpos[adr:adr + 3] = eyes - dist * R[:, 2] - 0.05 * R[:, 1] + side * R[:, 0]
        d.qpos[adr + 3:adr + 7] = (0.92, 0.2, 0.3, 0.1)
    mujoco.mj_forward(m, d)
    render_now(env)
    img = eye_images(env, "infant_0")["eye_left"]
    env.close()
    return img


def shrink(img: np.ndarray, factor: int) -> np.ndarray:
    """Mean of each ``factor`` x ``factor`` block."""
    h, w, c = img.shape
    h, w = h // factor * factor, w // factor * factor
    blocks = img[:h, :w].reshape(h // factor, factor, w // factor, factor, c)
    return blocks.mean(axis=(1, 3)).astype(np.uint8)


def panels(img: np.ndarray, ages=AGES, crop: int = 384, view: int = 384):
    """Per age: (label, whole view shrunk to about ``view`` pixels, centre ``crop`` at 1:1)."""
    h, w, _ = img.shape
    out = []
    for age in ages:
        cutoff = acuity_at(age)
        if cutoff is None:
            blurred = img
            data = dict(acuity_table())[float(age)] if float(age) in dict(acuity_table()) else None
            label = f"{age} months: no blur" + (f"\n(data: {data:g} c/deg)" if data else "")
        else:
            blur = AcuityBlur(cutoff, h, w)
            blurred = blur(img)
            label = f"{age} months: {cutoff:.2f} c/deg\n(sigma {blur.sigma_px:.1f} px of {h})"
        top, left = (h - crop) // 2, (w - crop) // 2
        out.append((label, shrink(blurred, max(1, h // view)),
                    blurred[top:top + crop, left:left + crop]))
    return out


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--size", type=int, default=2048, help="eye image width and height (px)")
    p.add_argument("--crop", type=int, default=384, help="centre crop shown 1:1 (px)")
    p.add_argument("--out", default="docs/acuity_by_age.png", help="PNG to write")
    args = p.parse_args(argv)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    img = scene_image(args.size)
    rows = panels(img, crop=args.crop)
    dpi = 100
    fig, axes = plt.subplots(2, len(rows), figsize=(len(rows) * args.crop / dpi,
                                                    2 * args.crop / dpi + 0.9), dpi=dpi)
    focal = (args.size / 2) / np.tan(np.radians(60) / 2)       # pixels
    crop_deg = 2 * np.degrees(np.arctan(args.crop / 2 / focal))
    for col, (label, view, centre) in enumerate(rows):
        axes[0, col].imshow(view, interpolation="none")
        axes[0, col].set_title(label, fontsize=9)
        axes[1, col].imshow(centre, interpolation="none")
        for ax in axes[:, col]:
            ax.set_xticks([]), ax.set_yticks([])
    axes[0, 0].set_ylabel("whole view (60 deg)", fontsize=9)
    axes[1, 0].set_ylabel(f"centre, 1:1 (about {crop_deg:.0f} deg)", fontsize=9)
    fig.suptitle(f"infant_0's left eye, {args.size}x{args.size} px, acuity by age "
                 "(Salomao & Ventura 1995, binocular Teller cards)", fontsize=10)
    fig.tight_layout(pad=0.3, rect=(0, 0, 1, 0.96))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=dpi)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
