"""Task logic for every world at once: rewards, success, terminations and the task's infos,
computed from the batched device data (torch tensors) as the CPU task computes them from
``MjData``, with the task's per-step state (a hold timer) as a per-world tensor
(:mod:`mimo_social.gpu.task_base`: the protocol each class follows).

One small class per task, in :data:`TASKS` by task name; :func:`batched_task` makes the one of a
CPU env's task, or raises a ValueError naming the task and those that run on the device. Free
play, reach, the high five and self-body are here; stand-up, roll-over and catch in
:mod:`mimo_social.gpu.motor_tasks`.
"""

from __future__ import annotations

import numpy as np

from ..core.kinematics import hand_geoms
from ..tasks.common import right_hand_parts
from ..tasks.high_five.task import PALM_COS
from .motor_tasks import BatchedCatch, BatchedRollOver, BatchedStandup
from .task_base import BatchedTask, hold_steps, streak

__all__ = ["TASKS", "BatchedTask", "BatchedFreePlay", "BatchedReach", "BatchedHighFive",
           "BatchedSelfBody", "BatchedStandup", "BatchedCatch", "BatchedRollOver", "batched_task",
           "task_class"]


class BatchedFreePlay(BatchedTask):
    """Free play (:class:`mimo_social.tasks.free_play.FreePlay`): no reward (0 for every
    agent), no termination (truncation at the env's time limit), no infos."""

    name = "free_play"

    def evaluate(self):
        t = self.batched.torch
        dev = self.batched.qpos.device
        n = self.batched.nworld
        return (t.zeros((n, self.n_agents), dtype=t.float32, device=dev),
                t.zeros(n, dtype=t.bool, device=dev), {})


class BatchedReach(BatchedTask):
    """Reach (:class:`mimo_social.tasks.reach.Reach`): ``+success_reward`` on the step a
    geom of the right hand touches the ball (``dist <= 0``), else minus the right fingertips'
    distance to the ball's centre; success ends the episode. The reset's ball (the model's
    ``body_pos`` of the ball, per world) and head and eye angles (set by the task every control
    step, with their speeds zeroed: the ball is held in place, so the angles of the reset)
    come from the CPU env reset with the world's seed."""

    name = "reach"
    batch_fields = ("body_pos",)
    info_keys = ("is_success", "distance")
    per_agent_infos = ()

    def __init__(self, env, batched):
        super().__init__(env, batched)
        torch = batched.torch
        w = env.world
        m = w.model
        a = w.agents[0]
        self.contacts = batched.contacts
        self.success_reward = float(env.task.options.success_reward)
        self.hand = self.contacts.mask(hand_geoms(w, 0))
        self.ball_geom = self.contacts.mask([m.geom("ball").id])
        self.ball_body = int(w.prop_bodies["ball"])
        self.tip = int(a.fingertip_sites[0])
        dev = batched.qpos.device
        self.gaze_qpos = torch.as_tensor(a.qpos_adr[a.gaze_idx].astype(np.int64), device=dev)
        self.gaze_dof = torch.as_tensor(a.dof_adr[a.gaze_idx].astype(np.int64), device=dev)
        self._gaze_np = a.qpos_adr[a.gaze_idx]
        self.gaze = torch.zeros((batched.nworld, len(self._gaze_np)), dtype=torch.float32,
                                device=dev)

    def capture(self, env) -> dict:
        return {"gaze": env.world.data.qpos[self._gaze_np].copy()}

    def load(self, idx, captured) -> None:
        t = self.batched.torch
        self.gaze[idx] = t.as_tensor(captured["gaze"], device=self.gaze.device).to(t.float32)

    def before_physics(self) -> None:
        data = self.batched.tensors
        data["qpos"][:, self.gaze_qpos] = self.gaze.to(data["qpos"].dtype)
        data["qvel"][:, self.gaze_dof] = 0.0

    def evaluate(self):
        t = self.batched.torch
        data = self.batched.tensors
        touched = self.contacts.per_world(self.contacts.between(self.hand, self.ball_geom))
        dist = t.linalg.vector_norm(data["site_xpos"][:, self.tip]
                                    - data["xpos"][:, self.ball_body], dim=1)
        reward = t.where(touched, t.full_like(dist, self.success_reward), -dist)
        return reward[:, None], touched, {"is_success": touched, "distance": dist}


class BatchedHighFive(BatchedTask):
    """High five (:class:`mimo_social.tasks.high_five.HighFive`), ``success="palms"`` or
    ``"touch"``: each step, both right hands feel the other agent (a contact of the other's
    geoms with the hand, ``dist <= 0``, and one of a skinned right-hand part with a geom of the
    other agent pushing with a positive normal force: the skin's rule), the two right hands
    touch, and (``"palms"``) one contact between them has its normal within 60 deg of each
    hand's palm normal; ``hold_time`` of it in a row (a per-world step count) is the success.
    Reward (both agents): ``-distance(right palms)`` with ``shaping``, plus ``touch_bonus`` on a
    step of success; success ends the episode when ``end_on_touch``. ``assisted_gaze`` (the
    head turned to the partner's hand every step) is not batched: refused."""

    name = "high_five"
    info_keys = ("is_success", "hands_touching", "hand_feels_partner", "hand_distance",
                 "palm_contact", "palm_contact_time")
    per_agent_infos = ("hand_feels_partner",)

    def __init__(self, env, batched):
        super().__init__(env, batched)
        torch = batched.torch
        opts = env.task.options
        if opts.assisted_gaze:
            raise ValueError("high_five: task option assisted_gaze=True does not run on the GPU "
                             "backend (the head and eyes follow the partner's hand by inverse "
                             "kinematics on the CPU); allowed: assisted_gaze=False")
        w = env.world
        m = w.model
        c = batched.contacts
        self.contacts = c
        self.touch_bonus = float(opts.touch_bonus)
        self.end_on_touch = bool(opts.end_on_touch)
        self.shaping = bool(opts.shaping)
        self.touch_rule = opts.success == "touch"
        self.dt = float(env.dt)
        self.hold_steps = hold_steps(opts.hold_time, env.dt)
        dev = batched.qpos.device
        hands = [hand_geoms(w, i) for i in range(2)]
        self.hands = [c.mask(h) for h in hands]
        geom_agent = np.asarray(w.geom_agent)
        self.agent_geoms = [c.mask(np.flatnonzero(geom_agent == i)) for i in range(2)]
        touch = env.systems.get("touch")
        part = np.asarray(touch.geom_part[:m.ngeom])
        skinned = []
        for i in range(2):
            parts = set(right_hand_parts(w.tables[i]))
            keep = [g for g in range(m.ngeom) if part[g] >= 0
                    and int(touch.part_agent[part[g]]) == i
                    and touch.part_names[part[g]] in parts]
            skinned.append(c.mask(keep))
        self.skinned = skinned
        hand_of = np.full(m.ngeom, -1, np.int64)
        for i in range(2):
            hand_of[hands[i]] = i
        self.hand_of = torch.as_tensor(hand_of, device=dev)
        palms = [int(w.agents[i].palm_sites[0]) for i in range(2)]
        self.palms = torch.as_tensor(palms, device=dev)
        self.hand_bodies = torch.as_tensor([int(m.site_bodyid[p]) for p in palms], device=dev)
        self.held = torch.zeros(batched.nworld, dtype=torch.int64, device=dev)

    def load(self, idx, captured) -> None:
        self.held[idx] = 0

    def _feels(self, i: int, normal):
        """Whether agent i's right hand feels the other agent, per world."""
        c = self.contacts
        j = 1 - i
        probe = c.per_world(c.between(self.hands[i], self.agent_geoms[j]))
        skin = c.between(self.skinned[i], self.agent_geoms[j], touching=False) & (normal > 0.0)
        return probe & c.per_world(skin)

    def _palms_meet(self):
        t = self.batched.torch
        c = self.contacts
        g0, g1 = c.sides()
        o0, o1 = self.hand_of[g0], self.hand_of[g1]
        keep = c.valid() & (o0 >= 0) & (o1 >= 0) & (o0 != o1) & (c.dist <= 0.0)
        # each contact's normal from infant_0's hand into infant_1's
        normal = c.frame[:, 0, :] * t.where(o0 == 0, 1.0, -1.0)[:, None]
        palms = -self.batched.tensors["xmat"][:, self.hand_bodies, :, 1]   # (nworld, 2, 3)
        p = c.in_world(palms)
        hit = keep & ((normal * p[:, 0]).sum(-1) >= PALM_COS) \
            & ((normal * p[:, 1]).sum(-1) <= -PALM_COS)
        return c.per_world(hit)

    def evaluate(self):
        t = self.batched.torch
        data = self.batched.tensors
        p = data["site_xpos"][:, self.palms]
        dist = t.linalg.vector_norm(p[:, 0] - p[:, 1], dim=1)
        normal = self.contacts.normal_forces()
        felt = t.stack([self._feels(0, normal), self._feels(1, normal)], dim=1)
        meet = felt[:, 0] & felt[:, 1] & self.contacts.per_world(
            self.contacts.between(self.hands[0], self.hands[1]))
        palm_contact = meet & self._palms_meet()
        self.held = streak(self.held, palm_contact)
        touching = meet if self.touch_rule else self.held >= self.hold_steps
        r = (-dist if self.shaping else t.zeros_like(dist)) + self.touch_bonus * touching
        terminated = touching & self.end_on_touch
        infos = {"is_success": touching, "hands_touching": touching,
                 "hand_feels_partner": felt, "hand_distance": dist,
                 "palm_contact": palm_contact, "palm_contact_time": self.held * self.dt}
        return t.stack([r, r], dim=1), terminated, infos


class BatchedSelfBody(BatchedTask):
    """Self-body (:class:`mimo_social.tasks.selfbody.SelfBody`): the right hand presses on the
    body's own primitives (a contact of a right-hand geom with another geom of the infant,
    ``dist <= 0``, a positive normal force). Success: it presses the episode's target primitive
    and the target's body part feels a touch by the infant itself (a contact on a skinned geom
    of that part with another geom of the infant pushing with a positive normal force: the
    skin's rule, :meth:`~mimo_social.senses.touch.TouchSystem.touched_by`), ending the episode
    with ``success_reward``; else minus (``other_touch_cost`` + the nearest pressing contact
    point's distance to the target primitive's centre), or ``miss_reward`` when the hand
    presses nothing. The target, drawn by the CPU reset, is observed as its one-hot
    ``target``; infos: ``is_success``, ``target`` (its index in the task's ``targets``),
    ``distance`` (NaN without a pressing contact, the CPU's None) and ``touched`` (how many
    primitives the hand presses)."""

    name = "selfbody"
    info_keys = ("is_success", "target", "distance", "touched")
    observed = ("target",)

    def __init__(self, env, batched):
        super().__init__(env, batched)
        torch = batched.torch
        task = env.task
        opts = task.options
        w = env.world
        m = w.model
        a = w.agents[0]
        c = batched.contacts
        dev = batched.qpos.device
        self.contacts = c
        self.success_reward = float(opts.success_reward)
        self.miss_reward = float(opts.miss_reward)
        self.other_touch_cost = float(opts.other_touch_cost)
        hand = np.zeros(m.ngeom, bool)
        hand[hand_geoms(w, 0, 0)] = True
        own = np.zeros(m.ngeom, bool)
        own[a.geom_ids] = True
        self.hand = torch.as_tensor(hand, device=dev)
        self.own = torch.as_tensor(own & ~hand, device=dev)
        self.agent = torch.as_tensor(own, device=dev)
        names = [f"{a.name}/{t}" for t in task.targets]
        geoms = np.array([m.geom(n).id for n in names], np.int64)
        self.target_geoms = torch.as_tensor(geoms, device=dev)
        # per target: the skinned geoms of its body part (the skin's sides: touched_by)
        skin = np.asarray(env.systems["touch"].geom_part[:m.ngeom]) >= 0
        body = np.asarray(m.geom_bodyid)
        parts = (body[None, :] == body[geoms][:, None]) & skin
        self.part_geoms = torch.as_tensor(parts, device=dev)
        self.ntargets = len(geoms)
        self.target = torch.zeros(batched.nworld, dtype=torch.int64, device=dev)

    def capture(self, env) -> dict:
        return {"target": env.task.targets.index(env.task.target)}

    def load(self, idx, captured) -> None:
        t = self.batched.torch
        self.target[idx] = t.as_tensor(captured["target"], device=self.target.device).to(
            t.int64)

    def observe(self) -> list[dict]:
        t = self.batched.torch
        return [{"target": t.nn.functional.one_hot(self.target, self.ntargets).to(t.float32)}]

    def evaluate(self):
        t = self.batched.torch
        c = self.contacts
        data = self.batched.tensors
        n = self.batched.nworld
        g0, g1 = c.sides()
        world = c.worldid.long().clamp(0, n - 1)
        fn = c.normal_forces()
        h0, h1 = self.hand[g0], self.hand[g1]
        other = t.where(h0, g1, g0)
        pressed = (h0 ^ h1) & self.own[other] & c.valid() & (c.dist <= 0.0) & (fn > 0.0)
        target = self.target[world]
        on_target = pressed & (other == self.target_geoms[target])
        felt = c.valid() & (fn > 0.0) & ((self.part_geoms[target, g0] & self.agent[g1])
                                         | (self.part_geoms[target, g1] & self.agent[g0]))
        success = c.per_world(on_target) & c.per_world(felt)
        centre = data["geom_xpos"][world, self.target_geoms[target]]
        dist = t.linalg.vector_norm(c.pos - centre, dim=1)
        inf = float("inf")
        nearest = t.full((n,), inf, dtype=dist.dtype, device=dist.device).scatter_reduce(
            0, world, dist.masked_fill(~pressed, inf), reduce="amin")
        any_pressed = t.isfinite(nearest)
        touched = c.distinct_per_world(pressed, other, c.ngeom)
        reward = t.where(success, t.full_like(nearest, self.success_reward),
                         t.where(any_pressed, -(self.other_touch_cost + nearest),
                                 t.full_like(nearest, self.miss_reward)))
        distance = t.where(success, t.zeros_like(nearest),
                           t.where(any_pressed, nearest, t.full_like(nearest, float("nan"))))
        infos = {"is_success": success, "target": self.target, "distance": distance,
                 "touched": touched}
        return reward[:, None], success, infos


#: the batched task logic by task name
TASKS = {"free_play": BatchedFreePlay, "reach": BatchedReach, "high_five": BatchedHighFive,
         "selfbody": BatchedSelfBody, "standup": BatchedStandup, "catch": BatchedCatch,
         "rollover": BatchedRollOver}


def task_class(name: str):
    """The batched logic class of task ``name`` (:data:`TASKS`), or a ValueError naming the
    task and the tasks that run on the device."""
    if name not in TASKS:
        raise ValueError(f"task {name!r} has no batched task logic on the GPU backend (rewards, "
                         f"success, resets); allowed: {', '.join(sorted(TASKS))}")
    return TASKS[name]


def batched_task(env, batched):
    """The batched logic of ``env``'s task (:func:`task_class`), bound to ``batched``."""
    return task_class(env.task.name)(env, batched)
