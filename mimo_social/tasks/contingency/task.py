"""The contingency task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...core.task import Plot, Task, TaskOptions
from ...expressions.faces import EXPRESSIONS
from ...partners.base import Partner
from ...util.checks import ConfigError, check_choice
from ..facing_pair import FacingPair
from ...core.factory import make_aec, make_parallel, with_options

__all__ = ["CONDITIONS", "MEASURES", "ContingencyOptions", "Contingency", "ContingencyCaregiver",
           "ContingencyMeasures",
           "parallel_env", "env", "scripted_env"]

DISTANCE = 0.3
EYE_SIZE = 64
HAPPY = EXPRESSIONS.index("happy")
#: the conditions, in the order of their info code
CONDITIONS = ("live", "replay", "non_contingent")
#: the per-episode measures of the summary (last-step infos)
MEASURES = ("learner_smile_rate", "smiling_fraction", "gaze_fraction", "response_rate",
            "baseline_rate", "contingency_index", "caregiver_smile_rate", "shared_fraction",
            "matched_fraction", "is_success")


@dataclass(frozen=True)
class ContingencyOptions(TaskOptions):
    """The condition (live, replay, non-contingent), the distance between the faces (m), the
    scripted caregiver's response delay (s: at least ``response_delay_s``, plus a uniform draw
    up to ``response_jitter_s``), probability and duration, the contingency index's window (s),
    the cost of a smiling step that is not shared, the share of shared-smile steps and the
    share of the learner's smiling steps that are shared (``success_match``) for success,
    reward-free mode, whether the learner's head and eyes are free (``gaze_free``, on) and
    whether the caregiver (``caregiver_0``) is scripted (no eyes, no reward)."""

    task = "contingency"
    condition: str = "live"
    distance: float = DISTANCE
    response_delay_s: float = 0.3
    response_jitter_s: float = 1.0
    response_probability: float = 0.8
    response_duration_s: float = 1.0
    timer_rate_hz: float = 0.5
    window_s: float = 1.5
    unshared_cost: float = 1.0
    success_fraction: float = 0.2
    success_match: float = 0.85
    reward_free: bool = False
    gaze_free: bool = True
    scripted_partner: bool = False

    def __post_init__(self):
        self._choice("condition", CONDITIONS)
        self._number("distance", 0.25, 2.0)   # closer, two infants' toes overlap
        self._number("response_delay_s", 0.0, 5.0)
        self._number("response_jitter_s", 0.0, 5.0)
        self._number("response_probability", 0.0, 1.0)
        self._number("response_duration_s", 0.01, 10.0)
        self._number("timer_rate_hz", 0.0, 10.0)
        self._number("window_s", 0.05, 10.0)
        self._number("unshared_cost", 0.0, 10.0)
        self._number("success_fraction", 0.01, 1.0)
        self._number("success_match", 0.0, 1.0)
        self._bool("reward_free")
        self._bool("gaze_free")
        self._bool("scripted_partner")
        if self.condition != "live" and not self.scripted_partner:
            raise ConfigError(
                f"{self.task}: task option condition={self.condition!r} needs the scripted "
                "caregiver (contingency_v0.scripted_env); with two learners allowed: 'live'")


class ContingencyMeasures:
    """The paradigm's running measures over one episode, fed one step at a time with whether
    the learner smiles, the caregiver smiles and the learner looks at the caregiver's face (see
    the task table's ``infos`` row); ``window``: the contingency window in steps. A learner's
    smile onset while the caregiver's face is neutral is a bid: the response and baseline rates
    count bids (a smile returned to the caregiver's own smile asks for nothing)."""

    def __init__(self, window: int, dt: float):
        self.window, self.dt = max(1, int(window)), float(dt)
        self.steps = 0
        self.prev = (False, False)
        self.smiling_steps = self.gaze_steps = self.shared_steps = 0
        self.learner_onsets = self.caregiver_onsets = self.bids = 0
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
        bid = l_on and not caregiver
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
        self.learner_onsets += l_on
        if bid:
            self.bids += 1
            self.open.append(t)
            self.last_onset = t
        # control blocks: window-long blocks with no bid in them or in the window before them
        self.block_learner |= bid
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
        matched = self.shared_steps / self.smiling_steps if self.smiling_steps else 0.0
        return {"shared_steps": self.shared_steps, "learner_smiles": self.learner_onsets,
                "learner_bids": self.bids, "caregiver_smiles": self.caregiver_onsets,
                "learner_smile_rate": self.learner_onsets / seconds,
                "caregiver_smile_rate": self.caregiver_onsets / seconds,
                "smiling_fraction": self.smiling_steps / n, "gaze_fraction": self.gaze_steps / n,
                "shared_fraction": self.shared_steps / n, "matched_fraction": matched,
                "response_rate": response, "baseline_rate": baseline,
                "contingency_index": response - baseline}


class Contingency(FacingPair, Task):
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
        return {**out, **self.pair_defaults(i, settings)}

    # -- running -------------------------------------------------------------------------------
    def reset(self, env, rng):
        o = self.options
        self.episode_condition = self.condition
        self._names = tuple(env.possible_agents)
        self._weights = np.zeros(2) if o.reward_free else \
            np.array([1.0, 0.0 if o.scripted_partner else 1.0])
        self._need = max(1, math.ceil(o.success_fraction * env.max_steps - 1e-9))
        self._match = float(o.success_match)
        self._cost = float(o.unshared_cost)
        self.measures = ContingencyMeasures(round(o.window_s / env.dt), env.dt)
        self._state = (False, False, False, False)
        self._shared = np.zeros(2, bool)

    def _cues(self, env):
        from ...partners.cues import learner_cues
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
        unshared = np.array([learner, caregiver]) & ~self._shared
        return self._weights * (self._shared - self._cost * unshared)

    def succeeded(self) -> bool:
        """The episode's verdict so far: enough shared-smile steps, and enough of the
        learner's smiling shared (the task table's success row)."""
        m = self.measures
        return m.shared_steps >= self._need and m.shared_steps >= self._match * m.smiling_steps

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
                  **m.infos(), "is_success": self.succeeded()}
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
            from ...partners.replay import check_stream
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

    def check(self, env, agent) -> None:
        """When the env is made (``scripted_env``): the task's condition "replay" needs a stream
        to play back, ``stream`` or an earlier live episode's, and a given stream must fit
        ``agent``; else a ConfigError naming the field, the value and what is needed."""
        if self.stream is not None:
            from ...partners.replay import ReplayCaregiver
            ReplayCaregiver(self.stream).check(env, agent)
        elif env.task.condition == "replay" and self.recorded is None:
            raise ConfigError(
                "contingency: task option condition='replay' needs a recorded caregiver to play "
                "back, and this env has none: give contingency_v0.scripted_env(stream=...) one "
                "(ContingencyCaregiver.recorded after a live episode, or load_stream(path)), or "
                "make the env with condition='live' and switch with env.unwrapped.task."
                "set_condition('replay') after a live episode; allowed without a stream: "
                "'live', 'non_contingent'")

    def _close_live(self) -> None:
        """Keep the live episode's stream and end its interactive period (the caregiver
        measures its response rates)."""
        live = self._live
        if live is not None and live.mode == "interactive":
            self._recorded = self.recorded
            live.set_mode("still")

    def reset(self, env, agent, rng):
        from ...partners.contingent import ContingentCaregiver
        from ...partners.replay import ReplayCaregiver
        super().reset(env, agent, rng)
        self._close_live()
        o = env.task.options
        self.condition = env.task.episode_condition
        if self._live is None:
            self._live = ContingentCaregiver(
                cues=("expression",), delay_s=o.response_delay_s,
                delay_jitter_s=o.response_jitter_s, refractory=True,
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


# -- the env factories (``mimo_social.envs.contingency_v0`` re-exports them) --------------

def parallel_env(**kwargs):
    return make_parallel(Contingency, **kwargs)


def env(**kwargs):
    return make_aec(Contingency, **kwargs)


def scripted_env(partner=None, stream=None, **kwargs):
    from ...partners import ScriptedPartners
    options = with_options(Contingency, kwargs.pop("task_options", None), scripted_partner=True)
    penv = parallel_env(task_options=options, **kwargs)
    # the partner: the second agent (caregiver_0 when it is the adult)
    partner = partner or ContingencyCaregiver(stream=stream)
    if isinstance(partner, ContingencyCaregiver):   # replay's stream, checked now, not at reset
        partner.check(penv, penv.possible_agents[1])
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner})
