"""Pictures for people that need a whole scene: the skin of a hand holding a ball (paper Fig. 5b).

``mimo-social figure skin-hand-ball OUT.png`` draws it (:mod:`mimo_social.cli.figure`).
"""

from __future__ import annotations

import mujoco
import numpy as np

from .body.postures import POSTURES
from .body.tables import load_body
from .core.env import MimoParallelEnv
from .body.joint_groups import held_posture
from .core.world import AgentSetup, Prop
from .tasks.free_play import FreePlay

__all__ = ["GAZE_TURNS", "HOLD_BALL_ARM", "THREE_SIZES", "eye_turn", "free_camera_pixel",
           "geom_triangles", "hand_ball_scene", "save_expressions_png", "save_hand_ball_png",
           "save_partner_gaze_png", "save_three_sizes_png", "save_validation_body_png",
           "FIGURES"]


# the right arm held forward, palm up, the hand tilted 12 degrees towards the fingertips
# (degrees; found by minimising the palm's deviation from that pose over the arm's joints)
HOLD_BALL_ARM = {"right_shoulder_horizontal": 95.7, "right_shoulder_abduction": 24.3,
                 "right_shoulder_rotation": -89.7, "right_elbow": -84.2,
                 "right_wrist_rotation": -76.9, "right_wrist_flexion": 34.7,
                 "right_wrist_ulnar": 12.3}


def hand_ball_scene(steps: int = 100, touch: dict | bool = True, ball_radius: float = 0.025,
                    grip: float = -0.1, along: float = 0.015):
    """A sitting infant holding a ball in its upturned right hand, the mitten closing over it.

    Every joint but the mitten fingers is held (the arm forward, palm up: :data:`HOLD_BALL_ARM`);
    the infant sits on the floor as one rigid body (so MuJoCo's parent-child contact filter
    keeps the fingers from colliding with the palm). After the infant has settled, the ball
    (``ball_radius``, 0.1 kg) is laid on the palm, ``along`` m from its centre towards the
    fingers, and the mitten closes on it with action ``grip`` for ``steps`` control steps (the
    ball then rests in the cup of palm, fingers and wrist). Returns the env.
    """
    class HoldBall(FreePlay):
        def setup(self, i, config):
            angles = dict(POSTURES["sitting"]["joints"])
            angles.update(HOLD_BALL_ARM)
            frozen = held_posture(load_body(config.hands), keep=("right_fingers",), angles=angles)
            return AgentSetup(config, position=(0.0, 0.0), facing=(1.0, 0.0), frozen=frozen,
                              actuated=("right_fingers",))

        def props(self):
            return [Prop("ball", "sphere", (ball_radius,), (0.5, 0.5, ball_radius), 0.1,
                         (0.9, 0.25, 0.2, 1.0))]

    env = MimoParallelEnv(HoldBall(1), touch=touch, posture="sitting", expressions=False,
                          proprioception=False)
    env.reset(seed=0)
    w = env.world
    m, d = w.model, w.data
    a = w.agents[0]
    name = env.agents[0]
    rest = {name: np.zeros(1, np.float32)}
    for _ in range(50):                                 # let the sitting infant settle
        env.step(rest)
    hand = m.site_bodyid[a.palm_sites[0]]
    palm_normal = -d.xmat[hand].reshape(3, 3)[:, 1]   # the palm side of the right mitten
    q = w.prop_qpos["ball"]
    along_hand = d.xmat[hand].reshape(3, 3)[:, 2]
    d.qpos[q:q + 3] = (d.site_xpos[a.palm_sites[0]] + (0.0105 + ball_radius) * palm_normal
                       + along * along_hand)
    d.qpos[q + 3:q + 7] = (1.0, 0.0, 0.0, 0.0)
    mujoco.mj_forward(m, d)
    hold = {name: np.array([grip], np.float32)}
    for _ in range(steps):
        env.step(hold)
    return env


def geom_triangles(model: mujoco.MjModel, data: mujoco.MjData, g: int, n: int = 16) -> np.ndarray:
    """The surface of geom ``g`` where it is now, as triangles (T, 3, 3) in world coordinates:
    boxes, spheres, ellipsoids, capsules and cylinders (other types: none)."""
    t, size = int(model.geom_type[g]), model.geom_size[g]
    G = mujoco.mjtGeom
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n + 1), np.linspace(0, np.pi, n // 2 + 1))
    if t == G.mjGEOM_BOX:
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
        quads = [(0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4),
                 (1, 3, 7, 5)]
        pts = corners * size
        tris = np.array([pts[[a, b, c]] for q in quads for a, b, c in ((q[0], q[1], q[2]),
                                                                        (q[0], q[2], q[3]))])
    elif t in (G.mjGEOM_SPHERE, G.mjGEOM_ELLIPSOID, G.mjGEOM_CAPSULE):
        radii = (np.full(3, size[0]) if t != G.mjGEOM_ELLIPSOID else size)
        grid = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], -1) * radii
        if t == G.mjGEOM_CAPSULE:                 # two half spheres apart by the length
            grid[..., 2] += np.sign(grid[..., 2]) * size[1]
        tris = _grid_triangles(grid)
    elif t == G.mjGEOM_CYLINDER:
        z = np.array([-size[1], -size[1], size[1], size[1]])[:, None]
        r = np.array([0.0, size[0], size[0], 0.0])[:, None]
        uu = np.linspace(0, 2 * np.pi, n + 1)[None, :]
        tris = _grid_triangles(np.stack([r * np.cos(uu), r * np.sin(uu), z + 0 * uu], -1))
    else:
        return np.zeros((0, 3, 3))
    R = data.geom_xmat[g].reshape(3, 3)
    return tris @ R.T + data.geom_xpos[g]


def _grid_triangles(grid: np.ndarray) -> np.ndarray:
    """Two triangles per cell of a grid of points (rows x columns x 3)."""
    a, b = grid[:-1, :-1], grid[:-1, 1:]
    c, d = grid[1:, 1:], grid[1:, :-1]
    return np.concatenate([np.stack([a, b, c], -2).reshape(-1, 3, 3),
                           np.stack([a, c, d], -2).reshape(-1, 3, 3)])


def save_hand_ball_png(path, steps: int = 100) -> str:
    """The paper's Fig. 5b: the skin of a hand holding a ball, coloured by force, as a PNG: the
    hand and forearm drawn as translucent skin-coloured solids (the geoms the skin covers), the
    skin points on them (grey without force; coloured and sized by the force), the ball's
    outline, each labelled."""
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    env = hand_ball_scene(steps)
    parts = ["right_lower_arm", "right_hand", "right_fingers"]
    w = env.world
    m, d = w.model, w.data
    view = getattr(env, "unwrapped", env).system("touch").view(0)
    points = np.concatenate([view[k]["points"] for k in parts])
    force = np.concatenate([view[k]["normal_force"] for k in parts])
    ball = d.xpos[w.prop_bodies["ball"]]
    radius = float(m.geom_size[m.geom("ball").id, 0])
    side = d.xmat[m.site_bodyid[w.agents[0].palm_sites[0]]].reshape(3, 3)[:, 0]
    fig = plt.figure(figsize=(8.0, 6.5), dpi=120)
    ax = fig.add_subplot(projection="3d")
    ax.computed_zorder = False        # drawn in order: the solids, then the skin points on them
    for part, colour in zip(parts, ("#e8c4a8", "#f0c8a8", "#f4d0b0")):
        body = m.body(f"{w.names[0]}/{part}").id
        tris = np.concatenate([geom_triangles(m, d, g) for g in range(m.ngeom)
                               if m.geom_bodyid[g] == body])
        ax.add_collection3d(Poly3DCollection(tris, facecolor=colour, edgecolor="none",
                                             alpha=0.3))
        centre = tris.reshape(-1, 3).mean(0)
        ax.text(*centre, part.replace("right_", "right ").replace("_", " "), fontsize=8,
                color="0.25", zorder=10)
    on = force > 1e-9
    ax.scatter(*points[~on].T, s=3, c="0.5", alpha=0.45, linewidths=0, label="skin point")
    if on.any():
        order = np.argsort(force[on])
        f = force[on][order]
        sc = ax.scatter(*points[on][order].T, s=12 + 150 * f / f.max(), c=f, cmap="autumn_r",
                        vmin=0.0, edgecolors="darkred", linewidths=0.4, depthshade=False,
                        label="skin point sensing a force")
        fig.colorbar(sc, ax=ax, shrink=0.6, pad=0.1, label="normal force on the point (N)")
    uu, vv = np.mgrid[0:2 * np.pi:25j, 0:np.pi:13j]
    ax.plot_wireframe(ball[0] + radius * np.cos(uu) * np.sin(vv),
                      ball[1] + radius * np.sin(uu) * np.sin(vv),
                      ball[2] + radius * np.cos(vv), color="tab:blue", alpha=0.3,
                      linewidth=0.6, label=f"ball ({100 * radius:.1f} cm radius, 0.1 kg)")
    lo, hi = points.min(0), points.max(0)
    centre, r = (lo + hi) / 2, (hi - lo).max() / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - r, c + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=35.0, azim=float(np.degrees(np.arctan2(side[1], side[0]))) + 35.0)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.tick_params(labelsize=7)
    ax.legend(loc="upper left", fontsize=8, markerscale=1.5)
    ax.set_title(f"An 18-month-old's right hand holding a ball\n{force.sum():.2f} N normal "
                 f"force sensed by {int(on.sum())} of {len(points)} skin points", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    env.close()
    return str(path)


def _pyplot():
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    return plt


def _face_camera(world, i: int, distance: float) -> mujoco.MjvCamera:
    """A free camera ``distance`` m in front of agent ``i``'s face, looking at it."""
    site = world.agents[i].head_site
    forward = world.data.site_xmat[site].reshape(3, 3)[:, 0]       # where the face looks
    cam = mujoco.MjvCamera()
    cam.lookat[:] = world.data.site_xpos[site]
    cam.distance = distance
    cam.azimuth = float(np.degrees(np.arctan2(-forward[1], -forward[0])))
    cam.elevation = float(np.degrees(np.arcsin(np.clip(-forward[2], -1, 1))))
    return cam


def _bare(ax, title: str | None = None, ylabel: str | None = None) -> None:
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_visible(False)
    if title:
        ax.set_title(title, fontsize=9)
    if ylabel:
        ax.set_ylabel(ylabel, fontsize=9)


#: the partner's eye turns of :func:`save_partner_gaze_png`: (label, horizontal, vertical motor)
GAZE_TURNS = (("ahead", 0.0, 0.0), ("to its left", 1.0, 0.0), ("to its right", -1.0, 0.0),
              ("up", 0.0, 1.0), ("down", 0.0, -1.0))


def eye_turn(n_motors: int, left: float, up: float) -> np.ndarray:
    """A head agent's motor action that turns both eyes the same way, ``left`` (to its left, -1:
    to its right) and ``up`` (-1: down), in [-1, 1], every other motor at 0. A horizontal eye
    motor turns its eye outward at +1 (the right eye to the right, the left eye to the left), so
    the right eye's takes ``-left``; the head's motors are swivel, tilt, side tilt, then each
    eye's horizontal, vertical and torsional ones (right eye first)."""
    action = np.zeros(n_motors, np.float32)
    action[[3, 6]], action[[4, 7]] = (-left, left), up
    return action


def save_partner_gaze_png(path, eye_size: int = 96, seconds: float = 0.4) -> str:
    """The joint-attention partner (``infant_1``) turns only its eyes (its eye motors at +-1 for
    ``seconds``; head and learner still): top, its face from 0.3 m in front; bottom, the same
    moment in the learner's left eye (``eye_size`` square, the face region enlarged 4x). Each
    column is titled with the turn and the eyes' measured angles."""
    from .envs import joint_attention_v0

    plt = _pyplot()
    fig, axes = plt.subplots(2, len(GAZE_TURNS), figsize=(2.3 * len(GAZE_TURNS), 5.0), dpi=120)
    for col, (label, h, v) in enumerate(GAZE_TURNS):
        env = joint_attention_v0.parallel_env(vision={"width": eye_size, "height": eye_size},
                                              render_size=(240, 280))
        env.reset(seed=0)
        learner, partner = env.agents
        zero = np.zeros(env.action_space(partner).shape, np.float32)
        turn = eye_turn(len(zero), h, v)
        steps = max(1, round(seconds / env.dt))
        for _ in range(steps):
            obs, *_ = env.step({learner: zero, partner: turn})
        w = env.world
        across, up = _gaze_angles(w, 1)
        face = env.render_rgb(_face_camera(w, 1, 0.3))
        eye = obs[learner]["eye_left"]
        r, c = _pixel_of(w, int(w.agents[0].eye_cameras[1]), w.data.site_xpos[
            w.agents[1].head_site], eye_size)
        half = eye_size // 8
        r0 = int(np.clip(round(r) - half, 0, eye_size - 2 * half))
        c0 = int(np.clip(round(c) - half, 0, eye_size - 2 * half))
        crop = eye[r0:r0 + 2 * half, c0:c0 + 2 * half].repeat(4, 0).repeat(4, 1)
        env.close()
        axes[0, col].imshow(face)
        _bare(axes[0, col], f"eyes {label}\n(gaze {across:+.0f}\u00b0 to its left, "
                            f"{up:+.0f}\u00b0 up)",
              "the partner's face\n(render, 0.3 m in front)" if col == 0 else None)
        axes[1, col].imshow(crop, interpolation="nearest")
        _bare(axes[1, col], None, (f"in the learner's left eye\n({eye_size}x{eye_size}; "
                                   f"face region x4)") if col == 0 else None)
    fig.suptitle("The partner turns only its eyes (eye motors at \u00b11 for "
                 f"{seconds:.1f} s): its face, and what the learner sees", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return str(path)


def _gaze_angles(world, i: int) -> tuple[float, float]:
    """Where agent ``i``'s eyes look, in its head's frame: degrees to its left and up (the mean
    of its two eyes' lines of sight)."""
    m, d = world.model, world.data
    prefix = world.names[i]
    gaze = sum(d.xmat[m.body(f"{prefix}/{side}_eye").id].reshape(3, 3)[:, 0]
               for side in ("right", "left"))
    head = d.site_xmat[world.agents[i].head_site].reshape(3, 3)
    x, y, z = gaze @ head
    return float(np.degrees(np.arctan2(y, x))), float(np.degrees(np.arctan2(z, np.hypot(x, y))))


def _pixel_of(world, cam: int, point, size: int) -> tuple[float, float]:
    """Pixel (row, column) of a world point in the square image of camera ``cam``."""
    d, m = world.data, world.model
    rel = (np.asarray(point) - d.cam_xpos[cam]) @ d.cam_xmat[cam].reshape(3, 3)
    f = size / 2 / np.tan(np.deg2rad(m.cam_fovy[cam]) / 2)
    return size / 2 - f * rel[1] / -rel[2], size / 2 + f * rel[0] / -rel[2]


def save_expressions_png(path) -> str:
    """The seven expressions on an 18-month-old's head with its eyeballs (a render from 0.3 m in
    front of the face), each titled with its name and id."""
    from .envs import free_play_v0
    from .expressions.faces import EXPRESSIONS

    plt = _pyplot()
    env = free_play_v0.parallel_env(n_agents=1, expressions=True, render_size=(240, 240))
    env.reset(seed=0)
    w = env.world
    fig, axes = plt.subplots(1, len(EXPRESSIONS), figsize=(1.9 * len(EXPRESSIONS), 2.4),
                             dpi=120)
    for e, name in enumerate(EXPRESSIONS):
        w.set_expression(0, e)
        mujoco.mj_forward(w.model, w.data)
        axes[e].imshow(env.render_rgb(_face_camera(w, 0, 0.3)))
        _bare(axes[e], f"{e} {name}")
    env.close()
    fig.suptitle("The seven expressions: the face texture (brows, mouth, cheeks, marks, lash "
                 "lines) and the eyeballs", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return str(path)


#: the bodies of :func:`save_three_sizes_png`: (label, agent settings)
THREE_SIZES = (("18-month-old\n(scale 1)", {"scale": 1.0}),
               ("3-4-year-old\n(scale 1.3)", {"scale": 1.3}),
               ("caregiver-sized\n(scale 2.2)", {"scale": 2.2, "strength": 1.0}))


def save_three_sizes_png(path) -> str:
    """Three bodies in one world, everyone smiling: an 18-month-old (scale 1), a 3-4-year-old
    (1.3) and a caregiver-sized body (2.2); each labelled with its scale, height and mass."""
    from .envs import free_play_v0

    plt = _pyplot()
    env = free_play_v0.parallel_env(n_agents=len(THREE_SIZES), render_mode="rgb_array",
                                    render_size=(480, 640), expressions=True,
                                    per_agent=[dict(s) for _, s in THREE_SIZES])
    env.reset(seed=0)
    still = {a: np.zeros(env.action_space(a)["motors"].shape, np.float32) for a in env.agents}
    for _ in range(10):  # a tenth of a second, everyone smiling
        env.step({a: {"motors": still[a], "expression": 1} for a in env.agents})
    w = env.world
    cam = env.scene_camera()
    frame = env.render_rgb(cam)
    h, wd = frame.shape[:2]
    fig, ax = plt.subplots(figsize=(wd / 100, h / 100 + 0.5), dpi=120)
    ax.imshow(frame)
    for i, (label, _) in enumerate(THREE_SIZES):
        a = w.agents[i]
        top = float(w.data.site_xpos[a.head_site, 2] + w.model.geom_size[a.head_geom, 0])
        feet = w.data.xpos[a.root_body] * (1, 1, 0)            # on the floor below the body
        mass = w.model.body_subtreemass[a.root_body]
        x, y = free_camera_pixel(cam, feet, h, wd, float(w.model.vis.global_.fovy))
        ax.annotate(f"{env.agents[i]}: {label}\n{top:.2f} m, {mass:.0f} kg", (x, y),
                    xytext=(0, -8), textcoords="offset points", ha="center", va="top",
                    fontsize=7, bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="0.6",
                                          alpha=0.85))
    env.close()
    _bare(ax, "Three body sizes in one world (every length x scale; docs/bodies.md)")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return str(path)


def free_camera_pixel(cam, point, height: int, width: int, fovy_deg: float):
    """Where a world point appears (x, y pixels) in the image of a free camera (MjvCamera's
    azimuth, elevation, distance and lookat; a pinhole of vertical field of view ``fovy_deg``)."""
    az, el = np.deg2rad(cam.azimuth), np.deg2rad(cam.elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    eye = np.asarray(cam.lookat) - cam.distance * forward
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rel = np.asarray(point, float) - eye
    f = 0.5 * height / np.tan(np.deg2rad(fovy_deg) / 2)
    z = rel @ forward
    return 0.5 * width + f * (rel @ right) / z, 0.5 * height - f * (rel @ up) / z


def save_validation_body_png(path) -> str:
    """The grown body (every 0.5 months, 0-24) against published infant data
    (docs/validation.md): standing length, mass, head and mid-upper-arm circumferences against
    the WHO medians with the tolerance bands of the tests, and the newborn's arm circumference
    and arm-to-head ratio against term newborns."""
    from .body import growth

    plt = _pyplot()
    model = growth.body_measures(np.arange(0.0, 24.01, 0.5))
    age = model["age"]
    who = growth.who_medians()
    head = growth.who_head_circumference()
    arm = growth.newborn_arm()
    fig, axes = plt.subplots(1, 4, figsize=(15, 3.8), dpi=110)
    panels = (
        ("Length (cm)", model["height_cm"], {a: v[0] for a, v in who.items()}, 0.07,
         "WHO median"),
        ("Mass (kg)", model["mass_kg"], {a: v[1] for a, v in who.items()}, 0.10,
         "WHO median"),
        ("Head circumference (cm)", model["head_cm"], head, 0.03,
         "WHO median"))
    for ax, (label, values, ref, tol, ref_label) in zip(axes, panels):
        ra = np.array(sorted(ref))
        rv = np.array([ref[a] for a in ra])
        ax.fill_between(ra, rv * (1 - tol), rv * (1 + tol), color="0.85",
                        label=f"tested band, +/- {100 * tol:.0f} %")
        ax.plot(ra, rv, "o", color="k", ms=5, label=ref_label)
        ax.plot(age, values, "-", color="tab:blue", lw=2, label="the model")
        ax.set_xlabel("age (months)")
        ax.set_title(label, fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    ax = axes[3]
    ratio = model["upper_arm_cm"] / model["head_cm"]
    ax.plot(age, model["upper_arm_cm"], "-", color="tab:blue", lw=2,
            label="the model (cm)")
    muac = "mid_upper_arm_circumference_cm"
    who_arm = growth.who_arm_circumference()
    wa = np.array(sorted(who_arm))
    wv = np.array([who_arm[a] for a in wa])
    ax.fill_between(wa, wv * 0.95, wv * 1.05, color="0.85", label="tested band, +/- 5 %")
    ax.plot(wa, wv, "o", color="k", ms=5, label="WHO median (from 3 months)")
    ax.errorbar([0], [arm[muac]], yerr=[arm[muac + "_sd"]], fmt="s", color="k",
                ms=5, capsize=3, label="term newborns (mean, SD)")
    twin = ax.twinx()
    twin.plot(age, ratio, "--", color="tab:orange", lw=1.5, label="the model: arm / head")
    ahr = "arm_to_head_circumference_ratio"
    twin.errorbar([0.4], [arm[ahr]], yerr=[arm[ahr + "_sd"]], fmt="D",
                  color="tab:red", ms=4, capsize=3, label="term newborns: arm / head")
    twin.set_ylim(0.1, 0.4)
    ax.set_ylim(5, 17)
    ax.set_xlabel("age (months)")
    ax.set_title("Mid-upper-arm circumference (cm); arm / head (right)", fontsize=10)
    ax.grid(alpha=0.3)
    lines = ax.get_legend_handles_labels()
    lines2 = twin.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], fontsize=7, loc="lower right")
    fig.suptitle("The grown body (mitten hands) against infant data: WHO medians with boys and "
                 "girls averaged, term newborns (docs/validation.md)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return str(path)


#: the figures ``mimo-social figure NAME OUT.png`` draws: name -> (function(path), what it shows)
FIGURES = {
    "skin-hand-ball": (save_hand_ball_png, "the skin of a hand holding a ball, coloured by force "
                                           "(paper Fig. 5b)"),
    "eyes-partner-gaze": (save_partner_gaze_png, "the joint-attention partner turning only its "
                                                 "eyes, and the learner's eye view of it"),
    "eyes-expressions": (save_expressions_png, "the seven expressions on a head with eyeballs"),
    "bodies-three-sizes": (save_three_sizes_png, "three body sizes in one world, labelled"),
    "validation-body": (save_validation_body_png, "the grown body's length, mass, head and arm "
                                                  "circumferences against infant data"),
}
