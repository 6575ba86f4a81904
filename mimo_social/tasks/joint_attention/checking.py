"""``CheckingFollowController``: joint attention done as a learner must, by watching the face.

The scripted follower (:class:`~.controller.GazeFollowController`) reads its partner's gaze from
the world every step, wherever it looks itself. A learner reads it only from its eyes, and only
while it looks at the partner's face: with a 3x fovea on the face, the direction of the partner's
toy is in the image (99 % of held-out steps, ``scripts/joint_attention_probe.py --look face``);
from the follower's own view, looking at the toys, far less (51-62 %). This follower does what
infants do, and what a learner with those eyes could copy (issue 30):

reads:
    the partner's toy from the world (as the scripted follower), but only while its own gaze is
    within ``on_face_deg`` (5) of the partner's face (head centre), and the partner's head
    direction (a head turn, visible out of the corner of the eye)
modes:
    ``face``: looks at the partner's face until the partner's gaze has rested ``settle_s`` (0.1)
    on one toy while it watched; ``toy``: turns to that toy and looks at it for ``look_s`` (2),
    or until the partner's head has turned more than ``peripheral_deg`` (3; 0: never) from where
    it was at the reading; then ``face`` again
head turn seen:
    ``head_turn_seen="in_view"`` (default): the turn counts only while the partner's head centre
    is inside one of the follower's eye images (its cameras' field of view, ``cam_fovy``, and the
    images' aspect): a 60-degree eye that fixates a toy on the floor has the partner's head out
    of view in every layout measured (docs/training/issue30/pilots/joint_attention_head_turn);
    ``"anywhere"``: wherever the head is (an oracle of the cue)
head and eyes:
    the scripted follower's PD law (:class:`~mimo_social.partners.gaze.GazeAtTarget`), to the face
    or to the toy; it writes no state and changes no model value

Measured (seeds 1000-1019, ``scripts/joint_attention_checking_follower.py``): with the head turn
seen anywhere, look 2 s and 3 s with a 3-degree head turn 20 / 20 each (look 1.5 s: 16 / 20);
on a timer alone (``peripheral_deg=0``) 5-10 of 20; with the head turn seen only in view: the
pilot's README. ``bc_kwargs`` ``demonstrator = "checking"`` clones it.
"""

from __future__ import annotations

import numpy as np

from ...body.sight import gaze_rays, in_view
from ...partners.base import agent_index
from ...util.checks import check_choice, check_number
from .controller import GazeFollowController

__all__ = ["CheckingFollowController", "MODES", "HEAD_TURN_SEEN"]

#: the follower's modes: watching the face, looking at the toy read there
MODES = ("face", "toy")
#: where the partner's head turn is seen: only inside the follower's eye images, or anywhere
HEAD_TURN_SEEN = ("in_view", "anywhere")


class CheckingFollowController(GazeFollowController):
    """Watches the partner's face, turns to the toy read there, looks back (module table).
    ``partner``, ``max_angle_deg``, ``omega``, ``zeta``: as :class:`GazeFollowController`'s (it
    reads the partner's eyes); ``look_s``, ``settle_s``, ``on_face_deg``, ``peripheral_deg``:
    the checking; ``head_turn_seen``: ``"in_view"`` or ``"anywhere"`` (module table)."""

    def __init__(self, partner: str | None = None, look_s: float = 2.0, settle_s: float = 0.1,
                 on_face_deg: float = 5.0, peripheral_deg: float = 3.0,
                 head_turn_seen: str = "in_view", max_angle_deg: float = 10.0,
                 omega: float = 15.0, zeta: float = 1.0):
        super().__init__(partner=partner, read="eyes", max_angle_deg=max_angle_deg,
                         omega=omega, zeta=zeta)
        who = "CheckingFollowController"
        self.look_s = check_number(who, "look_s", look_s, 0.05, 60.0)
        self.settle_s = check_number(who, "settle_s", settle_s, 0.0, 10.0)
        self.on_face_deg = check_number(who, "on_face_deg", on_face_deg, 0.5, 45.0)
        self.peripheral_deg = check_number(who, "peripheral_deg", peripheral_deg, 0.0, 90.0,
                                           "0: no early look back")
        self.head_turn_seen = check_choice(who, "head_turn_seen", head_turn_seen,
                                           HEAD_TURN_SEEN)
        self.mode = "face"

    def __repr__(self):
        return (f"CheckingFollowController(partner={self.partner!r}, look_s={self.look_s}, "
                f"settle_s={self.settle_s}, on_face_deg={self.on_face_deg}, "
                f"peripheral_deg={self.peripheral_deg}, "
                f"head_turn_seen={self.head_turn_seen!r})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        self._face = len(self._found)
        self._found = list(self._found) + [("site", self._head_site)]
        i = agent_index(env, agent)
        self._own_cams = np.asarray(env.world.agents[i].eye_cameras, dtype=np.intp)
        m = env.world.model
        half_v = np.tan(np.deg2rad(m.cam_fovy[self._own_cams]) / 2.0)
        vision = getattr(env, "systems", {}).get("vision")     # the images' aspect, else 1
        cfg = vision.configs[i] if vision is not None else None
        aspect = cfg.width / cfg.height if cfg else 1.0
        self._half_tan = np.stack([half_v * aspect, half_v], axis=1)    # (eye, x / y)
        self.mode, self._steps, self._read, self._seen_head = "face", 0, None, None
        self.target = self._face

    def gaze_to_face_deg(self, data) -> float:
        """Angle (degrees) between this follower's line of sight and the partner's face."""
        origin, direction = gaze_rays(data, self._own_cams)
        face = data.site_xpos[self._head_site] - origin
        cos = direction @ face / np.linalg.norm(face)
        return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))

    def head_in_view(self, data) -> bool:
        """Whether the partner's head centre is inside one of this follower's eye images."""
        return bool(in_view(data, self._own_cams, data.site_xpos[self._head_site],
                            self._half_tan).any())

    def act(self, env, agent, observation):
        if getattr(self, "_own_cams", None) is None:
            raise RuntimeError("CheckingFollowController.act() before reset(); reset the env "
                               "first")
        d, dt = env.world.data, float(env.dt)
        if self.mode == "face":
            read = self.read_now(env)
            watching = self.gaze_to_face_deg(d) <= self.on_face_deg
            self._steps = self._steps + 1 if (
                read is not None and read == self._read and watching) else 0
            self._read = read
            if read is not None and watching and self._steps * dt >= self.settle_s:
                self.mode, self.target = "toy", read
                self._steps, self._seen_head = 0, self.head_direction(d)
        else:
            self._steps += 1
            turned = np.degrees(np.arccos(np.clip(self.head_direction(d) @ self._seen_head,
                                                  -1.0, 1.0)))
            seen = self.head_turn_seen == "anywhere" or self.head_in_view(d)
            if self._steps * dt >= self.look_s or (
                    self.peripheral_deg and turned > self.peripheral_deg and seen):
                self.mode, self.target, self._steps, self._read = "face", self._face, 0, None
        self._left = 1 << 30          # never switch on its own: the mode picks the target
        return super(GazeFollowController, self).act(env, agent, observation)
