"""The demo's interaction: an infant and a caregiver play a high five, then hand a ball over.

:class:`HighFiveThenHandover` is the handover task (:mod:`mimo_social.tasks.handover`: two
agents face to face, five-finger hands, skin on both arms and hands, a ball the giver
``caregiver_0`` holds out to the receiver ``infant_0``) with a first phase before it, in the same
world: a high five. Its :attr:`~HighFiveThenHandover.phase` (set before ``env.reset``) says what
the next episode is:

``"high_five"``:
    reset: the receiver's right arm hanging (shifted at random, as in the handover), the giver's arm
        where the world starts it, the ball on the floor beside the giver
    success (``is_success`` in the infos): both right hands feel the other agent on their skin and
        touch each other (as in :mod:`mimo_social.tasks.high_five` with ``success="touch"``); the
        episode does not end
    scripted agents (:func:`phase_partners`): ``infant_0``:
        :class:`~mimo_social.tasks.high_five.HighFiveController` with the first versions' palm
        goal (``palm="forward"``); ``caregiver_0``: ``HandOffer(grip=False, release=None,
        palm="forward")``
``"handover"``:
    reset: the handover's own: the ball in the giver's palm, its fingers closed on it
    success (``is_success`` in the infos): the handover's (the receiver's hand holds the ball, the
        giver's no longer touches it, for 0.3 s)
    scripted agents (:func:`phase_partners`): ``infant_0``:
        :class:`~mimo_social.tasks.handover.ReceiveController`; ``caregiver_0``: the handover's
        :func:`~mimo_social.tasks.handover.scripted_giver`

Both phases keep running after success (the handover's ``end_on_success`` is off); a ball that
falls ends the handover (as in the task). Rewards are the handover's in its phase, zero in the
high five. The scripted agents act only through their own action spaces.
"""

from __future__ import annotations

import numpy as np

from ..core.kinematics import hand_geoms
from ..core.task import Plot
from ..partners import HandOffer
from ..tasks.handover import ReceiveController
from ..tasks.high_five import HighFiveController
from ..tasks.common import ContactProbe, right_hand_parts
from ..tasks.handover.task import GIVER, RECEIVER, Handover, scripted_giver
from ..tasks.high_five.task import SkinSource
from ..util.checks import check_choice

__all__ = ["PHASES", "HighFiveThenHandover", "phase_partners"]

PHASES = ("high_five", "handover")
#: where the ball waits during the high five: m from the giver's hip, in its heading frame
#: (forward, left), on the floor beside it
BALL_WAITS = (0.05, 0.3)


class HighFiveThenHandover(Handover):
    name = "demo"
    #: what the next reset starts (one of :data:`PHASES`)
    phase = "high_five"

    def bind(self, env):
        super().bind(env)
        w = env.world
        hands = [hand_geoms(w, i) for i in (RECEIVER, GIVER)]
        self._hands_meet = ContactProbe(w.model.ngeom, hands[0], hands[1])
        touch = env.systems.get("touch")
        self._feels = [SkinSource(w, touch, i, hands[i], right_hand_parts(w.tables[i]), 1 - i)
                       for i in (RECEIVER, GIVER)]

    def _ball_waits(self, env) -> np.ndarray:
        w = env.world
        d = w.data
        root = w.agents[GIVER].root_body
        R = d.xmat[root].reshape(3, 3)
        heading = np.arctan2(R[1, 0], R[0, 0])
        c, s = np.cos(heading), np.sin(heading)
        fwd, left = BALL_WAITS
        x = d.xpos[root, 0] + c * fwd - s * left
        y = d.xpos[root, 1] + s * fwd + c * left
        return np.array([x, y, self.options.ball_radius + 0.002])

    def reset(self, env, rng):
        self.phase = check_choice("demo", "phase", self.phase, PHASES)
        if self.phase == "handover":
            super().reset(env, rng)
            return
        w = env.world
        d = w.data
        r = w.agents[RECEIVER]
        k = r.actuated_joint_idx[:7]   # as the handover: the hanging arm, shifted at random
        noise = np.deg2rad(self.options.arm_noise) * rng.uniform(-1.0, 1.0, len(k))
        d.qpos[r.qpos_adr[k]] = np.clip(d.qpos[r.qpos_adr[k]] + noise, r.joint_range[k, 0],
                                        r.joint_range[k, 1])
        self.place_ball(env, self._ball_waits(env))
        self._high_five = False
        self._palms_apart = self._palm_gap(d)

    def _palm_gap(self, d) -> float:
        w = self._world
        return float(np.linalg.norm(d.site_xpos[w.agents[RECEIVER].palm_sites[0]]
                                    - d.site_xpos[w.agents[GIVER].palm_sites[0]]))

    def rewards(self, env):
        if self.phase == "handover":
            return super().rewards(env)
        d = env.world.data
        felt = [bool(f(d)) for f in self._feels]
        self._high_five = felt[0] and felt[1] and self._hands_meet(d)
        self._palms_apart = self._palm_gap(d)
        return np.zeros(2)

    @property
    def palm_distance(self) -> float:
        """The distance (m) between the two right palm centres in the high five (NaN in the
        handover)."""
        return self._palms_apart if self.phase == "high_five" else float("nan")

    @property
    def ball_distance(self) -> float:
        """The distance (m) from the receiver's right palm centre to the ball in the handover
        (NaN in the high five)."""
        return self._distance if self.phase == "handover" else float("nan")

    def plots(self):
        """The replay's plots: the distance between the right palms (high five), the ball's
        distance to the infant's palm and who holds it (handover), and the phase's success;
        each NaN (no value) outside its phase."""
        nan = float("nan")
        holder = {"giver": -1.0, "none": 0.0, "receiver": 1.0}
        return [Plot("palm_distance", "m", lambda env: self.palm_distance, per_agent=False),
                Plot("ball_to_hand", "m", lambda env: self.ball_distance, per_agent=False),
                Plot("holder", "-1 caregiver, 0 none, 1 infant",
                     lambda env: holder[self._holder] if self.phase == "handover" else nan,
                     per_agent=False),
                Plot("success", "0/1", lambda env: float(self.succeeded), per_agent=False)]

    @property
    def succeeded(self) -> bool:
        """Whether this phase's goal is met this step (the high five, the ball held)."""
        return self._success if self.phase == "handover" else self._high_five

    def info_spec(self, i):
        """Both phases' info keys (see MimoParallelEnv.info_spec)."""
        return {**super().info_spec(i), "phase": PHASES, "palm_distance": "number"}

    def terminations(self, env):
        if self.phase == "handover":
            done, infos = super().terminations(env)
            for info in infos:
                info.update(phase="handover", palm_distance=float("nan"))
            return done, infos
        info = {"is_success": self._high_five, "holder": "none", "dropped": False,
                "receiver_parts": 0, "held_steps": 0, "distance": float("nan"),
                "phase": "high_five", "palm_distance": self._palms_apart}
        return np.zeros(2, bool), [dict(info), dict(info)]


def phase_partners(env, phase: str) -> dict:
    """The scripted controller of each agent for ``phase`` (agent name -> Partner; not yet
    reset)."""
    phase = check_choice("demo", "phase", phase, PHASES)
    receiver, giver = env.possible_agents
    if phase == "high_five":
        return {receiver: HighFiveController(palm="forward"),
                giver: HandOffer(grip=False, release=None, palm="forward")}
    return {receiver: ReceiveController(), giver: scripted_giver(env.task.options)}
