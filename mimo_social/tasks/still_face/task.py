"""The still_face task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ...body.joint_groups import GAZE_JOINTS, held_posture
from ...body.postures import posture_joints
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup
from ...expressions.faces import EXPRESSIONS
from ...partners.cues import learner_cues
from ...util.checks import ConfigError
from ..common import face_to_face
from ..dyad import held_angles, tables_of, task_plan
from ...core.factory import make_aec, make_parallel, with_options
from ...partners.wrapper import ScriptedPartners

__all__ = ["PHASES", "MEASURES", "LEARNER_ARM_JOINTS", "StillFace", "StillFaceOptions",
           "self_touch_geoms", "parallel_env",
           "env", "scripted_env", "PhasedPartners"]

PHASES = ("interaction", "still", "reunion")
#: the per-phase measures: info key prefix -> what it counts
MEASURES = {"smile": "smiling", "gaze": "gaze_on_face", "self_touch": "self_touch"}
DISTANCE = 0.6
EYE_SIZE = 64
DEFAULT_DT = 0.01       # the default physics (5 ms x 2): the default max_steps
HAPPY = EXPRESSIONS.index("happy")
NEUTRAL = EXPRESSIONS.index("neutral")
#: the learner's free arm joints with ``arms_free``: both shoulders and elbows
LEARNER_ARM_JOINTS = ("right_shoulder_horizontal", "right_shoulder_abduction",
                      "right_shoulder_rotation", "right_elbow",
                      "left_shoulder_horizontal", "left_shoulder_abduction",
                      "left_shoulder_rotation", "left_elbow")
#: the caregiver's free arm joints: the right shoulder, elbow and wrist
CAREGIVER_ARM_JOINTS = ("right_shoulder_horizontal", "right_shoulder_abduction",
                        "right_shoulder_rotation", "right_elbow", "right_wrist_rotation",
                        "right_wrist_flexion", "right_wrist_ulnar")
#: the parts a hand may touch for self-directed behaviour (with the other arm and hand)
SELF_PARTS = ("head", "upper_body", "lower_body")


@dataclass(frozen=True)
class StillFaceOptions(TaskOptions):
    """The phases' lengths (s: interaction, still face, reunion) and the spread of the first two
    (``phase_jitter``: each drawn at reset within +- that share), the standard pair's distance
    (m), whether the learner's head and eyes are free (else held on the caregiver's face) and
    whether its arms are, head support, the cost of a smiling step that is
    not engaged, the share of interactive steps that must be engaged and the share of the
    learner's smiling steps that must be engaged for success, the reward of a still-phase step
    with the classic response, whether the caregiver talks (``caregiver_speech``: it has a
    voice, the learner ears; silent in the still face), reward-free mode and whether the
    caregiver (``caregiver_0``) is scripted (no eyes, no reward)."""

    task = "still_face"
    phases_s: tuple = (5.0, 5.0, 5.0)
    phase_jitter: float = 0.5
    distance: float = DISTANCE
    gaze_free: bool = True
    arms_free: bool = True
    head_support: bool = True
    unshared_cost: float = 1.0
    success_fraction: float = 0.8
    success_match: float = 0.8
    still_response_reward: float = 0.0
    caregiver_speech: bool = False
    reward_free: bool = False
    scripted_partner: bool = False

    def __post_init__(self):
        self._numbers("phases_s", 3, 0.05, 600.0,
                      allowed="(interaction, still, reunion) seconds, each 0.05 to 600")
        self._number("phase_jitter", 0.0, 0.9)
        self._number("distance", 0.3, 1.5)
        self._bool("gaze_free")
        self._bool("arms_free")
        self._bool("head_support")
        self._number("unshared_cost", 0.0, 10.0)
        self._number("success_fraction", 0.05, 1.0)
        self._number("success_match", 0.0, 1.0)
        self._number("still_response_reward", 0.0, 10.0)
        self._bool("caregiver_speech")
        self._bool("reward_free")
        self._bool("scripted_partner")
        if self.still_response_reward > 0 and not self.arms_free:
            raise ConfigError(
                f"{self.task}: task option still_response_reward={self.still_response_reward!r} "
                "pays the still-phase response, which needs self-touch, with arms_free=False; "
                "allowed: still_response_reward=0 or arms_free=True")


def self_touch_geoms(world, i: int) -> tuple[np.ndarray, np.ndarray]:
    """Agent ``i``'s geoms for self-touch: per hand (right, left) the hand's geoms, and the
    geoms each may touch (its head, trunk and the other arm and hand), as a pair of index arrays
    ``hands`` (n,) and ``allowed`` (n, ngeom) masks."""
    m = world.model
    a = world.agents[i]
    body_of = {m.body(b).name.split("/", 1)[-1]: int(b) for b in a.body_ids}
    parent = m.body_parentid

    def subtree_geoms(root: str) -> np.ndarray:
        inside = np.zeros(m.nbody, bool)
        inside[body_of[root]] = True
        for b in sorted(a.body_ids.tolist()):
            if inside[parent[b]]:
                inside[b] = True
        return a.geom_ids[inside[m.geom_bodyid[a.geom_ids]]]

    trunk = np.concatenate([subtree_geoms(p) if p == "head" else
                            a.geom_ids[m.geom_bodyid[a.geom_ids] == body_of[p]]
                            for p in SELF_PARTS])
    hands, masks = [], []
    for side, other in (("right", "left"), ("left", "right")):
        hand = subtree_geoms(f"{side}_hand")
        mask = np.zeros(m.ngeom, bool)
        mask[trunk] = True
        mask[subtree_geoms(f"{other}_upper_arm")] = True
        hands.append(hand)
        masks.append(mask)
    return hands, masks


class StillFace(Task):
    name = "still_face"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 1500
    Options = StillFaceOptions

    def __init__(self, n_agents: int, options=None, /, **values):
        super().__init__(n_agents, options, **values)
        self.default_max_steps = max(1, int(round(sum(self.options.phases_s) / DEFAULT_DT)))
        self.phase = 0            # the phase of the last step (0 at reset)
        self._bounds = None

    def agent_defaults(self, i, settings):
        speech = self.options.caregiver_speech
        if i == 0:
            return {"posture": "sitting", "expressions": True, "vestibular": False,
                    "vision": {"width": EYE_SIZE, "height": EYE_SIZE}, "audition": speech}
        scripted = self.options.scripted_partner
        return {"body": "adult", "posture": "kneeling", "expressions": True,
                "vestibular": False, "voice": speech,
                "audition": speech and not scripted,
                "vision": False if scripted else {"width": EYE_SIZE, "height": EYE_SIZE}}

    def _free(self, i, config) -> tuple[str, ...]:
        if i == 0:
            return (GAZE_JOINTS if self.options.gaze_free else ()) + \
                (LEARNER_ARM_JOINTS if self.options.arms_free else ())
        return GAZE_JOINTS + CAREGIVER_ARM_JOINTS

    def held_joints(self, i, config):
        """Agent i's held joints (rad): all but its free ones, sitting (or its own posture)."""
        angles = held_angles(config, "sitting", posture_joints("sitting", config.body))
        return held_posture(tables_of(config), keep=self._free(i, config), angles=angles)

    def setup(self, i, config):
        # a held gaze (gaze_free off): the learner's head and eyes aimed at the caregiver's face
        look = () if self.options.gaze_free else (0,)
        plan = task_plan(self, "sitting", self.options.distance, self.held_joints, look)
        pos, facing = face_to_face(i, plan.distance)
        free = self._free(i, config)
        aimed = {k: v for k, v in plan.gaze[i].items() if k not in free}
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen={**self.held_joints(i, config), **aimed}, base="fixed",
                          actuated=free)

    # -- phases ---------------------------------------------------------------------------------
    def phase_steps(self, dt: float) -> tuple[int, int, int]:
        """Control steps of each phase at control step ``dt`` (s), as ``phases_s`` says (before
        ``phase_jitter``: :attr:`episode_phase_steps` are this episode's)."""
        return tuple(max(1, int(round(s / dt))) for s in self.options.phases_s)

    def phase_at(self, step: int) -> int:
        """The phase index of control step ``step`` (0-based; past the last phase: reunion) in
        this episode (its phase lengths are drawn at reset)."""
        b = self._bounds
        return 0 if step < b[0] else (1 if step < b[1] else 2)

    def _draw_phases(self, env, rng) -> None:
        """This episode's phase lengths: interaction and still face each ``phases_s`` times a
        uniform draw within 1 +- ``phase_jitter`` (none at 0), reunion as set; the interactive
        steps within ``max_steps`` and the engaged steps success needs."""
        steps = list(self.phase_steps(env.dt))
        j = self.options.phase_jitter
        if j > 0:
            for k in (0, 1):
                steps[k] = max(1, int(round(steps[k] * rng.uniform(1.0 - j, 1.0 + j))))
        #: this episode's control steps per phase
        self.episode_phase_steps = tuple(steps)
        self._bounds = (steps[0], steps[0] + steps[1])
        still = max(0, min(env.max_steps, self._bounds[1]) - min(env.max_steps, self._bounds[0]))
        self._n_inter = env.max_steps - still
        self._need = max(1, math.ceil(self.options.success_fraction * self._n_inter - 1e-9))

    @property
    def phase_name(self) -> str:
        return PHASES[self.phase]

    # -- running ----------------------------------------------------------------------------------
    def bind(self, env):
        """Index tables of this world (once per world: :meth:`Task.bind`)."""
        w = env.world
        m = w.model
        self._bounds = tuple(np.cumsum(self.phase_steps(env.dt))[:2].tolist())   # until reset
        self._head_dofs = np.concatenate([
            a.dof_adr[[k for k in a.actuated_joint_idx if a.joint_names[k] in GAZE_JOINTS]]
            for a in w.agents])
        c = w.agents[1]
        k = c.actuated_joint_idx
        self._care_qpos, self._care_dof = c.qpos_adr[k], c.dof_adr[k]
        hands, masks = self_touch_geoms(w, 0)
        self._hand_mask = np.zeros((2, m.ngeom), bool)
        for s in range(2):
            self._hand_mask[s, hands[s]] = True
        self._touch_mask = np.stack(masks)
        scripted = self.options.scripted_partner
        self._weights = np.array([1.0, 0.0 if scripted else 1.0])

    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        del m
        self._draw_phases(env, rng)
        self.phase = 0
        self._held_q = None
        self._counts = np.zeros((3, 3), np.int64)     # phase x measure (smile, gaze, touch)
        self._steps = np.zeros(3, np.int64)
        self._engaged_steps = 0
        self._inter_steps = 0
        self._now = (False, False, False, False, False)
        d.qfrc_applied[self._care_dof] = 0.0

    def before_physics(self, env):
        w = env.world
        d = w.data
        self.phase = self.phase_at(env.steps)
        if self.options.head_support:
            d.qfrc_applied[self._head_dofs] = d.qfrc_bias[self._head_dofs]
        if self.phase == 1:
            self._hold_caregiver(env)
        elif self._held_q is not None:    # the still phase is over: the caregiver moves again
            self._held_q = None
            d.qfrc_applied[self._care_dof] = 0.0
            if self.options.head_support:
                d.qfrc_applied[self._head_dofs] = d.qfrc_bias[self._head_dofs]

    def _hold_caregiver(self, env):
        """The still face: neutral, the free joints held at the phase's first angles."""
        w = env.world
        m, d = w.model, w.data
        if self._held_q is None:
            self._held_q = d.qpos[self._care_qpos].copy()
        w.set_expression(1, NEUTRAL)
        env.mute(1)                           # silent as well as still
        d.qpos[self._care_qpos] = self._held_q
        d.qvel[self._care_dof] = 0.0
        mujoco.mj_forward(m, d)               # gravity and contacts of the held state
        act = env.actuation[1]
        if hasattr(act, "controls_for"):      # positional: the held angles are the targets,
            # offset by the gravity torque over the servo's stiffness (no sag)
            target = self._held_q + d.qfrc_bias[self._care_dof] / np.maximum(act.kp, 1e-9)
            u = np.clip(2.0 * (target - act.lo) / (act.hi - act.lo) - 1.0, -1.0, 1.0)
            d.qfrc_applied[self._care_dof] = 0.0
        else:                                 # torques: none; gravity and springs cancelled
            u = np.zeros(act.n_controls)
            d.qfrc_applied[self._care_dof] = (d.qfrc_bias[self._care_dof]
                                              - d.qfrc_spring[self._care_dof])
        env.controls[1][:] = u
        act.apply(m, d, env.controls[1])

    def _self_touch(self, d) -> bool:
        n = d.ncon
        if n == 0:
            return False
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        on = c.dist[:n] <= 0.0
        h, t = self._hand_mask, self._touch_mask
        hit = (h[:, g1] & t[:, g2]) | (h[:, g2] & t[:, g1])
        return bool(np.any(hit & on))

    def rewards(self, env):
        w = env.world
        names = env.possible_agents
        cues = learner_cues(env, names[0], names[1])
        smiling = bool(cues.smiling)
        gaze = bool(cues.gaze_on_face)
        touch = self._self_touch(w.data)
        engaged = gaze and smiling and w.expression_of(1) == HAPPY and self.phase != 1
        p = self.phase
        # the classic still-face response: sober, gaze averted, self-comforting
        response = p == 1 and touch and not smiling and not gaze
        self._steps[p] += 1
        self._counts[p] += (smiling, gaze, touch)
        if p != 1:
            self._inter_steps += 1
            self._engaged_steps += int(engaged)
        self._now = (smiling, gaze, touch, engaged, response)
        if self.options.reward_free:
            return np.zeros(2)
        out = self._weights * float(engaged)
        # the infant's own: its smiling into a face that does not smile back (or while looking
        # away) costs, the classic still-phase response may pay
        out[0] += self.options.still_response_reward * float(response) \
            - self.options.unshared_cost * float(smiling and not engaged)
        return out

    def succeeded(self) -> bool:
        """The verdict so far (the task table's success row): enough interactive steps engaged,
        and enough of the learner's smiling steps engaged."""
        engaged = self._engaged_steps
        return engaged >= self._need and \
            engaged >= self.options.success_match * int(self._counts[:, 0].sum())

    def plots(self):
        """Reward, the phase (0 interaction, 1 still face, 2 reunion), the learner's smile and
        gaze on the caregiver's face, and engagement (what is rewarded)."""
        nan = float("nan")
        return [Plot.reward(),
                Plot("phase", "0 play, 1 still, 2 reunion", lambda env: self.phase,
                     per_agent=False),
                Plot("smiling", "0/1", lambda env: (self._now[0], nan), agents=(0,)),
                Plot("gaze_on_face", "0/1", lambda env: (self._now[1], nan), agents=(0,)),
                Plot("engaged", "0/1", lambda env: self._now[3], per_agent=False)]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        keys = ["phase", "smiling", "gaze_on_face", "self_touch", "engaged", "still_response",
                "engaged_steps", "interactive_steps", "matched_fraction", "is_success"]
        keys += [f"{k}_{p}" for p in PHASES for k in MEASURES]
        return {k: "number" for k in keys}

    def _info(self) -> dict:
        smiling, gaze, touch, engaged, response = self._now
        out = {"phase": int(self.phase), "smiling": smiling, "gaze_on_face": gaze,
               "self_touch": touch, "engaged": engaged, "still_response": response,
               "engaged_steps": int(self._engaged_steps),
               "interactive_steps": int(self._inter_steps),
               "matched_fraction": self._engaged_steps / max(1, int(self._counts[:, 0].sum())),
               "is_success": self.succeeded()}
        frac = self._counts / np.maximum(self._steps, 1)[:, None]
        for p, phase in enumerate(PHASES):
            for k, key in enumerate(MEASURES):
                out[f"{key}_{phase}"] = float(frac[p, k])
        return out

    def terminations(self, env):
        info = self._info()
        return np.zeros(2, bool), [info, dict(info)]


# -- the env factories (``mimo_social.envs.still_face_v0`` re-exports them) ---------------

MODES = {"interaction": "interactive", "still": "still", "reunion": "interactive"}


def parallel_env(**kwargs):
    return make_parallel(StillFace, **kwargs)


def env(**kwargs):
    return make_aec(StillFace, **kwargs)


class PhasedPartners(ScriptedPartners):
    """:class:`~mimo_social.partners.wrapper.ScriptedPartners` that, before each step (and at
    reset), sets every partner with a ``set_mode`` method to the mode of the step's phase
    (:data:`MODES`), when it changes (a partner's ``mode`` attribute, where it has one, is
    its mode after its reset)."""

    def _sync(self):
        inner = self.env.unwrapped
        mode = MODES[PHASES[inner.task.phase_at(inner.steps)]]
        for name, partner in self.partners.items():
            if callable(getattr(partner, "set_mode", None)) and self._modes.get(name) != mode:
                partner.set_mode(mode)
                self._modes[name] = mode

    def reset(self, seed=None, options=None):
        out = super().reset(seed=seed, options=options)
        self._modes = {name: getattr(p, "mode", None) for name, p in self.partners.items()}
        self._sync()
        return out

    def step(self, actions):
        if self.__dict__.get("_seeds") is not None and self.env.agents:
            self._sync()
        return super().step(actions)


def scripted_env(partner=None, **kwargs):
    options = with_options(StillFace, kwargs.pop("task_options", None), scripted_partner=True)
    if partner is None:
        from ...partners.contingent import ContingentCaregiver
        partner = ContingentCaregiver()
    penv = parallel_env(task_options=options, **kwargs)
    # the partner: the second agent (caregiver_0 when it is the adult)
    return PhasedPartners(penv, {penv.possible_agents[1]: partner})
