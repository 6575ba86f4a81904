"""Still face: face-to-face play, then the caregiver's still, unresponsive face, then reunion.

| | |
|---|---|
| agents | 2: `infant_0` (the learner infant) and `infant_1` (the caregiver: by default the adult body kneeling, `body="adult"`, `posture="kneeling"`; an infant partner is allowed, e.g. `per_agent=[{}, {"body": "infant", "posture": "sitting"}]`); scripted (`scripted_env`: by default a `ContingentCaregiver`, `partners/contingent.py`) or a second learner |
| body | the learner sits (the infant seat of the paradigm), hip fixed in the world, every joint held except head and eyes (9 motors) and, with `arms_free` (on), both shoulders and elbows (8 motors): it can look at or away from the caregiver and bring its hands to its own body (self-directed behaviour); without `arms_free` no self-touch is possible. The caregiver holds its posture (legs, trunk) and moves its head and eyes and its right arm (shoulder, elbow, wrist: 7 motors; its fingers held), as `ContingentCaregiver` needs (its gaze response and its pat). Both have faces (expressions on). With `head_support` (on) the task cancels gravity on both agents' head and eye joints (neck tone: a zero action does not let the head drop) |
| scene | the pair face to face; two sitting 18-month-olds `distance` (0.6 m) apart, their feet just short of each other (at 0.45 m the scripted infant's hands caught on the partner's toes on their way to its chest); other bodies placed by measured reach (`tasks/dyad.py`): the kneeling adult's hip 1.01 m from the infant's, at arm's length, its eyes (1.13 m high) 1.0 m from the sitting infant's (0.42 m high), 45 degrees above them; its head (0.18 m across) spans 10 degrees, 11 pixels of a 64x64 eye (60 degree field; `per_agent=[{"vision": {"width": 128, "height": 128}}, {}]` doubles it). Closer, the adult's face would be nearly overhead (the "gap" law of `tasks/dyad.py`: 0.61 m, 67 degrees up) |
| phases | `phases_s` = (interaction, still face, reunion) seconds, default (5, 5, 5): phase k lasts `round(phases_s[k] / dt)` control steps (dt 0.01 s: 500 each); `max_steps` defaults to their sum at the default dt (1500; steps past the last phase stay in reunion). Laboratory phases last 1-2 min (Mesman et al. 2009); seconds here keep episodes short enough to train. Interaction and reunion: the caregiver acts; the scripted form sets a caregiver with `set_mode` to `"interactive"`. Still face: the scripted form sets it to `"still"`, and the task holds the caregiver still whoever drives it (a script or a second learner, whose actions are then ignored): its face shown neutral, its free joints written back to the angles they had when the phase began and their velocities zeroed every control step, its controls replaced by ones that hold (spring-damper: none, gravity and springs cancelled by applied forces; positional: the held angles plus the gravity torque over the servo stiffness). Measured: no free joint of the caregiver moves more than 1e-3 rad in the still phase (tests/tasks/test_still_face.py, spring-damper and positional, random caregiver actions) |
| reset | heads and eyes at rest: the learner's line of sight passes 51 degrees below the caregiver's face (it sees the caregiver's trunk and thighs, the face above its view), so a still learner does not look at the face; both faces neutral; arms at their sitting rest. Nothing in the task is random (the scripted caregiver draws whether it answers each cue; with its defaults, `probability` 1, it always does) |
| action | learner: `Dict(motors=Box(-1, 1, (17,)), expression=Discrete(7))` (9 head and eye motors, then the 8 arm motors; 9 without `arms_free`); caregiver (two learners): its 16 motors and expression |
| observation | `eye_left`, `eye_right` (64x64x3 RGB: the only way the caregiver's face and movements reach the learner), `proprioception` (102 floats: its own free joints); a scripted caregiver has no eyes; never the phase, nor the caregiver's expression or mode |
| measures | per learner step, from `learner_cues` (`partners/cues.py`, the same cues the contingent caregiver answers): `smiling` (its face is "happy": positive expression), `gaze_on_face` (its line of sight passes within 10 degrees of the caregiver's face centre), and `self_touch` (self-directed behaviour: a contact between a hand of the learner and its own head, trunk or other arm and hand; a hand on its legs or hip does not count, nor a touch by or of the caregiver); per phase, so far this episode, the fraction of that phase's steps with each: `smile_<phase>`, `gaze_<phase>`, `self_touch_<phase>` (phases `interaction`, `still`, `reunion`), and `phase` (0, 1, 2: the step's phase, names in `PHASES`). `still_face_summary(infos)` (this module) gives their mean and spread over episodes from each episode's last info; `format_still_face_summary` prints it |
| reward | a social reward, +1 on a step of mutual engagement: the learner looks at the caregiver's face while both smile (the learner's and the caregiver's face "happy"), else 0. The still phase pays nothing (the caregiver's face is held neutral). The default caregiver smiles back 0.5 s after each onset of the learner's smile, for 1 s: a smile held without renewal is answered once, so engagement needs renewed bids, as in a real exchange. Two learners both get it (cooperative); with `scripted_partner` only `infant_0`. `reward_free` (off): every reward 0, the measures unchanged (for a learning signal of one's own: curiosity, contingency detection) |
| success | per episode: the engaged steps reach `success_fraction` (0.5) of the episode's interaction and reunion steps (within `max_steps`: 1000 by default); `is_success` turns True on the step from which the episode can no longer fail, the last step's value is the verdict. Success measures engagement in the interactive phases; the still phase is where the measures show the still-face effect, not a test |
| termination | none; truncation at `max_steps` |
| infos | `phase`, `smiling`, `gaze_on_face`, `self_touch`, `engaged`, `engaged_steps`, `interactive_steps` (interaction and reunion steps so far), `smile_<phase>`, `gaze_<phase>`, `self_touch_<phase>`, `is_success` (the learner's measures; the caregiver's infos are the same). The caregiver's `expression` info is its action's, also while the task shows its face neutral |
| options | `phases_s` ((5, 5, 5) s, each 0.05-600), `distance` (0.6 m, 0.3-1.5: two sitting 18-month-olds' hip distance), `arms_free` (True), `head_support` (True), `success_fraction` (0.5, 0.05-1), `reward_free` (False), `scripted_partner` (False) |
| privileged cues | none: the caregiver's face, head and arm reach the learner only through its eyes; the phase and the caregiver's mode are never observed. The reward and the measures read both faces, the gaze line and the contacts from the world (they are no observation) |
| baselines | scripted form, default settings, 20 episodes of 15 s (seeds 1000-1019): scripted `StillFaceInfantController` 20 / 20, return 888.0 +- 0.0 (every episode alike: nothing is random with the default caregiver), success secured at step 1109 (in reunion); its measures per phase (fraction of the phase's steps, mean over episodes; smile / gaze at the face / self-touch): interaction 0.99 / 0.96 / 0.00, still 0.00 / 0.01 / 0.94, reunion 0.99 / 0.93 / 0.01, the still-face pattern (the gaze fractions miss the 0.3 s head turns). Random 0 / 20, 16.7 +- 8.9; zero action 0 / 20, 0.0 +- 0.0, every measure 0 (`mimo-social baselines still_face --episodes 20 --seed 1000`). The test file's own baselines and hacks, with every measure (`python tests/tasks/test_still_face.py 20`): uniform random 0 / 20, 13.9 +- 8.5, smile 0.14-0.15, gaze 0.09-0.14, self-touch 0.02-0.03 in every phase; "stare" (smiles and looks, never renews its smile: answered once a phase) 0 / 20, 200.0; "look" (looks, never smiles) 0 / 20, 0.0; looks with a random face every step 0 / 20, 128.9 +- 15.2; smiles (renewed every second) without turning its head 0 / 20, 0.0. `test_baselines_scripted_succeeds_random_zero_and_hacks_fail` (slow) checks these on 5 episodes |
| sources | Tronick, Als, Adamson, Wise & Brazelton (1978), The infant's response to entrapment between contradictory messages in face-to-face interaction, J. Am. Acad. Child Psychiatry 17: 1-13 (the paradigm: interaction, still face, reunion; infants sober, look away and comfort themselves when the mother's face is still); Mesman, van IJzendoorn & Bakermans-Kranenburg (2009), The many faces of the Still-Face Paradigm, Developmental Review 29: 120-162 (review and meta-analysis of the measures: positive affect and gaze at the parent drop in the still face and partly recover in reunion) |
| version history | v0, issue 19: first version, with the contingent caregiver (`partners/contingent.py`), the learner's cues (`partners/cues.py`) and the scripted infant `StillFaceInfantController` |
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Mapping

import mujoco
import numpy as np

from ..body.joint_groups import GAZE_JOINTS, held_posture
from ..body.postures import posture_joints
from ..core.task import Plot, Task, TaskOptions
from ..core.world import AgentSetup
from ..expressions.faces import EXPRESSIONS
from ..partners.cues import learner_cues
from .common import face_to_face
from .dyad import held_angles, tables_of, task_plan

__all__ = ["PHASES", "MEASURES", "LEARNER_ARM_JOINTS", "StillFace", "StillFaceOptions",
           "self_touch_geoms", "still_face_summary", "format_still_face_summary"]

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
    """The phases' lengths (s: interaction, still face, reunion), the standard pair's distance
    (m), whether the learner's arms are free, head support, the share of interactive steps that
    must be engaged for success, reward-free mode and whether ``infant_1`` is a scripted
    caregiver (no eyes, no reward)."""

    task = "still_face"
    phases_s: tuple = (5.0, 5.0, 5.0)
    distance: float = DISTANCE
    arms_free: bool = True
    head_support: bool = True
    success_fraction: float = 0.5
    reward_free: bool = False
    scripted_partner: bool = False

    def __post_init__(self):
        self._numbers("phases_s", 3, 0.05, 600.0,
                      allowed="(interaction, still, reunion) seconds, each 0.05 to 600")
        self._number("distance", 0.3, 1.5)
        self._bool("arms_free")
        self._bool("head_support")
        self._number("success_fraction", 0.05, 1.0)
        self._bool("reward_free")
        self._bool("scripted_partner")


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
        if i == 0:
            return {"posture": "sitting", "expressions": True, "vestibular": False,
                    "vision": {"width": EYE_SIZE, "height": EYE_SIZE}}
        scripted = self.options.scripted_partner
        return {"body": "adult", "posture": "kneeling", "expressions": True,
                "vestibular": False,
                "vision": False if scripted else {"width": EYE_SIZE, "height": EYE_SIZE}}

    def _free(self, i, config) -> tuple[str, ...]:
        if i == 0:
            return GAZE_JOINTS + (LEARNER_ARM_JOINTS if self.options.arms_free else ())
        return GAZE_JOINTS + CAREGIVER_ARM_JOINTS

    def _held(self, i, config):
        """Agent i's held joints (rad): all but its free ones, sitting (or its own posture)."""
        angles = held_angles(config, "sitting", posture_joints("sitting", config.body))
        return held_posture(tables_of(config), keep=self._free(i, config), angles=angles)

    def setup(self, i, config):
        plan = task_plan(self, "sitting", self.options.distance, self._held, ())
        pos, facing = face_to_face(i, plan.distance)
        free = self._free(i, config)
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=self._held(i, config), base="fixed", actuated=free)

    # -- phases ---------------------------------------------------------------------------------
    def phase_steps(self, dt: float) -> tuple[int, int, int]:
        """Control steps of each phase at control step ``dt`` (s)."""
        return tuple(max(1, int(round(s / dt))) for s in self.options.phases_s)

    def phase_at(self, step: int) -> int:
        """The phase index of control step ``step`` (0-based; past the last phase: reunion)."""
        b = self._bounds
        return 0 if step < b[0] else (1 if step < b[1] else 2)

    @property
    def phase_name(self) -> str:
        return PHASES[self.phase]

    # -- running ----------------------------------------------------------------------------------
    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        if self._bounds is None:
            self._bounds = tuple(np.cumsum(self.phase_steps(env.dt))[:2].tolist())
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
            self._n_inter = sum(1 for t in range(env.max_steps) if self.phase_at(t) != 1)
            self._need = max(1, math.ceil(self.options.success_fraction * self._n_inter - 1e-9))
            scripted = self.options.scripted_partner
            self._weights = np.array([1.0, 0.0 if scripted else 1.0])
        del m
        self.phase = 0
        self._held_q = None
        self._counts = np.zeros((3, 3), np.int64)     # phase x measure (smile, gaze, touch)
        self._steps = np.zeros(3, np.int64)
        self._engaged_steps = 0
        self._inter_steps = 0
        self._now = (False, False, False, False)
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
        self._steps[p] += 1
        self._counts[p] += (smiling, gaze, touch)
        if p != 1:
            self._inter_steps += 1
            self._engaged_steps += int(engaged)
        self._now = (smiling, gaze, touch, engaged)
        if self.options.reward_free:
            return np.zeros(2)
        return self._weights * float(engaged)

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
        keys = ["phase", "smiling", "gaze_on_face", "self_touch", "engaged", "engaged_steps",
                "interactive_steps", "is_success"]
        keys += [f"{k}_{p}" for p in PHASES for k in MEASURES]
        return {k: "number" for k in keys}

    def _info(self) -> dict:
        smiling, gaze, touch, engaged = self._now
        out = {"phase": int(self.phase), "smiling": smiling, "gaze_on_face": gaze,
               "self_touch": touch, "engaged": engaged,
               "engaged_steps": int(self._engaged_steps),
               "interactive_steps": int(self._inter_steps),
               "is_success": bool(self._engaged_steps >= self._need)}
        frac = self._counts / np.maximum(self._steps, 1)[:, None]
        for p, phase in enumerate(PHASES):
            for k, key in enumerate(MEASURES):
                out[f"{key}_{phase}"] = float(frac[p, k])
        return out

    def terminations(self, env):
        info = self._info()
        return np.zeros(2, bool), [info, dict(info)]


# -- summary over episodes --------------------------------------------------------------------
def still_face_summary(infos: Iterable[Mapping]) -> dict:
    """Per phase and measure, the mean and standard deviation over episodes of the fraction of
    the phase's steps with it, from each episode's last learner info (``infos``: one mapping per
    episode with the ``<measure>_<phase>`` keys of the task's infos). Returns ``{"episodes": n,
    "success": share of episodes with is_success, "phases": {phase: {measure: (mean, sd)}}}``;
    a ValueError names a missing key."""
    rows = [dict(x) for x in infos]
    if not rows:
        raise ValueError("still_face_summary: no episodes; allowed: one info mapping per episode")
    out = {}
    for phase in PHASES:
        out[phase] = {}
        for key in MEASURES:
            name = f"{key}_{phase}"
            missing = [k for k, r in enumerate(rows) if name not in r]
            if missing:
                raise ValueError(f"still_face_summary: episode {missing[0]} has no {name!r}; "
                                 "allowed: the last info of a still_face_v0 episode")
            v = np.array([float(r[name]) for r in rows])
            out[phase][key] = (float(v.mean()), float(v.std()))
    success = float(np.mean([bool(r.get("is_success", False)) for r in rows]))
    return {"episodes": len(rows), "success": success, "phases": out}


def format_still_face_summary(summary: Mapping) -> str:
    """:func:`still_face_summary` as a text table (phase rows, measure columns)."""
    lines = [f"episodes {summary['episodes']}, success {100 * summary['success']:.0f} %",
             f"{'phase':<12}" + "".join(f"{k:>18}" for k in MEASURES)]
    for phase, row in summary["phases"].items():
        lines.append(f"{phase:<12}" + "".join(f"{m:>11.2f} +-{s:>4.2f}" for m, s in row.values()))
    return "\n".join(lines)
