"""``ContingentCaregiver``: a scripted caregiver whose responses depend on what the learner does.

Each control step the caregiver reads the learner's cues from the world
(:func:`~mimo_social.partners.cues.learner_cues`: its face, whether it looks at the
caregiver's face and where it looks on the floor, whether its hands touch the caregiver) and
acts only through its own action space (motors and face), as every scripted partner does.

**Cue events** (the onset of a cue; ``cues`` says which count):

``"expression"``:
    event (onset): ``face="smile"``: the learner starts smiling (its face becomes ``happy``);
        ``face="copy"``: its face changes to a non-neutral one
    response: the caregiver shows ``happy`` (``"smile"``) or the learner's face of the event
        (``"copy"``)
``"gaze"``:
    event (onset): the learner's line of sight leaves the caregiver's face for a point on the floor
        (``gaze_point`` appears while ``gaze_on_face`` is false)
    response: the caregiver turns head and eyes to where the learner looks on the floor (the point
        of the event; while the response lasts, the learner's current floor point, as long as it
        looks at the floor)
``"touch"``:
    event (onset): a hand of the learner starts touching the caregiver's body
    response: a pat: the caregiver's right palm goes to 4 cm above the palm of the learner's
        touching hand (both touching, or none any more: the nearer one), down onto it, up, and back
        (each a quarter of the response; the arm's angles planned when the response starts)

Each event is answered with probability ``probability`` (one draw from the partner's
generator per event, seeded by :class:`~mimo_social.partners.wrapper.ScriptedPartners`), after
``delay_s`` seconds rounded to control steps (``delay_steps = round(delay_s / dt)``): an event
first seen in the world's state at the caregiver's step ``n`` (the state the learner's action
of step ``n - 1`` left) is answered by the caregiver's action of step ``n + delay_steps``
(``delay_s=0``: the same step); with ``delay_jitter_s`` each answered event's delay is
``delay_s`` plus a uniform draw from [0, ``delay_jitter_s``] (one more draw per answered event),
so that an answer's moment cannot be foretold from the event's. A response lasts ``duration_s``
seconds (rounded to steps, at least one); a new response of the same kind replaces a running
one, unless ``refractory``: then an event whose kind has a response pending or running is not
answered (no draw; logged ``answered=False``, ``ignored=True``): a caregiver does not smile anew
at every flicker of a face while it is still answering the last smile. Between responses the face
is ``rest_face`` (neutral) and head and eyes look at the learner's face (its ``head_centre``);
every other motor holds the pose it had at reset.

**Modes** (:meth:`ContingentCaregiver.set_mode`, any time; ``mode`` is the one each episode
starts in):

- ``"interactive"``: as above; the responses started per second of each kind are counted;
- ``"still"``: neutral face, no response to anything; every motor holds the pose the caregiver
  had when the mode was set (the still face of Tronick et al. 1978): positional, constant
  controls (the angles at the switch plus the gravity torque at rest over the servo's
  stiffness); spring-damper, the PD law toward those angles;
- ``"non_contingent"``: responses at the rates measured in the last interactive period (or
  ``rate_hz``), started at random steps (a Bernoulli draw per step and kind: a Poisson process
  independent of the learner); their content is drawn from the responses of that period (the
  faces shown, the points looked at; none yet: ``happy``, a floor point near the learner's
  feet). Their timing and content do not depend on the learner; a pat still aims at where the
  learner's arm is, and between responses the caregiver still looks at the learner's face.

**Motors**: the desired angle of each of the caregiver's motors (its held pose, the look-at
angles of :class:`~mimo_social.core.kinematics.LookAt`'s geometry for head and eyes, the pat's
arm angles from damped least squares, :func:`~mimo_social.core.kinematics.reach_sites`) becomes
its controls: ``actuation="positional"``: the target angle plus the gravity / Coriolis torque
over the servo's stiffness (``q + qfrc_bias / kp``, so a held pose does not sag);
``"spring_damper"``: a PD law per joint (natural frequency ``omega``, damping ``zeta``, gains
from the joint's inertia) with gravity, spring and applied-force compensation, as
:class:`~mimo_social.partners.gaze.GazeAtTarget`. Muscles are not supported.

**Speech**: a caregiver whose action has a voice (``voice=True`` in its settings) talks in the
``"interactive"`` and ``"non_contingent"`` modes, whatever the learner does, from their first
step on (an episode's start, a still face's end): utterances of
``speech`` (5, ``"speech"``) lasting a uniform draw from ``speech_s`` (0.5-1.5 s), each followed
by a pause drawn from ``pause_s`` (0.3-1.2 s), at ``speech_loudness`` (0.5 of the kind's range;
draws from the partner's generator, none for a caregiver without a voice); in ``"still"`` it is
silent (the still face of Tronick et al. 1978 is silent as well as still: the parent stops talking).
A caregiver's speech does not depend on the learner, so it adds nothing to the contingency; it
tells a listener whether the caregiver is engaged, also while the listener looks away.

**Stream**: ``stream`` holds the action of every step of the episode (``motors``: (T, n)
float32, ``expression``: (T,) int64, -1 without expressions, ``voice``: (T,) int64, the sound
kind, -1 without a voice, ``loudness``: (T,) float32, 0 without a voice, ``dt``); a
:class:`~mimo_social.partners.replay.ReplayCaregiver` plays it back bit for bit, the voice
included.

Logs for measures and tests: ``events`` (one dict per cue event: ``step``, ``cue``,
``answered``, ``due``) and ``responses`` (one dict per response started: ``step``, ``cue``,
``event_step`` (None when non-contingent), ``mode``) and ``modes`` ((step, mode) at reset and
at every :meth:`~ContingentCaregiver.set_mode`: the mode from that step's action on).
"""

from __future__ import annotations

from typing import Mapping, Sequence

import mujoco
import numpy as np
from gymnasium import spaces

from ..body.joint_groups import GAZE_JOINTS, RIGHT_SHOULDER_ELBOW
from ..core.kinematics import LookAt, reach_sites
from ..expressions.faces import EXPRESSIONS
from ..expressions.voice import SOUNDS
from ..util.checks import ConfigError, check_bool, check_choice, check_number, show
from .base import Partner, agent_index
from .cues import HAPPY, NEUTRAL, Cues, learner_cues, touching_hands

__all__ = ["ContingentCaregiver", "CUES", "MODES", "FACES", "look_at_point"]

CUES = ("expression", "gaze", "touch")
MODES = ("interactive", "still", "non_contingent")
FACES = ("smile", "copy")
#: the sound kind of the caregiver's talk
SPEECH = SOUNDS.index("speech")
#: m: the pat's palm height above the learner's palm before it comes down onto it
PAT_LIFT = 0.04
#: m: a pat point counts as reached when the planned palm comes this near it
PAT_REACHED = 0.03
#: the pat's phases as fractions of the response: above, onto, above, back
PAT_PHASES = (0.25, 0.5, 0.75)


def look_at_point(look: LookAt, model, scratch, qpos, point) -> np.ndarray:
    """:class:`LookAt`'s angles (head swivel then tilt facing ``point`` from the neck, each eye
    then aimed from its own centre) for a world point instead of a body or site, computed on
    ``scratch`` (a private MjData) from the state ``qpos``."""
    scratch.qpos[:] = qpos
    return look.point(model, scratch, point)


def _check_cues(value) -> tuple[str, ...]:
    allowed = f"a non-empty list of distinct names from {list(CUES)}"
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or not len(value) \
            or not all(isinstance(v, str) and v in CUES for v in value) \
            or len(set(value)) != len(value):
        raise ConfigError(f"ContingentCaregiver: cues={show(value)} not allowed; allowed: "
                          f"{allowed}")
    return tuple(value)


def _check_range(who: str, name: str, value, lo: float, hi: float) -> tuple[float, float]:
    """A (shortest, longest) pair of seconds within [lo, hi], shortest <= longest."""
    ok = isinstance(value, Sequence) and not isinstance(value, (str, bytes)) and len(value) == 2
    if ok:
        a = check_number(who, f"{name}[0]", value[0], lo, hi)
        b = check_number(who, f"{name}[1]", value[1], lo, hi)
        ok = a <= b
    if not ok:
        raise ConfigError(f"{who}: {name}={show(value)} not allowed; allowed: (shortest, "
                          f"longest) seconds, each {lo} to {hi}, shortest <= longest")
    return float(a), float(b)


def _check_rates(value, cues) -> dict | None:
    if value is None:
        return None
    if isinstance(value, Mapping):
        bad = [k for k in value if k not in CUES]
        if bad:
            raise ConfigError(f"ContingentCaregiver: rate_hz names unknown cues {bad}; allowed: "
                              f"{list(CUES)}")
        return {k: check_number("ContingentCaregiver", f"rate_hz[{k!r}]", value.get(k, 0.0),
                                0.0, 100.0) for k in cues}
    r = check_number("ContingentCaregiver", "rate_hz", value, 0.0, 100.0)
    return {k: r for k in cues}


class ContingentCaregiver(Partner):
    """A caregiver that answers the learner's cues (see the module docstring).

    Settings: ``cues`` (which cue events count), ``delay_s`` (0-60 s), ``delay_jitter_s`` (0-60 s:
    added delay, uniform), ``refractory`` (events of a kind being answered are ignored),
    ``probability`` (0-1 per event), ``duration_s`` (0.01-60 s: how long a response lasts), ``face``
    (``"smile"`` or ``"copy"``), ``rest_face`` (an expression name), ``mode`` (the mode each episode
    starts in), ``rate_hz`` (None: non-contingent rates measured; a number or a mapping cue ->
    rate), ``learner`` (None: the other agent of a pair), ``omega`` / ``zeta`` (the spring-damper
    PD). ``measured_rates`` (responses per second of each cue in the last interactive period that
    ended, of this or an earlier episode) is kept across resets, so a non-contingent episode can
    follow a live one. ``speech_s``, ``pause_s`` (ranges, s) and ``speech_loudness`` (0-1): its
    talk, where its action has a voice (see the module docstring).
    """

    def __init__(self, cues=CUES, delay_s: float = 0.5, probability: float = 1.0,
                 duration_s: float = 1.0, face: str = "smile", rest_face: str = "neutral",
                 mode: str = "interactive", rate_hz=None, learner: str | None = None,
                 omega: float = 15.0, zeta: float = 1.0, delay_jitter_s: float = 0.0,
                 refractory: bool = False, speech_s=(0.5, 1.5), pause_s=(0.3, 1.2),
                 speech_loudness: float = 0.5):
        who = "ContingentCaregiver"
        self.cues = _check_cues(cues)
        self.delay_s = check_number(who, "delay_s", delay_s, 0.0, 60.0)
        self.delay_jitter_s = check_number(who, "delay_jitter_s", delay_jitter_s, 0.0, 60.0)
        self.refractory = check_bool(who, "refractory", refractory)
        self.probability = check_number(who, "probability", probability, 0.0, 1.0)
        self.duration_s = check_number(who, "duration_s", duration_s, 0.01, 60.0)
        self.face = check_choice(who, "face", face, FACES)
        self.rest_face = EXPRESSIONS.index(check_choice(who, "rest_face", rest_face, EXPRESSIONS))
        self.initial_mode = check_choice(who, "mode", mode, MODES)
        self.rate_hz = _check_rates(rate_hz, self.cues)
        if learner is not None and not isinstance(learner, str):
            raise ConfigError(f"{who}: learner={show(learner)} not allowed; allowed: None (the "
                              "other agent of a pair) or an agent name")
        self.learner = learner
        self.omega = check_number(who, "omega", omega, 0.01, 1000.0)
        self.zeta = check_number(who, "zeta", zeta, 0.01, 1000.0)
        self.speech_s = _check_range(who, "speech_s", speech_s, 0.05, 60.0)
        self.pause_s = _check_range(who, "pause_s", pause_s, 0.0, 60.0)
        self.speech_loudness = check_number(who, "speech_loudness", speech_loudness, 0.0, 1.0)
        self.mode = self.initial_mode
        self.measured_rates: dict[str, float] | None = None
        self._env = None
        self.events: list[dict] = []
        self.responses: list[dict] = []
        self.modes: list[tuple[int, str]] = []
        self._motors: list[np.ndarray] = []
        self._faces: list[int] = []
        self._voices: list[int] = []

    def __repr__(self) -> str:
        return (f"ContingentCaregiver(cues={self.cues}, delay_s={self.delay_s}, delay_jitter_s="
                f"{self.delay_jitter_s}, refractory={self.refractory}, probability="
                f"{self.probability}, duration_s={self.duration_s}, face={self.face!r}, "
                f"mode={self.mode!r})")

    # -- set up --------------------------------------------------------------------------------
    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        who = "ContingentCaregiver"
        names = list(env.possible_agents)
        if self.learner is None:
            if len(names) != 2:
                raise ValueError(f"{who}: learner=None needs a pair; this env has {names}: name "
                                 "the learner (learner='infant_0')")
            learner = names[1 - names.index(agent)]
        elif self.learner not in names or self.learner == agent:
            raise ValueError(f"{who}: learner={self.learner!r} not allowed; allowed: an agent "
                             f"of {[n for n in names if n != agent]}")
        else:
            learner = self.learner
        self._agent, self._learner = agent, learner
        i, k = agent_index(env, agent), names.index(learner)
        self._i, self._k = i, k
        cfg = env.agent_configs[i]
        if cfg.actuation not in ("positional", "spring_damper"):
            raise ValueError(f"{who}: {agent} has actuation={cfg.actuation!r}; allowed: "
                             "'positional' or 'spring_damper'")
        self._positional = cfg.actuation == "positional"
        space = env.action_space(agent)
        self._dict = isinstance(space, spaces.Dict) and "expression" in space.spaces
        self._voice = isinstance(space, spaces.Dict) and "voice" in space.spaces
        if "expression" in self.cues and not self._dict:
            raise ValueError(f"{who}: cue 'expression' answers with the face, but {agent}'s "
                             "action has no expression (build the env with expressions on), "
                             "or leave 'expression' out of cues")
        w = env.world
        m = w.model
        a = w.agents[i]
        act = env.actuation[i]
        self._act = act
        self._n = act.n_controls
        motor_joint = {n: j for j, n in enumerate(a.actuated_names)}
        self._qadr = a.qpos_adr[a.actuated_joint_idx]
        self._dadr = a.dof_adr[a.actuated_joint_idx]
        self._mdiag = (m.M_rowadr[self._dadr] + m.M_rownnz[self._dadr] - 1).astype(np.intp)
        self._lo, self._hi = a.joint_range[a.actuated_joint_idx].T
        # head and eyes: the look-at geometry over the caregiver's gaze joints with motors
        self._look = LookAt(w, i)
        gnames = [a.joint_names[j] for j in self._look.joints]
        self._gslot = np.array([s for s, n in enumerate(gnames) if n in motor_joint], np.intp)
        self._gmotor = np.array([motor_joint[gnames[s]] for s in self._gslot], np.intp)
        if "gaze" in self.cues and not len(self._gmotor):
            raise ValueError(f"{who}: cue 'gaze' answers by turning head and eyes, but {agent} "
                             f"has no motor on {list(GAZE_JOINTS)}; actuate them or leave "
                             "'gaze' out of cues")
        # the pat: shoulder and elbow of either arm with all four motors
        self._arms = []
        for side, palm in zip(("right", "left"), a.palm_sites):
            arm = [n.replace("right_", f"{side}_", 1) for n in RIGHT_SHOULDER_ELBOW]
            if all(n in motor_joint for n in arm):
                self._arms.append((np.array([motor_joint[n] for n in arm], np.intp), int(palm)))
        if "touch" in self.cues and not self._arms:
            raise ValueError(f"{who}: cue 'touch' answers with a pat, but {agent} has no arm "
                             f"with motors on all of {list(RIGHT_SHOULDER_ELBOW)} (or their "
                             "left_ counterparts); actuate an arm or leave 'touch' out of cues")
        self._learner_palms = w.agents[k].palm_sites
        self._learner_arm = [(m.geom(f"{learner}/{side}_lower_arm").id,
                              m.geom(f"{learner}/{side}_upper_arm").id)
                             for side in ("right", "left")]
        self._learner_face = int(w.agents[k].head_site)
        self._scratch = mujoco.MjData(m)
        self._dt = float(env.dt)
        self.delay_steps = int(round(self.delay_s / self._dt))
        self.jitter_steps = int(round(self.delay_jitter_s / self._dt))
        self.duration_steps = max(1, int(round(self.duration_s / self._dt)))
        self._home = w.data.qpos[self._qadr].copy()
        self._env = env
        self.mode = self.initial_mode
        self._step = 0
        self._pending: list[tuple[int, str, object, int]] = []
        self._active: dict[str, tuple[int, int, object]] = {}
        self.events, self.responses = [], []
        self._motors, self._faces, self._voices = [], [], []
        self._talk = 0              # steps left of the utterance (> 0) or of the pause (< 0)
        self._period_steps = 0
        self._period_counts = dict.fromkeys(self.cues, 0)
        self._period_content: dict[str, list] = {c: [] for c in self.cues}
        self._content = {c: [] for c in self.cues}
        self._prev = self.cues_now()
        self._enter(self.mode)
        self.modes = [(0, self.mode)]

    def cues_now(self) -> Cues:
        """The learner's cues in the env's current state."""
        return learner_cues(self._env, self._learner, self._agent)

    # -- modes ---------------------------------------------------------------------------------
    def set_mode(self, mode: str) -> None:
        """Switch to ``"interactive"``, ``"still"`` or ``"non_contingent"`` (see the module
        docstring); before the first reset it sets the mode the episode starts in."""
        mode = check_choice("ContingentCaregiver", "mode", mode, MODES)
        if self._env is None:
            self.initial_mode = self.mode = mode
            return
        if self.mode == "interactive" and mode != "interactive":
            self._close_period()
        self.mode = mode
        self._enter(mode)
        self.modes.append((self._step, mode))

    def _close_period(self) -> None:
        if self._period_steps:
            seconds = self._period_steps * self._dt
            self.measured_rates = {c: self._period_counts[c] / seconds for c in self.cues}
            self._content = {c: list(v) for c, v in self._period_content.items()}

    def _enter(self, mode: str) -> None:
        self._pending.clear()
        self._active.clear()
        if mode == "interactive":
            self._period_steps = 0
            self._period_counts = dict.fromkeys(self.cues, 0)
            self._period_content = {c: [] for c in self.cues}
        elif mode == "still":
            w = self._env.world
            self._hold = w.data.qpos[self._qadr].copy()
            self._hold_u = None
            if self._positional:    # constant targets: the angles plus gravity at rest
                if self.__dict__.get("_scratch") is None:
                    self._scratch = mujoco.MjData(w.model)
                s = self._scratch
                s.qpos[:] = w.data.qpos
                s.qvel[:] = 0.0
                mujoco.mj_forward(w.model, s)
                self._hold_u = self._controls(s, self._hold)
        elif self.rate_hz is None and self.measured_rates is None:
            raise ValueError("ContingentCaregiver: mode 'non_contingent' needs response rates: "
                             "none measured yet (no interactive period has ended); give "
                             "rate_hz=<responses per second> or run an interactive period first")

    @property
    def rates(self) -> dict[str, float]:
        """Responses per second of each cue kind that ``"non_contingent"`` uses."""
        return dict(self.rate_hz if self.rate_hz is not None else self.measured_rates or {})

    # -- the stream ----------------------------------------------------------------------------
    @property
    def stream(self) -> dict:
        """This episode's actions: ``motors`` (T, n) float32, ``expression`` (T,) int64 (-1:
        the agent has no expression action), ``voice`` (T,) int64 (the sound kind; -1: the
        agent has no voice), ``loudness`` (T,) float32 (0 without a voice), ``dt`` (s)."""
        n = getattr(self, "_n", 0)
        motors = np.stack(self._motors) if self._motors else np.zeros((0, n), np.float32)
        voice = np.asarray(self._voices, np.int64)
        loud = np.where(voice >= 0, self.speech_loudness, 0.0).astype(np.float32)
        return {"motors": motors, "expression": np.asarray(self._faces, np.int64),
                "voice": voice, "loudness": loud, "dt": float(getattr(self, "_dt", np.nan))}

    # -- acting --------------------------------------------------------------------------------
    def act(self, env, agent, observation):
        if self._env is None:
            raise RuntimeError("ContingentCaregiver.act() before reset(); reset the env first")
        self._env = env
        if self.__dict__.get("_scratch") is None:   # dropped when pickled
            self._scratch = mujoco.MjData(env.world.model)
        n = self._step
        now = self.cues_now()
        if self.mode == "interactive":
            self._period_steps += 1
            self._detect(n, now)
        elif self.mode == "non_contingent":
            self._spontaneous(n)
        for due, cue, content, event_step in [p for p in self._pending if p[0] <= n]:
            self._start(n, cue, content, event_step)
        self._pending = [p for p in self._pending if p[0] > n]
        self._prev = now
        for cue in [c for c, (_, end, _) in self._active.items() if end <= n]:
            del self._active[cue]
        u, face = self._action(env, n)
        self._step += 1
        self._motors.append(u)
        self._faces.append(face if self._dict else -1)
        sound = self._speech() if self._voice else -1
        self._voices.append(sound)
        if not (self._dict or self._voice):
            return u.copy()
        out = {"motors": u.copy()}
        if self._dict:
            out["expression"] = np.int64(face)
        if self._voice:
            out["voice"] = np.int64(sound)
            out["loudness"] = np.array([self.speech_loudness], np.float32)
        return out

    def _speech(self) -> int:
        """This step's sound kind (see the module docstring: utterances and pauses drawn from
        the partner's generator; silent in ``"still"``)."""
        if self.mode == "still":
            self._talk = 0
            return 0
        if self._talk == 0:      # an episode's start or a still face's end: it talks at once
            self._talk = self._draw(self.speech_s)
        if self._talk < 0:
            self._talk += 1
            if self._talk == 0:
                self._talk = self._draw(self.speech_s)
            return 0
        self._talk -= 1
        if self._talk == 0:
            self._talk = -self._draw(self.pause_s)
        return SPEECH

    def _draw(self, span: tuple[float, float]) -> int:
        """A length of at least one step, uniform within ``span`` seconds."""
        return max(1, int(round(self.rng.uniform(*span) / self._dt)))

    def _detect(self, n: int, now: Cues) -> None:
        prev = self._prev
        found = []
        if "expression" in self.cues:
            if self.face == "smile" and now.smiling and not prev.smiling:
                found.append(("expression", HAPPY))
            elif self.face == "copy" and now.expression != prev.expression \
                    and now.expression != NEUTRAL:
                found.append(("expression", now.expression))
        if "gaze" in self.cues and now.gaze_point is not None and not now.gaze_on_face \
                and (prev.gaze_point is None or prev.gaze_on_face):
            found.append(("gaze", now.gaze_point.copy()))
        if "touch" in self.cues and now.touching and not prev.touching:
            found.append(("touch", None))
        for cue, content in found:
            busy = self.refractory and (self._active.get(cue, (0, n))[1] > n
                                        or any(p[1] == cue for p in self._pending))
            answered = not busy and bool(self.rng.random() < self.probability)
            due = n + self.delay_steps
            if answered and self.jitter_steps:
                due += int(self.rng.integers(self.jitter_steps + 1))
            self.events.append({"step": n, "cue": cue, "answered": answered, "due": due,
                                "ignored": busy})
            if answered:
                self._pending.append((due, cue, content, n))

    def _spontaneous(self, n: int) -> None:
        for cue in self.cues:
            p = min(1.0, self.rates.get(cue, 0.0) * self._dt)
            if self.rng.random() < p:
                seen = self._content.get(cue) or []
                content = seen[int(self.rng.integers(len(seen)))] if seen else self._default(cue)
                self._start(n, cue, content, None)

    def _default(self, cue: str):
        if cue == "expression":
            return HAPPY
        if cue == "gaze":
            d = self._env.world.data
            feet = d.xpos[self._env.world.agents[self._k].root_body].copy()
            feet[:2] += self.rng.uniform(-0.3, 0.3, 2)
            feet[2] = 0.0
            return feet
        return None

    def _start(self, n: int, cue: str, content, event_step) -> None:
        if cue == "touch":
            content = self._plan_pat()
        self._active[cue] = (n, n + self.duration_steps, content)
        self.responses.append({"step": n, "cue": cue, "event_step": event_step,
                               "mode": self.mode})
        if self.mode == "interactive":
            self._period_counts[cue] += 1
            if cue != "touch":
                self._period_content[cue].append(content)

    def _plan_pat(self):
        """The pat: for each arm with motors and each point of the learner's touching arm
        (its palm, then the middle of its forearm, then of its upper arm: the first that the
        palm reaches within :data:`PAT_REACHED` m), the arm's angles above the point and on it
        (damped least squares on a scratch copy of the state); the plan that comes nearest is
        kept. ``pat_misses``: how far (m) it leaves the palm from those two points."""
        w = self._env.world
        m, d, s = w.model, w.data, self._scratch
        sides = np.flatnonzero(touching_hands(w, self._k, self._i))
        if not len(sides):      # not touching now (a non-contingent pat): either arm
            sides = np.arange(2)
        points = [(d.site_xpos[self._learner_palms[k]], d.geom_xpos[self._learner_arm[k][0]],
                   d.geom_xpos[self._learner_arm[k][1]]) for k in sides]
        best = None
        for motors, palm in self._arms:
            qadr, dadr = self._qadr[motors], self._dadr[motors]
            lo, hi = self._lo[motors], self._hi[motors]
            for level in range(3):
                for per_side in points:
                    s.qpos[:] = d.qpos
                    poses, misses = [], []
                    for lift in (PAT_LIFT, 0.0):
                        misses.append(reach_sites(m, s, qadr, dadr, lo, hi, palm,
                                                  per_side[level] + [0.0, 0.0, lift]))
                        poses.append(s.qpos[qadr].copy())
                    if best is None or misses[1] < best[2][1]:
                        best = (motors, poses, misses)
                if best[2][1] <= PAT_REACHED:
                    break
        self.pat_misses = best[2]
        return best[0], best[1]

    def _action(self, env, n: int) -> tuple[np.ndarray, int]:
        w = env.world
        d = w.data
        if self.mode == "still":
            if self._hold_u is not None:
                return self._hold_u.copy(), NEUTRAL
            return self._controls(d, self._hold), NEUTRAL
        q = self._home.copy()
        face = self.rest_face
        if "expression" in self._active:
            face = int(self._active["expression"][2])
        if len(self._gmotor):
            gaze = self._active.get("gaze")
            if gaze is None:
                point = d.site_xpos[self._learner_face]
            else:
                point = gaze[2]
                now = self._prev
                if self.mode == "interactive" and now.gaze_point is not None \
                        and not now.gaze_on_face:
                    point = now.gaze_point      # follow the learner's look while it lasts
                    self._active["gaze"] = (gaze[0], gaze[1], point)
            angles = look_at_point(self._look, w.model, self._scratch, d.qpos, point)
            q[self._gmotor] = angles[self._gslot]
        pat = self._active.get("touch")
        if pat is not None:
            start, end, (motors, (above, on)) = pat
            f = (n - start) / max(1, end - start)
            a, b, c = PAT_PHASES
            if f < b:
                q[motors] = above if f < a else on
            elif f < c:
                q[motors] = above
        return self._controls(d, q), face

    def _controls(self, d, q: np.ndarray) -> np.ndarray:
        """Motor controls that drive the caregiver's actuated joints to the angles ``q``."""
        dof = self._dadr
        if self._positional:
            act = self._act
            target = q + d.qfrc_bias[dof] / act.kp
            u = 2.0 * (target - act.lo) / (act.hi - act.lo) - 1.0
        else:
            err = q - d.qpos[self._qadr]
            inertia = d.M[self._mdiag]
            w, z = self.omega, self.zeta
            tau = (inertia * (w * w * err - 2.0 * z * w * d.qvel[dof])
                   + d.qfrc_bias[dof] - d.qfrc_passive[dof] - d.qfrc_applied[dof])
            act = self._act
            u = tau / np.where(tau >= 0, act.torque_pos, act.torque_neg)
        return np.clip(u, -1.0, 1.0).astype(np.float32)

    # -- pickling ------------------------------------------------------------------------------
    def __getstate__(self):
        state = self.__dict__.copy()
        state.pop("_scratch", None)
        return state

