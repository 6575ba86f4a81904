"""The paper's single-infant motor tasks on the device (:mod:`mimo_social.gpu.tasks` lists them
with the others): stand-up, roll-over and catch, each computing what its CPU task computes
(:mod:`mimo_social.gpu.task_base` has the protocol).
"""

from __future__ import annotations

import numpy as np

from ..core.kinematics import LookAt, hand_geoms
from .gaze import BatchedGaze
from .task_base import BatchedTask, hold_steps, streak

__all__ = ["BatchedStandup", "BatchedRollOver", "BatchedCatch"]


class BatchedStandup(BatchedTask):
    """Stand-up (:class:`mimo_social.tasks.standup.Standup`): the reward is the head's height
    above the reference minus ``cost_weight`` times the squared applied controls (after the
    motor delay, as the CPU env's ``controls``); success: the head ``success_gain`` above its
    settled start height for ``success_hold`` s in a row (a per-world step count); the episode
    ends at the time limit only. Each world's start height and reference (the head's height
    after the CPU reset's settling, where the option asks for it) come from the CPU env reset
    with the world's seed."""

    name = "standup"
    info_keys = ("head_height", "head_gain", "is_success", "control_cost")

    def __init__(self, env, batched):
        super().__init__(env, batched)
        torch = batched.torch
        opts = env.task.options
        dev = batched.qpos.device
        self.head = int(env.world.agents[0].head_site)
        self.cost_weight = float(opts.cost_weight)
        self.success_gain = float(opts.success_gain)
        self.hold_steps = hold_steps(opts.success_hold, env.dt)
        self.controls = batched.controls[0]
        n = batched.nworld
        self.start = torch.zeros(n, dtype=torch.float32, device=dev)
        self.ref = torch.zeros(n, dtype=torch.float32, device=dev)
        self.above = torch.zeros(n, dtype=torch.int64, device=dev)

    def capture(self, env) -> dict:
        return {"start": float(env.task.start_height), "ref": float(env.task.reference)}

    def load(self, idx, captured) -> None:
        t = self.batched.torch
        for key in ("start", "ref"):
            getattr(self, key)[idx] = t.as_tensor(captured[key], device=self.ref.device).to(
                t.float32)
        self.above[idx] = 0

    def evaluate(self):
        t = self.batched.torch
        height = self.batched.tensors["site_xpos"][:, self.head, 2].to(t.float32)
        u = self.controls.applied
        cost = self.cost_weight * (u * u).sum(1)
        gain = height - self.start
        self.above = streak(self.above, gain >= self.success_gain)
        success = self.above >= self.hold_steps
        infos = {"head_height": height, "head_gain": gain, "is_success": success,
                 "control_cost": cost}
        return (height - self.ref - cost)[:, None], t.zeros_like(success), infos


class BatchedRollOver(BatchedTask):
    """Roll-over (:class:`mimo_social.tasks.rollover.RollOver`): the chest's turn from its
    start posture (the angle between the upper trunk's forward axis and the world's up, or
    down from the belly, :func:`~mimo_social.tasks.rollover.turn_angle`); the reward is that
    angle over 180 degrees, plus ``over_bonus`` while it is ``success_angle`` or more, minus
    ``cost_weight`` times the squared applied controls; success: turned that far for
    ``success_hold`` s in a row (a per-world step count); the episode ends at the time limit
    only. Nothing per world comes from the reset but the state."""

    name = "rollover"
    info_keys = ("turn_angle", "is_success", "control_cost")

    def __init__(self, env, batched):
        super().__init__(env, batched)
        torch = batched.torch
        o = env.task.options
        self.chest = int(env.task.chest_body)
        self.sign = -1.0 if o.start == "prone" else 1.0
        self.success_angle = float(o.success_angle)
        self.over_bonus, self.cost_weight = float(o.over_bonus), float(o.cost_weight)
        self.hold_steps = hold_steps(o.success_hold, env.dt)
        self.controls = batched.controls[0]
        self.turned = torch.zeros(batched.nworld, dtype=torch.int64, device=batched.qpos.device)

    def load(self, idx, captured) -> None:
        self.turned[idx] = 0

    def evaluate(self):
        t = self.batched.torch
        up = self.sign * self.batched.tensors["xmat"][:, self.chest, 2, 0].to(t.float32)
        angle = t.rad2deg(t.arccos(up.clamp(-1.0, 1.0)))
        u = self.controls.applied
        cost = self.cost_weight * (u * u).sum(1)
        over = angle >= self.success_angle
        self.turned = streak(self.turned, over)
        success = self.turned >= self.hold_steps
        reward = angle / 180.0 + self.over_bonus * over.to(t.float32) - cost
        infos = {"turn_angle": angle, "is_success": success, "control_cost": cost}
        return reward[:, None], t.zeros_like(success), infos


class BatchedCatch(BatchedTask):
    """Catch (:class:`mimo_social.tasks.catch.Catch`): each step the head and eyes fixate the
    ball (:class:`~mimo_social.gpu.gaze.BatchedGaze`, the CPU task's gaze); the body parts
    touching the ball (contacts with ``dist <= 0``) and whether the right hand does; the hand's
    hold count; dropped (the ball ``drop_margin`` below the palm or ``max_distance`` from it:
    ``failure_reward``, the end); success (held ``hold_time`` and not dropped:
    ``success_reward``, with ``pay_remaining`` plus ``contact_reward`` per step left, the end);
    else ``contact_reward`` while touching minus ``cost_weight`` times the actuation's weighted
    effort (muscles: their activations; spring-damper: the applied controls; positional:
    refused). Each world's ball (its radius and mass: the model's fields per world, its start
    above the palm) comes from the CPU reset with the world's seed; ``ball_size`` observed."""

    name = "catch"
    batch_fields = ("geom_size", "geom_rbound", "geom_aabb", "body_mass", "body_inertia")
    info_keys = ("is_success", "dropped", "parts_touching", "held_steps", "ball_radius",
                 "ball_mass")
    observed = ("ball_size",)

    def __init__(self, env, batched):
        super().__init__(env, batched)
        torch = batched.torch
        o = env.task.options
        w = env.world
        m = w.model
        a = w.agents[0]
        dev = batched.qpos.device
        c = batched.contacts
        self.contacts = c
        act = env.actuation[0]
        self.controls = batched.controls[0]
        if self.controls.positional:
            raise ValueError("catch: actuation='positional' does not run on the GPU backend "
                             "(its effort is the servo's); allowed: 'muscle', 'spring_damper'")
        as_t = lambda x: torch.as_tensor(np.asarray(x, np.float32), device=dev)  # noqa: E731
        if self.controls.muscle is not None:
            self.fmax = as_t(act.fmax)
        else:
            self.t_pos, self.t_neg = as_t(act.torque_pos), as_t(act.torque_neg)
        self.ball_body = int(w.prop_bodies["ball"])
        self.ball_geom = int(np.flatnonzero(m.geom_bodyid == self.ball_body)[0])
        self.palm = int(a.palm_sites[0])
        hand = np.zeros(m.ngeom, bool)
        hand[hand_geoms(w, 0, 0)] = True
        mine = np.zeros(m.ngeom, bool)
        mine[a.geom_ids] = True
        self.hand = torch.as_tensor(hand, device=dev)
        self.mine = torch.as_tensor(mine, device=dev)
        self.body_of = torch.as_tensor(m.geom_bodyid.astype(np.int64), device=dev)
        self.nbody = int(m.nbody)
        self.gaze = BatchedGaze(LookAt(w, 0, a.gaze_idx), batched)
        self.opts = o
        self.hold_steps = hold_steps(o.hold_time, env.dt)
        self.max_steps = int(env.max_steps)
        n = batched.nworld
        self.held = torch.zeros(n, dtype=torch.int64, device=dev)
        self.steps = torch.zeros(n, dtype=torch.int64, device=dev)
        self.radius = torch.zeros(n, dtype=torch.float32, device=dev)
        self.mass = torch.zeros(n, dtype=torch.float32, device=dev)

    def capture(self, env) -> dict:
        return {"radius": float(env.task.ball_radius), "mass": float(env.task.ball_mass)}

    def load(self, idx, captured) -> None:
        t = self.batched.torch
        for key, field in (("radius", self.radius), ("mass", self.mass)):
            field[idx] = t.as_tensor(captured[key], device=field.device).to(t.float32)
        self.held[idx] = 0
        self.steps[idx] = 0

    def before_physics(self) -> None:
        self.gaze.fixate(self.ball_body)

    def observe(self) -> list[dict]:
        return [{"ball_size": self.radius[:, None].clone()}]

    def _effort(self):
        """The actuation's weighted effort per world (the CPU model's ``weighted_cost``)."""
        t = self.batched.torch
        if self.controls.muscle is not None:
            a = self.controls.muscle.activation.to(t.float32)
            return (a * a * self.fmax).sum((1, 2)) / (a[0].numel() * self.fmax.sum())
        u = self.controls.applied
        strength = t.where(u >= 0.0, self.t_pos, self.t_neg)
        return (u * u * strength).sum(1) / (u.shape[1] * strength.sum(1))

    def _touching(self):
        """Per world: the infant's body parts touching the ball, and whether the hand does."""
        t = self.batched.torch
        c = self.contacts
        g0, g1 = c.sides()
        on = c.valid() & (c.dist <= 0.0) & ((g0 == self.ball_geom) | (g1 == self.ball_geom))
        other = t.where(g0 == self.ball_geom, g1, g0)
        mine = on & self.mine[other]
        return (c.distinct_per_world(mine, self.body_of[other], self.nbody),
                c.per_world(mine & self.hand[other]))

    def evaluate(self):
        t = self.batched.torch
        o = self.opts
        d = self.batched.tensors
        self.steps += 1
        n_touch, in_hand = self._touching()
        self.held = streak(self.held, in_hand)
        ball = d["xpos"][:, self.ball_body].to(t.float32)
        palm = d["site_xpos"][:, self.palm].to(t.float32)
        dropped = (ball[:, 2] < palm[:, 2] - o.drop_margin) | (
            t.linalg.vector_norm(ball - palm, dim=1) > o.max_distance)
        success = ~dropped & (self.held >= self.hold_steps)
        left = (self.max_steps - self.steps + 1).clamp(min=0) if o.pay_remaining \
            else t.zeros_like(self.steps)
        reward = t.where(dropped, t.full_like(ball[:, 0], o.failure_reward), t.where(
            success, o.success_reward + o.contact_reward * left.to(t.float32),
            o.contact_reward * (n_touch > 0).to(t.float32) - o.cost_weight * self._effort()))
        infos = {"is_success": success, "dropped": dropped, "parts_touching": n_touch,
                 "held_steps": self.held, "ball_radius": self.radius, "ball_mass": self.mass}
        return reward[:, None], success | dropped, infos
