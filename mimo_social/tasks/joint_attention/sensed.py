"""``SensedFollowController``: joint attention from what the follower's face perception gives.

The scripted follower (:class:`~.controller.GazeFollowController`) reads its partner's gaze from
the world on every step, wherever it looks itself. This one reads it only on the steps the
follower's ``faces`` sense (:mod:`mimo_social.senses.faces`) sees the partner's face, and keeps
what it read while the face is out of view: what a learner with that sense and a memory can do
(issue 30: a demonstrator for a recurrent learner).

reads:
    the partner's toy (as the scripted follower: the toy nearest the partner's gaze ray, within
    ``max_angle_deg``) on the steps its ``faces`` sense says the face is seen (the agent's own
    sense when it has one on, else one of the sense's defaults)
target:
    the toy last read; when the face has been out of view for ``look_back_s`` (0.5), the partner's
    face (a look back to check), until it is seen again; the face too before the first reading
head and eyes:
    the scripted follower's PD law (:class:`~mimo_social.partners.gaze.GazeAtTarget`); it writes
    no state and changes no model value

Measured: docs/social/joint_attention.md, "Face perception" (``scripts/joint_attention_sensed.py``).
"""

from __future__ import annotations

from ...partners.base import agent_index
from ...senses.faces import Faces, FacesConfig
from ...util.checks import check_number
from .controller import GazeFollowController

__all__ = ["SensedFollowController"]


class SensedFollowController(GazeFollowController):
    """Follows the partner's gaze while its face is seen, keeps the last toy read while it is
    not, and looks back at the face after ``look_back_s`` unseen (module table). ``partner``,
    ``max_angle_deg``, ``omega``, ``zeta``: as :class:`GazeFollowController`'s."""

    def __init__(self, partner: str | None = None, look_back_s: float = 0.5,
                 max_angle_deg: float = 10.0, omega: float = 15.0, zeta: float = 1.0):
        super().__init__(partner=partner, read="eyes", max_angle_deg=max_angle_deg,
                         omega=omega, zeta=zeta)
        self.look_back_s = check_number("SensedFollowController", "look_back_s", look_back_s,
                                        0.0, 60.0)
        self._faces = None

    def __repr__(self):
        return (f"SensedFollowController(partner={self.partner!r}, "
                f"look_back_s={self.look_back_s}, max_angle_deg={self.max_angle_deg})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        i = agent_index(env, agent)
        own = [s for s in env.senses[i] if s.name == "faces"]
        self._faces = own[0] if own else Faces(FacesConfig(), env.world, i)
        j = env.possible_agents.index(self.partner) if self.partner else 1 - i
        self._slot = j if j < i else j - 1          # the partner's place among the others
        self._face = len(self._found)
        self._found = list(self._found) + [("site", self._head_site)]
        self._read, self._unseen = None, 0
        self.target = self._face

    def seen(self, env) -> bool:
        """Whether the follower's face perception sees the partner's face now."""
        w = env.world
        return bool(self._faces.seen(w.model, w.data)[self._slot])

    def act(self, env, agent, observation):
        if self._faces is None:
            raise RuntimeError("SensedFollowController.act() before reset(); reset the env first")
        if self.seen(env):
            self._unseen = 0
            read = self.read_now(env)
            if read is not None:
                self._read = read
        else:
            self._unseen += 1
        if self._read is None or self._unseen * float(env.dt) >= self.look_back_s:
            self.target = self._face
        else:
            self.target = self._read
        self._left = 1 << 30          # never switch on its own: the reading picks the target
        return super(GazeFollowController, self).act(env, agent, observation)
