"""Joint attention: the learner follows its partner's gaze to one of several toys.

| | |
|---|---|
| agents | 2: `infant_0` (the learner) and `infant_1` (the partner: scripted, by default `GazeAtTarget`, which turns its head and eyes to one toy after another, or a second learner) |
| body | sitting, hip fixed in the world, every joint held except the head (swivel, tilt, sideways tilt) and the eyes (horizontal, vertical, torsional), which are motors: each agent turns its own head and eyes; with `head_support` (on) the task cancels gravity on head and eyes (neck tone: a zero action does not let the head drop) |
| scene | the two infants `distance` (0.7 m) apart, face to face; `n_toys` (4) toys on the floor beside them, a red ball, a blue cube, a yellow ball and a green cube (3.5 cm), to the left and right of the pair, 0.25-0.45 m off the line between the infants, each at least `min_separation_deg` (25) from every other as seen from either head |
| reset | the toys placed at random (seeded), each turned at random about the vertical; heads and eyes at rest, facing the partner |
| action | the 9 head and eye motors (`Box(-1, 1, (9,))`; expressions are off by default) |
| observation | `eye_left`, `eye_right` (96x96x3 RGB), `proprioception` (54: its own joints, where its head and eyes point); never the partner's target or joint angles |
| gaze | an agent's gaze ray starts between its eyes (the mean of the two eye cameras) along the mean of the two cameras' viewing axes; it *lands on* a toy when the angle to the toy's centre is below the toy's angular radius plus `margin_deg` (5); the nearest such toy is the one looked at |
| reward | +1 on a step where both agents' gaze lands on the same toy, else 0; with `shaping` > 0, minus `shaping` x the angle (rad) between the agent's gaze ray and the toy the other agent looks at (when it looks at one); with `scripted_partner` (set by `scripted_env`) only `infant_0` is rewarded and `infant_1` has no eyes |
| success | `is_success`: both look at the same toy this step; infos also `looked_at` (own toy or -1), `target` (the toy the other agent looks at, -1 while it looks at none, e.g. mid-turn), `gaze_error_deg` (angle from the own gaze ray to `target`, -1 without one) |
| termination | none; truncation at 500 steps (5 s) |
| options | `distance` (0.6-1.5 m), `n_toys` (2-4), `margin_deg` (0-30), `shaping` (0-100, default 0), `min_separation_deg` (0-35), `head_support` (True), `scripted_partner` (False) |
| privileged cues | none in the observation (the partner's head turn reaches the learner only through its eyes); with `shaping` > 0 the reward reads the partner's toy from the geometry |
| baselines | 20 episodes of 500 steps, scripted partner (no command in the package): random policy (uniform motor commands) return 0.0 +- 0.0, success rate 0.000; zero action (keeps looking at the partner) 0; a privileged follower (a `GazeAtTarget` told the partner's current target; not a learner) 0.858 +- 0.028, the ceiling a follower with instant knowledge reaches. PPO, scripted `GazeAtTarget` partner, `shaping` 0.1, 2 seeds, 61k env steps (27-32 min): training return -76 / -66 -> -26 / -31 (mean gaze error to the partner's toy from ~1.5 rad to ~0.5 rad), no step of shared attention in evaluation (`mimo-social compare --task joint_attention --mode scripted --algos ppo --seeds 2 --steps 60000 --out runs/joint_attention --eval-every 5000 --eval-episodes 5 --env-kwargs '{"task_options": {"shaping": 0.1}}'`) |
| sources | not in the MIMo paper: a social task of this package; rationale (gaze following, 9-18 months) and figures: `docs/social/joint_attention.md` |
| version history | v0: first version, with mirror and the scripted partners `ExpressionShow` and `GazeAtTarget` |

What the learner sees: the eyeballs of this body are hidden in renders (the face texture draws
the eyes), so only the partner's head turn is visible. `GazeAtTarget` turns the head fully to
the toy and the eyes only correct the rest: a swivel of 20-75 degrees (median 40) and a tilt of
15-45 degrees down. `shaping` is off by default: the return then counts the steps of shared
attention (return / 500 is the success rate); a learner trained from scratch may turn it on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body.joint_groups import GAZE_JOINTS, held_posture
from ..body.postures import POSTURES
from ..body.tables import load_body
from ..core.task import Task, TaskOptions
from ..core.world import AgentSetup, Prop
from .common import face_to_face

DISTANCE = 0.7
EYE_SIZE = 96
TOY_SIZE = 0.035
TOYS = (("sphere", (0.9, 0.15, 0.15, 1.0)), ("box", (0.15, 0.35, 0.9, 1.0)),
        ("sphere", (0.95, 0.85, 0.1, 1.0)), ("box", (0.15, 0.7, 0.2, 1.0)))
SIDE = (0.25, 0.45)          # toys this far (m) off the line between the infants
MAX_TRIES = 500


class GazeRays:
    """Each agent's gaze ray (from between its eyes along the eyes' mean viewing axis) and the
    toy it lands on; index tables resolved once. Every toy counts as a sphere of ``toy_radius``
    (for the cubes: their inscribed sphere plus 18 %)."""

    def __init__(self, world, toy_bodies, toy_radius: float, margin_deg: float):
        self.cams = np.array([a.eye_cameras for a in world.agents], dtype=np.intp)  # (n, 2)
        self.toys = np.asarray(toy_bodies, dtype=np.intp)
        self.radius = float(toy_radius)
        self.margin = np.deg2rad(margin_deg)

    def rays(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Origins (n, 3) and unit directions (n, 3); a camera looks along its frame's -z."""
        origin = data.cam_xpos[self.cams].mean(axis=1)
        axes = -data.cam_xmat[self.cams].reshape(*self.cams.shape, 3, 3)[..., 2]
        direction = axes.sum(axis=1)
        direction /= np.linalg.norm(direction, axis=1, keepdims=True)
        return origin, direction

    def angles(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Angle (rad) from each agent's ray to each toy centre (n, k), and each toy's angular
        radius seen from each agent (n, k)."""
        origin, direction = self.rays(data)
        to_toy = data.xpos[self.toys][None, :, :] - origin[:, None, :]
        dist = np.linalg.norm(to_toy, axis=2)
        cos = np.einsum("nkc,nc->nk", to_toy, direction) / dist
        return np.arccos(np.clip(cos, -1.0, 1.0)), np.arcsin(np.minimum(1.0, self.radius / dist))

    def looked_at(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Per agent, the toy its gaze lands on (-1: none), and the angles of :meth:`angles`."""
        angle, radius = self.angles(data)
        excess = angle - radius
        best = np.argmin(excess, axis=1)
        hit = excess[np.arange(len(best)), best] <= self.margin
        return np.where(hit, best, -1), angle


@dataclass(frozen=True)
class JointAttentionOptions(TaskOptions):
    """Distance between the infants (m), number of toys, the gaze margin around a toy (deg),
    the shaping weight, the toys' least angular separation (deg), head support, and whether
    ``infant_1`` is a scripted partner (no eyes, no reward)."""

    task = "joint_attention"
    distance: float = DISTANCE
    n_toys: int = len(TOYS)
    margin_deg: float = 5.0
    shaping: float = 0.0
    min_separation_deg: float = 25.0
    head_support: bool = True
    scripted_partner: bool = False

    def __post_init__(self):
        self._number("distance", 0.6, 1.5)
        self._int("n_toys", 2, len(TOYS))
        self._number("margin_deg", 0.0, 30.0)
        self._number("shaping", 0.0, 100.0)
        self._number("min_separation_deg", 0.0, 35.0)
        self._bool("head_support")
        self._bool("scripted_partner")


class JointAttention(Task):
    name = "joint_attention"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 500
    Options = JointAttentionOptions

    def __init__(self, n_agents: int, options=None, /, **values):
        super().__init__(n_agents, options, **values)
        self.toy_bodies: np.ndarray | None = None   # body ids of the toys, set at the first reset

    def agent_defaults(self, i, settings):
        scripted = i == 1 and self.options.scripted_partner
        return {"posture": "sitting", "expressions": False, "vestibular": False,
                "vision": False if scripted else {"width": EYE_SIZE, "height": EYE_SIZE}}

    def setup(self, i, config):
        dist = self.options.distance
        pos, facing = face_to_face(i, dist)
        tables = load_body(config.hands)
        frozen = held_posture(tables, keep=GAZE_JOINTS, angles=POSTURES["sitting"]["joints"])
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=GAZE_JOINTS)

    def props(self):
        out = []
        for k in range(self.options.n_toys):
            shape, rgba = TOYS[k]
            size = (TOY_SIZE,) if shape == "sphere" else (TOY_SIZE * 0.85,) * 3
            out.append(Prop(f"toy_{k}", shape, size, (0.35, 1.0 + 0.2 * k, TOY_SIZE), 0.05, rgba))
        return out

    # -- running -------------------------------------------------------------------------------
    def reset(self, env, rng):
        w = env.world
        d = w.data
        if self.toy_bodies is None:
            n = self.options.n_toys
            self.toy_bodies = np.array([w.prop_bodies[f"toy_{k}"] for k in range(n)], np.intp)
            self._toy_qpos = [w.prop_qpos[f"toy_{k}"] for k in range(n)]
            self._rays = GazeRays(w, self.toy_bodies, TOY_SIZE, self.options.margin_deg)
            self._heads = np.array([d.site_xpos[a.head_site] for a in w.agents])
            self._weights = np.array([1.0, 0.0 if self.options.scripted_partner else 1.0])
            self._head_dofs = np.concatenate([a.dof_adr[a.actuated_joint_idx] for a in w.agents])
        for k, xy in enumerate(self._place_toys(rng)):
            q = self._toy_qpos[k]
            yaw = rng.uniform(-np.pi, np.pi)
            d.qpos[q:q + 7] = (xy[0], xy[1], TOY_SIZE if TOYS[k][0] == "sphere"
                               else 0.85 * TOY_SIZE, np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))
        self._looked = np.full(2, -1)
        self._angle = None

    def _place_toys(self, rng) -> list[np.ndarray]:
        """Toy positions (x, y): beside the pair (left and right alternate, so both sides hold
        toys), each at least ``min_separation_deg`` from the others seen from either head."""
        dist = self.options.distance
        sep = np.deg2rad(self.options.min_separation_deg)
        n = self.options.n_toys
        for _ in range(MAX_TRIES):   # whole layouts: an early toy may leave no room for a later
            first_side = rng.choice([-1.0, 1.0])
            placed: list[np.ndarray] = []
            for k in range(n):
                side = first_side * (1 if k % 2 == 0 else -1)
                for _ in range(20):
                    xy = np.array([rng.uniform(0.1, dist - 0.1), side * rng.uniform(*SIDE)])
                    if all(self._separated(xy, other, sep) for other in placed):
                        placed.append(xy)
                        break
                else:
                    break
            if len(placed) == n:
                return placed
        raise RuntimeError(f"joint_attention: could not place {n} toys {np.rad2deg(sep):.0f} "
                           "degrees apart; lower min_separation_deg")

    def _separated(self, a, b, sep) -> bool:
        for head in self._heads:
            u = np.append(a, TOY_SIZE) - head
            v = np.append(b, TOY_SIZE) - head
            cos = u @ v / (np.linalg.norm(u) * np.linalg.norm(v))
            if np.arccos(np.clip(cos, -1.0, 1.0)) < sep:
                return False
        return True

    def before_physics(self, env):
        """Head support: the head and eye joints' generalised gravity (and Coriolis) force of
        the last physics step is applied to them, as neck tone would, so a zero action holds
        the head where it is (springs and damping still pull it toward rest)."""
        if self.options.head_support:
            d = env.world.data
            d.qfrc_applied[self._head_dofs] = d.qfrc_bias[self._head_dofs]

    def rewards(self, env):
        looked, angle = self._rays.looked_at(env.world.data)
        self._looked, self._angle = looked, angle
        self._joint = bool(looked[0] >= 0 and looked[0] == looked[1])
        r = np.full(2, float(self._joint))
        shaping = self.options.shaping
        if shaping:
            for i in range(2):
                other = looked[1 - i]
                if other >= 0:
                    r[i] -= shaping * angle[i, other]
        return self._weights * r

    def terminations(self, env):
        infos = []
        for i in range(2):
            other = int(self._looked[1 - i])
            err = float(np.rad2deg(self._angle[i, other])) if other >= 0 else -1.0
            infos.append({"looked_at": int(self._looked[i]), "target": other,
                          "gaze_error_deg": err, "is_success": self._joint})
        return np.zeros(2, bool), infos
