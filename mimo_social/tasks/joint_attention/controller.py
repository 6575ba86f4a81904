"""``GazeFollowController``: the scripted solution of joint attention (a perfect gaze reader).

reads:
    each step, from the world: the partner's eye cameras (where its two eyes are and point: the same
    gaze ray the task uses, from between its eyes along the mean of their viewing axes) and the
    toys' positions (``env.task.toy_bodies``); with ``read="head"`` (a hack, not a solution) the
    partner's head direction instead of its eyes
target:
    the toy nearest the partner's gaze ray, once the ray passes within ``max_angle_deg`` (10) of its
    centre (the toys are at least 25 degrees apart); kept while the partner's gaze is between toys.
    ``read="head"``: the toy nearest the partner's head's facing direction, once the head has turned
    ``min_head_deg`` (5) from facing the follower
head and eyes:
    :class:`~mimo_social.partners.gaze.GazeAtTarget`'s PD law drives the follower's own head and eye
    motors to the angles that look at the target (head turned fully, the eyes correcting)
acts:
    only through the agent's 9 head and eye motors; it writes no state and changes no model value; a
    zero action until the partner's gaze first lands near a toy

Measured on ``joint_attention_v0.scripted_env()`` (seeds 1000-1019): see the task's table and
``docs/social/joint_attention.md``.
"""

from __future__ import annotations

import numpy as np

from ...body.sight import gaze_rays
from ...util.checks import check_choice, check_number
from ...partners.base import agent_index, zero_action
from ...partners.gaze import GazeAtTarget

__all__ = ["GazeFollowController"]

READS = ("eyes", "head")


class GazeFollowController(GazeAtTarget):
    """Looks at the toy its partner looks at (see the module table). ``partner``: the agent to
    follow (``None``: the other of two agents); ``read``: ``"eyes"`` (the partner's gaze ray)
    or ``"head"`` (its head's facing direction only: a hack that ignores the eyes);
    ``max_angle_deg``, ``min_head_deg``: the reading thresholds; ``omega``, ``zeta``: the PD
    law (see :class:`~mimo_social.partners.gaze.GazeAtTarget`)."""

    def __init__(self, partner: str | None = None, read: str = "eyes",
                 max_angle_deg: float = 10.0, min_head_deg: float = 5.0,
                 omega: float = 15.0, zeta: float = 1.0):
        super().__init__(targets=None, hold_s=(1.0, 1.0), omega=omega, zeta=zeta,
                         head_share=1.0)
        if partner is not None and (not isinstance(partner, str) or not partner):
            raise ValueError(f"GazeFollowController: partner={partner!r}; allowed: None (the "
                             "other agent) or an agent's name")
        check_choice("GazeFollowController", "read", read, READS)
        self.partner, self.read = partner, read
        self.max_angle_deg = check_number("GazeFollowController", "max_angle_deg",
                                          max_angle_deg, 1.0, 30.0)
        self.min_head_deg = check_number("GazeFollowController", "min_head_deg",
                                         min_head_deg, 0.0, 45.0)

    def __repr__(self):
        return (f"GazeFollowController(partner={self.partner!r}, read={self.read!r}, "
                f"max_angle_deg={self.max_angle_deg})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        i = agent_index(env, agent)
        agents = list(env.possible_agents)
        if self.partner is None:
            if len(agents) != 2:
                raise ValueError(f"GazeFollowController: {len(agents)} agents; name the partner "
                                 f"to follow (partner=...), one of {agents}")
            j = 1 - i
        else:
            if self.partner not in agents or self.partner == agent:
                raise ValueError(f"GazeFollowController: partner={self.partner!r}; allowed: "
                                 f"{[a for a in agents if a != agent]}")
            j = agents.index(self.partner)
        w = env.world
        p = w.agents[j]
        self._cams = np.asarray(p.eye_cameras, dtype=np.intp)
        self._head_site = int(p.head_site)
        self._head_body = int(w.model.site_bodyid[p.head_site])
        self._toys = np.asarray(env.task.toy_bodies, dtype=np.intp)
        # the partner's head at rest faces the follower: its facing direction then
        d = w.data
        self._rest = self.head_direction(d)
        self._zero = zero_action(env.action_space(agent))
        self.target = None

    def head_direction(self, d) -> np.ndarray:
        """The partner's head's facing direction (its frame's x axis, world frame; a copy)."""
        return d.xmat[self._head_body].reshape(3, 3)[:, 0].copy()

    def _ray(self, d) -> tuple[np.ndarray, np.ndarray]:
        if self.read == "head":
            return d.site_xpos[self._head_site], self.head_direction(d)
        return gaze_rays(d, self._cams)

    def read_target(self, env) -> int | None:
        """The toy the partner looks at, as this reader sees it; between toys the last one read
        (None: none yet)."""
        toy = self.read_now(env)
        return self.target if toy is None else toy

    def read_now(self, env) -> int | None:
        """The toy the partner looks at now, as this reader sees it (None: between toys)."""
        d = env.world.data
        origin, direction = self._ray(d)
        to_toy = d.xpos[self._toys] - origin
        cos = to_toy @ direction / np.linalg.norm(to_toy, axis=1)
        best = int(np.argmax(cos))
        angle = np.rad2deg(np.arccos(np.clip(cos[best], -1.0, 1.0)))
        if self.read == "head":
            turned = np.rad2deg(np.arccos(np.clip(direction @ self._rest, -1.0, 1.0)))
            return best if turned >= self.min_head_deg else None
        return best if angle <= self.max_angle_deg else None

    def act(self, env, agent, observation):
        if getattr(self, "_toys", None) is None:
            raise RuntimeError("GazeFollowController.act() before reset(); reset the env first")
        self.target = self.read_target(env)
        if self.target is None:
            return self._zero
        self._left = 1 << 30          # never switch on its own: the target is read each step
        return super().act(env, agent, observation)
