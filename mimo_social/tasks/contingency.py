"""Contingency: smiling with a caregiver who answers live, replays a session or smiles on a timer.

| | |
|---|---|
| agents | 2: `infant_0` (the learner, an 18-month-old) and `infant_1` (the caregiver: by default the adult body, kneeling; an infant partner is allowed with `per_agent=[{}, {"body": "infant"}]`). `scripted_env` drives the caregiver (`ContingencyCaregiver`, below); `parallel_env` makes it a second learner (condition "live" only) |
| body | the learner stands (as in `mirror_v0`), hip fixed in the world, every joint held; head and eyes held looking at the caregiver's face (`tasks/dyad.py` aims them for the pair's bodies), so the caregiver's face is in the middle of both eye images without any aiming; the caregiver kneels (its own posture's legs), every joint held, head and eyes on the learner's face. Nothing moves but the faces: the paradigm is about expressions |
| scene | the pair face to face, `distance` (0.3 m) apart for two 18-month-olds; the kneeling adult is placed by the measured reach of its arm (0.37 m, `tasks/dyad.py`), as in `mirror_v0`: its face spans about a third of each of the learner's 64x64 eye images (about 20 pixels across on a rendered frame) |
| conditions | option `condition`, or `env.unwrapped.task.set_condition(name)` from the next reset on. **live**: the scripted caregiver answers each of the learner's smiles (its face turning "happy") with probability `response_probability` (0.8) by a smile `response_delay_s` (0.5 s) later, held `response_duration_s` (1 s; a new answer restarts it), else a neutral face (`ContingentCaregiver`, mode "interactive", cue: the expression only). **replay**: the caregiver's action stream (its faces, step by step) of an earlier live episode is played back regardless of the learner (`ReplayCaregiver`): by default the last live episode of this env (run one first), or the `stream` given to `scripted_env` (a stream dict, e.g. `mimo_social.partners.replay.load_stream(path)` of one saved with `save_stream(path, env.partners["infant_1"].recorded)`); Murray and Trevarthen's double video: the same caregiver behaviour, out of sync with the infant. **non_contingent**: the caregiver smiles, each smile held `response_duration_s`, at the rate it answered in this env's last live episode (before any live episode: `timer_rate_hz`, 0.5 per second), started on a random timer independent of the learner (mode "non_contingent"; a Poisson process from the partner's seeded generator). In replay and non-contingent nothing the learner does changes the caregiver (tested). Two learners: "live" only (the caregiver is the other learner's policy; replay and non-contingent need the script: a ConfigError) |
| reset | both faces neutral; nothing random in the task (the scripted caregiver draws its responses and timer from the env's seed) |
| action | `Dict(motors=Box(0,), expression=Discrete(7))`: the learner's face is its action (no motor is free) |
| observation | `eye_left`, `eye_right` (64x64x3 RGB: the caregiver's face reaches the learner only through its eyes), `proprioception` (0 floats: no free joint); never the caregiver's expression, mode or stream |
| reward | +1 on a step of shared smiling: the learner and the caregiver both show "happy" while the learner's gaze is on the caregiver's face (`partners/cues.py`, `learner_cues`), else 0; with `reward_free` (False) 0 on every step, every measure still in the infos (for curiosity, empowerment or contingency-detection signals of one's own). Two learners: each is rewarded when both smile and its own gaze is on the other's face. A learner that smiles at random (1/7 of the steps) shares at most 1/7 of the steps; the zero action (neutral) none |
| success | per episode: `is_success` becomes True on the step at which the shared-smile steps reach `success_fraction` (0.2) of the episode's `max_steps` (2000: 400 steps); the last step's value is the episode's verdict. Meant for the live condition, where the learner's smiles bring the caregiver's: a smile held on (one answer of 1 s) or a copy of the caregiver's face (which never smiles first) fails; a face drawn at random each step is happy on 1/7 of the steps (13.8 % shared, measured), far from 20 %. In replay and non-contingent it depends on the caregiver's own timing and is reported, not a goal |
| termination | none; truncation at 2000 steps (20 s: a contingency needs several smiles and answers to show; Murray and Trevarthen's live and replay sessions lasted 30-60 s) |
| infos | `condition` (0 live, 1 replay, 2 non_contingent), `smiling` (the learner, this step), `caregiver_smiling`, `gaze_on_face` (the learner's), `shared` (a shared-smile step), `shared_steps`, `learner_smiles` and `caregiver_smiles` (smile onsets so far: the face turning "happy"), `learner_smile_rate` and `caregiver_smile_rate` (onsets per second so far), `smiling_fraction` (of the steps so far), `gaze_fraction`, `shared_fraction`, `response_rate` (the share of the learner's smiles, among those whose window has passed or been answered, followed by a caregiver smile onset within `window_s` (1.5 s)), `baseline_rate` (the share of control windows, `window_s` blocks of the episode holding no learner smile and not within `window_s` after one, in which the caregiver begins to smile), `contingency_index` (`response_rate - baseline_rate`: Watson's conditional-probability difference: about the response probability in live, lower in replay and non-contingent, where the caregiver's smiles follow the learner's only by chance), `is_success` |
| options | `condition` ("live", "replay", "non_contingent"), `distance` (0.3 m, 0.22 to 2.0), `response_delay_s` (0.5 s, 0 to 5), `response_probability` (0.8, 0 to 1), `response_duration_s` (1.0 s, 0.01 to 10), `timer_rate_hz` (0.5, 0 to 10: the non-contingent rate before any live episode), `window_s` (1.5 s, 0.05 to 10: the contingency index's window; keep it above the delay), `success_fraction` (0.2, 0.01 to 1), `reward_free` (False), `scripted_partner` (False; set by `scripted_env`) |
| privileged cues | none: the caregiver's face reaches the learner only through its eyes; the reward and the measures read both faces and the gaze from the world (no observation) |
| baselines | live, 20 episodes of 2000 steps, seeds 1000-1019, the learner's eyes rendered (`mimo-social baselines contingency --episodes 20 --seed 1000`): random face each step 0 / 20 successes, return 276.8 +- 13.2; zero action (neutral) 0 / 20, 0 +- 0; scripted `ContingencyDetectorController` 19 / 20, 665 +- 117, success secured at step 1122 on average. Hacks and an upper bound, same seeds (`python tests/tasks/test_contingency.py`; eyes off, no policy reads them): always happy 0 / 20, 90.0 +- 30.0 (one answer); copying the caregiver's face (`MirrorController`) 0 / 20, 0 +- 0 (the caregiver never smiles first); smiling with a one-step neutral dip every 0.5 s (each dip a new smile, answered before the last answer ends) 20 / 20, 1851.3 +- 59.1: the reward's optimum uses the contingency, and the detector, which also tests it, reaches a third of it. No trained learner yet |
| summary | `condition_summary(episodes, seed, controller)` runs blocks of live, replay (of that block's live episode) and non-contingent episodes and returns each measure's mean and sd per condition (`format_summary` prints it); the scripted `ContingencyDetectorController`, 10 blocks, seeds 1000-1009 (`condition_summary(episodes=10, seed=1000)`), mean +- sd live / replay / non-contingent: share of the steps smiling 0.576 +- 0.073 / 0.381 +- 0.136 / 0.364 +- 0.158; smile onsets per second 0.42 / 0.40 / 0.38; response rate 0.851 +- 0.124 / 0.438 +- 0.210 / 0.369 +- 0.215; baseline rate 0.000 / 0.392 / 0.135; contingency index 0.851 +- 0.124 / 0.046 +- 0.554 / 0.234 +- 0.381; shared smiling 0.344 / 0.173 / 0.152 of the steps; success 9 / 5 / 3 of 10; caregiver smile onsets per second 0.35 / 0.35 (the same stream) / 0.24. The pattern Murray and Trevarthen report (fewer positive expressions when the same mother is replayed) shows in the share of the steps smiling, not in the smile onsets (the detector keeps bidding briefly) |
| sources | not in the MIMo paper: a paradigm of this package after Watson (1972, 1979: infants detect the contingency of events on their own behaviour, measured as conditional probabilities; the smile as the response to a contingent stimulus), Watson and Ramey (1972: contingent mobiles raise the infant's response rate), Murray and Trevarthen (1985: double video, 6-12-week-olds with their mothers live versus a replay of the same mother, which brought gaze avoidance and fewer positive expressions), Nadel et al. (1999, live-replay-live), Bigelow and Rochat (2006: 2-month-olds smile less to a partner whose contingency for smiles differs from their mother's). Response delay 0.5 s: a prompt answer, within the 1-s resolution at which face-to-face interaction is coded (Beebe et al. 2016), and well below the delays of a few seconds that keep young infants from learning a contingency (Millar 1972) |
| version history | v0, issue 19: first version, with `still_face_v0`, `imitation_v0` and the contingent and replay caregivers |

The learner's action and the caregiver's face of the same step are compared; a scripted
caregiver reads the learner's face before the learner's action of a step applies, so its answers
come one control step (10 ms) after `response_delay_s`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..body.joint_groups import held_posture
from ..core.task import Plot, Task, TaskOptions
from ..core.world import AgentSetup
from ..expressions.faces import EXPRESSIONS
from ..partners.base import Partner
from ..util.checks import ConfigError, check_choice
from .common import face_to_face
from .dyad import held_angles, tables_of, task_plan

__all__ = ["CONDITIONS", "MEASURES", "ContingencyOptions", "Contingency", "ContingencyCaregiver",
           "ContingencyMeasures", "condition_summary", "summarize", "format_summary"]

DISTANCE = 0.3
EYE_SIZE = 64
HAPPY = EXPRESSIONS.index("happy")
#: the conditions, in the order of their info code
CONDITIONS = ("live", "replay", "non_contingent")
#: the per-episode measures of the summary (last-step infos)
MEASURES = ("learner_smile_rate", "smiling_fraction", "gaze_fraction", "response_rate",
            "baseline_rate", "contingency_index", "caregiver_smile_rate", "shared_fraction",
            "is_success")


@dataclass(frozen=True)
class ContingencyOptions(TaskOptions):
    """The condition (live, replay, non-contingent), the distance between the faces (m), the
    scripted caregiver's response delay (s) and probability, the contingency index's window (s),
    the share of shared-smile steps for success, reward-free mode and whether ``infant_1`` is
    the scripted caregiver (no eyes, no reward)."""

    task = "contingency"
    condition: str = "live"
    distance: float = DISTANCE
    response_delay_s: float = 0.5
    response_probability: float = 0.8
    response_duration_s: float = 1.0
    timer_rate_hz: float = 0.5
    window_s: float = 1.5
    success_fraction: float = 0.2
    reward_free: bool = False
    scripted_partner: bool = False

    def __post_init__(self):
        self._choice("condition", CONDITIONS)
        self._number("distance", 0.22, 2.0)
        self._number("response_delay_s", 0.0, 5.0)
        self._number("response_probability", 0.0, 1.0)
        self._number("response_duration_s", 0.01, 10.0)
        self._number("timer_rate_hz", 0.0, 10.0)
        self._number("window_s", 0.05, 10.0)
        self._number("success_fraction", 0.01, 1.0)
        self._bool("reward_free")
        self._bool("scripted_partner")
        if self.condition != "live" and not self.scripted_partner:
            raise ConfigError(
                f"{self.task}: task option condition={self.condition!r} needs the scripted "
                "caregiver (contingency_v0.scripted_env); with two learners allowed: 'live'")


class ContingencyMeasures:
    """The paradigm's running measures over one episode, fed one step at a time with whether
    the learner smiles, the caregiver smiles and the learner looks at the caregiver's face (see
    the task table's ``infos`` row); ``window``: the contingency window in steps."""

    def __init__(self, window: int, dt: float):
        self.window, self.dt = max(1, int(window)), float(dt)
        self.steps = 0
        self.prev = (False, False)
        self.smiling_steps = self.gaze_steps = self.shared_steps = 0
        self.learner_onsets = self.caregiver_onsets = 0
        self.open: list[int] = []            # learner onsets whose window is still open
        self.answered = self.resolved = 0
        self.last_onset = -10 ** 9            # step of the learner's last smile onset
        self.block_start = 1
        self.block_learner = self.block_caregiver = False
        self.control = self.control_hits = 0

    def update(self, learner: bool, caregiver: bool, gaze: bool, shared: bool) -> None:
        self.steps += 1
        t = self.steps
        l_on = learner and not self.prev[0]
        c_on = caregiver and not self.prev[1]
        self.prev = (learner, caregiver)
        self.smiling_steps += learner
        self.gaze_steps += gaze
        self.shared_steps += shared
        self.caregiver_onsets += c_on
        # the learner's smiles answered within the window (a caregiver onset after the smile)
        still = []
        for t0 in self.open:
            if c_on and t > t0:
                self.answered += 1
                self.resolved += 1
            elif t - t0 >= self.window:
                self.resolved += 1
            else:
                still.append(t0)
        self.open = still
        if l_on:
            self.learner_onsets += 1
            self.open.append(t)
            self.last_onset = t
        # control blocks: window-long blocks with no learner onset in them or in the window
        # before them
        self.block_learner |= l_on
        self.block_caregiver |= c_on
        if t - self.block_start + 1 >= self.window:
            if not self.block_learner and self.block_start - self.last_onset > self.window:
                self.control += 1
                self.control_hits += self.block_caregiver
            self.block_start = t + 1
            self.block_learner = self.block_caregiver = False

    def infos(self) -> dict:
        seconds = max(self.steps, 1) * self.dt
        n = max(self.steps, 1)
        response = self.answered / self.resolved if self.resolved else 0.0
        baseline = self.control_hits / self.control if self.control else 0.0
        return {"shared_steps": self.shared_steps, "learner_smiles": self.learner_onsets,
                "caregiver_smiles": self.caregiver_onsets,
                "learner_smile_rate": self.learner_onsets / seconds,
                "caregiver_smile_rate": self.caregiver_onsets / seconds,
                "smiling_fraction": self.smiling_steps / n, "gaze_fraction": self.gaze_steps / n,
                "shared_fraction": self.shared_steps / n,
                "response_rate": response, "baseline_rate": baseline,
                "contingency_index": response - baseline}


class Contingency(Task):
    name = "contingency"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 2000
    Options = ContingencyOptions

    def __init__(self, n_agents: int, options=None, /, **values):
        super().__init__(n_agents, options, **values)
        #: the condition of the next episodes (the option, or :meth:`set_condition`'s)
        self.condition = self.options.condition
        #: the condition of the current episode (set at reset)
        self.episode_condition = self.condition

    def set_condition(self, condition: str) -> None:
        """The condition from the next reset on (one of :data:`CONDITIONS`; the two-learner form
        allows "live" only)."""
        check_choice(self.name, "condition", condition, CONDITIONS)
        if condition != "live" and not self.options.scripted_partner:
            raise ConfigError(f"{self.name}: condition={condition!r} needs the scripted "
                              "caregiver (contingency_v0.scripted_env); with two learners "
                              "allowed: 'live'")
        self.condition = condition

    def agent_defaults(self, i, settings):
        scripted = i == 1 and self.options.scripted_partner
        out = {"expressions": True, "vestibular": False,
               "vision": False if scripted else {"width": EYE_SIZE, "height": EYE_SIZE}}
        if i == 0:
            out["posture"] = "standing"
        else:
            body = settings.get("body", "adult")
            out["body"] = body
            out["posture"] = "kneeling" if body == "adult" else "standing"
        return out

    def _held(self, i, config):
        """Agent i's held joints (rad): all, standing knees a little bent, or its own posture's
        angles (the kneeling adult)."""
        angles = held_angles(config, "standing", {"right_knee": -5, "left_knee": -5})
        return held_posture(tables_of(config), keep=(), angles=angles)

    def setup(self, i, config):
        plan = task_plan(self, "standing", self.options.distance, self._held, (0, 1))
        pos, facing = face_to_face(i, plan.distance)
        frozen = {**self._held(i, config), **plan.gaze[i]}
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=())

    # -- running -------------------------------------------------------------------------------
    def reset(self, env, rng):
        o = self.options
        self.episode_condition = self.condition
        self._names = tuple(env.possible_agents)
        self._weights = np.zeros(2) if o.reward_free else \
            np.array([1.0, 0.0 if o.scripted_partner else 1.0])
        self._need = max(1, math.ceil(o.success_fraction * env.max_steps - 1e-9))
        self.measures = ContingencyMeasures(round(o.window_s / env.dt), env.dt)
        self._state = (False, False, False, False)
        self._shared = np.zeros(2, bool)

    def _cues(self, env):
        from ..partners.cues import learner_cues
        a, b = self._names
        mine = learner_cues(env, a, b)
        gaze1 = True if self.options.scripted_partner else learner_cues(env, b, a).gaze_on_face
        return bool(mine.smiling), env.world.expression_of(1) == HAPPY, \
            bool(mine.gaze_on_face), bool(gaze1)

    def rewards(self, env):
        learner, caregiver, gaze0, gaze1 = self._cues(env)
        both = learner and caregiver
        self._shared = np.array([both and gaze0, both and gaze1])
        self.measures.update(learner, caregiver, gaze0, bool(self._shared[0]))
        self._state = (learner, caregiver, gaze0, bool(self._shared[0]))
        return self._weights * self._shared

    def plots(self):
        """Reward, each agent smiling (learner, caregiver), the shared smiles (what is
        rewarded) and the shared steps as a share of those success needs."""
        return [Plot.reward(),
                Plot("smiling", "0/1", lambda env: self._state[:2]),
                Plot("shared_smile", "0/1", lambda env: self._shared),
                Plot("shared_share", "of success",
                     lambda env: self.measures.shared_steps / self._need, per_agent=False)]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        keys = ("condition", "smiling", "caregiver_smiling", "gaze_on_face", "shared",
                "is_success", *ContingencyMeasures(1, 1.0).infos())
        return {k: "number" for k in keys}

    def terminations(self, env):
        m = self.measures
        learner, caregiver, gaze, shared = self._state
        common = {"condition": CONDITIONS.index(self.episode_condition), "smiling": learner,
                  "caregiver_smiling": caregiver, "gaze_on_face": gaze, "shared": shared,
                  **m.infos(), "is_success": m.shared_steps >= self._need}
        return np.zeros(2, bool), [dict(common) for _ in range(2)]


class ContingencyCaregiver(Partner):
    """The scripted caregiver of ``contingency_v0.scripted_env``: per episode, the task's
    condition (``env.task.episode_condition``) picks its behaviour. live: a
    :class:`~mimo_social.partners.contingent.ContingentCaregiver` answering the learner's smiles
    (cue "expression", face "smile", the task's ``response_delay_s``, ``response_probability``
    and ``response_duration_s``); non_contingent: the same caregiver in mode
    ``"non_contingent"``, smiling at the rate it answered in this env's last live episode (before
    any: ``timer_rate_hz``) on a timer; replay: a
    :class:`~mimo_social.partners.replay.ReplayCaregiver` of ``stream`` if given, else of the
    stream of this env's last live episode (:attr:`recorded`, kept when the next episode
    starts)."""

    def __init__(self, stream=None):
        if stream is not None:
            from ..partners.replay import check_stream
            stream = check_stream(stream, "ContingencyCaregiver")
        self.stream = stream
        self._recorded = None
        self.condition = None
        self._live = None
        self._active = None

    def __repr__(self):
        given = "None" if self.stream is None else f"<{len(self.stream['motors'])} steps>"
        return f"ContingencyCaregiver(stream={given})"

    @property
    def recorded(self) -> dict | None:
        """The caregiver's stream of the last live episode, the running one included (a dict of
        arrays, see :class:`~mimo_social.partners.replay.ReplayCaregiver`; save it with
        :func:`~mimo_social.partners.replay.save_stream`), or None before any."""
        live = self._live
        if live is not None and live.mode == "interactive" and len(live.stream["expression"]):
            return live.stream
        return self._recorded

    def _close_live(self) -> None:
        """Keep the live episode's stream and end its interactive period (the caregiver
        measures its response rates)."""
        live = self._live
        if live is not None and live.mode == "interactive":
            self._recorded = self.recorded
            live.set_mode("still")

    def reset(self, env, agent, rng):
        from ..partners.contingent import ContingentCaregiver
        from ..partners.replay import ReplayCaregiver
        super().reset(env, agent, rng)
        self._close_live()
        o = env.task.options
        self.condition = env.task.episode_condition
        if self._live is None:
            self._live = ContingentCaregiver(
                cues=("expression",), delay_s=o.response_delay_s,
                probability=o.response_probability, duration_s=o.response_duration_s)
        if self.condition == "replay":
            stream = self.stream if self.stream is not None else self._recorded
            if stream is None:
                raise RuntimeError(
                    "contingency: condition 'replay' plays back the caregiver of an earlier live "
                    "episode, and this env has run none: run a live episode first "
                    "(env.unwrapped.task.set_condition('live'), reset, step) or give "
                    "contingency_v0.scripted_env(stream=...) a recorded stream")
            self._active = ReplayCaregiver(stream)
        elif self.condition == "live" or self._live.measured_rates is not None:
            self._active = self._live
        else:   # non-contingent before any live episode: the timer's own rate
            self._active = ContingentCaregiver(
                cues=("expression",), duration_s=o.response_duration_s,
                rate_hz=o.timer_rate_hz, mode="non_contingent")
        self._active.reset(env, agent, rng)
        if self._active is self._live and self.condition == "non_contingent":
            self._live.set_mode("non_contingent")

    def act(self, env, agent, observation):
        if self._active is None:
            raise RuntimeError("ContingencyCaregiver.act() before reset(); reset the env first")
        return self._active.act(env, agent, observation)


# -- the per-condition summary ----------------------------------------------------------------
def summarize(finals: Sequence[Mapping[str, Any]]) -> dict[str, dict[str, tuple[float, float]]]:
    """Per condition, each :data:`MEASURES` entry's mean and sd over episodes, from each
    episode's last-step info (its ``condition`` code says the condition)."""
    out: dict[str, dict[str, tuple[float, float]]] = {}
    for code, cond in enumerate(CONDITIONS):
        rows = [f for f in finals if int(f["condition"]) == code]
        if not rows:
            continue
        out[cond] = {m: (float(np.mean([float(r[m]) for r in rows])),
                         float(np.std([float(r[m]) for r in rows]))) for m in MEASURES}
        out[cond]["episodes"] = (float(len(rows)), 0.0)
    return out


def condition_summary(episodes: int = 5, seed: int = 0, controller: Any = None,
                      conditions: Sequence[str] = CONDITIONS,
                      env_kwargs: Mapping[str, Any] | None = None,
                      policy: Callable | None = None) -> dict:
    """Blocks of one episode per condition (``conditions``, in that order; "replay" needs a
    "live" before it in a block and replays it), ``episodes`` blocks, the env reset with seed
    ``seed + block``; the learner is ``controller`` (a Partner for ``infant_0``, by default
    :class:`~mimo_social.partners.controllers.contingency.ContingencyDetectorController`, reset
    with a generator seeded per block and condition, so that it does not repeat its live
    actions in the replay) or ``policy`` (a callable observation -> action). Returns
    :func:`summarize` of the episodes."""
    from ..core.env import MimoParallelEnv
    from ..partners.wrapper import ScriptedPartners
    conditions = tuple(conditions)
    for c in conditions:
        check_choice("contingency", "conditions", c, CONDITIONS)
    if "replay" in conditions and ("live" not in conditions
                                   or conditions.index("live") > conditions.index("replay")):
        raise ConfigError("contingency: conditions list 'replay' without a 'live' before it; "
                          "allowed: e.g. ('live', 'replay', 'non_contingent')")
    if controller is None and policy is None:
        from ..partners.controllers.contingency import ContingencyDetectorController
        controller = ContingencyDetectorController()
    kwargs = dict(env_kwargs or {})
    options = kwargs.pop("task_options", None) or {}
    options = dataclasses.replace(options, scripted_partner=True) \
        if isinstance(options, ContingencyOptions) else {**options, "scripted_partner": True}
    # the scripted form of contingency_v0 (tasks sit below envs: built here from the core)
    env = ScriptedPartners(MimoParallelEnv(Contingency(2, options), **kwargs),
                           {"infant_1": ContingencyCaregiver()})
    inner = env.unwrapped
    finals = []
    for block in range(int(episodes)):
        for k, cond in enumerate(conditions):
            inner.task.set_condition(cond)
            obs, _ = env.reset(seed=seed + block)
            if controller is not None:
                rng = np.random.default_rng([seed + block, k])
                controller.reset(inner, "infant_0", rng)
            info = {}
            while env.agents:
                o = obs["infant_0"]
                action = controller.act(inner, "infant_0", o) if controller is not None \
                    else policy(o)
                obs, _, _, _, infos = env.step({"infant_0": action})
                info = infos.get("infant_0", info)
            finals.append(info)
    env.close()
    return summarize(finals)


def format_summary(table: Mapping[str, Mapping[str, tuple[float, float]]]) -> str:
    """A markdown table: one row per measure, one column per condition (mean +- sd)."""
    conds = list(table)
    lines = ["| measure | " + " | ".join(conds) + " |", "|---" * (len(conds) + 1) + "|"]
    for m in ("episodes", *MEASURES):
        cells = []
        for c in conds:
            mean, sd = table[c][m]
            cells.append(f"{mean:.0f}" if m == "episodes" else f"{mean:.3f} +- {sd:.3f}")
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
