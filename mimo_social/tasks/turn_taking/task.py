"""The turn-taking task: the Task, its options, its caregiver and its env factories (table: the
package docstring)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.factory import make_aec, make_parallel, with_options
from ...core.task import Plot, Task, TaskOptions
from ...expressions.voice import SOUNDS
from ...partners.base import Partner, zero_action
from ...util.checks import ConfigError, check_choice
from ..facing_pair import FacingPair
from .schedule import (ContingentSchedule, Latency, TimedSchedule, poisson_onsets, steps_of,
                       yoked_onsets)
from .turns import INFO_KEYS, TurnMeasures

__all__ = ["CONDITIONS", "MEASURES", "TurnTakingOptions", "TurnTaking", "TurnTakingCaregiver",
           "parallel_env", "env", "scripted_env"]

DISTANCE = 0.3
SPEECH = SOUNDS.index("speech")
#: the conditions, in the order of their info code
CONDITIONS = ("contingent", "noncontingent", "replay")
#: the per-episode measures of the summary (last-step infos)
MEASURES = ("infant_rate_per_min", "speech_like_fraction", "vocal_fraction",
            "caregiver_rate_per_min", "mean_latency_s", "answered_fraction", "turns",
            "mean_turn_gap_s", "answers", "is_success")


@dataclass(frozen=True)
class TurnTakingOptions(TaskOptions):
    """The condition, the distance between the pair (m), the scripted caregiver's answer
    latency (lognormal mean and sd, s, from the offset of the infant's vocalisation), its answer
    probability, its utterance (s) and loudness, the non-contingent rate before any contingent
    episode, the turn window (s), the answers success needs, reward-free mode, whether the
    learner's head and eyes are free and whether the caregiver is scripted."""

    task = "turn_taking"
    condition: str = "contingent"
    distance: float = DISTANCE
    latency_mean_s: float = 0.7
    latency_sd_s: float = 0.3
    response_probability: float = 0.8
    utterance_s: float = 1.0
    caregiver_loudness: float = 0.25
    timer_rate_hz: float = 0.25
    window_s: float = 1.0
    min_vocal_s: float = 0.2
    success_answers: int = 10
    reward_free: bool = False
    gaze_free: bool = True
    scripted_partner: bool = False

    def __post_init__(self):
        self._choice("condition", CONDITIONS)
        self._number("distance", 0.25, 2.0)
        self._number("latency_mean_s", 0.01, 10.0)
        self._number("latency_sd_s", 0.0, 10.0)
        self._number("response_probability", 0.0, 1.0)
        self._number("utterance_s", 0.01, 10.0)
        self._number("caregiver_loudness", 0.0, 1.0)
        self._number("timer_rate_hz", 0.0, 10.0)
        self._number("window_s", 0.05, 10.0)
        self._number("min_vocal_s", 0.01, 5.0)
        self._int("success_answers", 1, 10_000)
        self._bool("reward_free")
        self._bool("gaze_free")
        self._bool("scripted_partner")
        if self.condition != "contingent" and not self.scripted_partner:
            raise ConfigError(
                f"{self.task}: task option condition={self.condition!r} needs the scripted "
                "caregiver (turn_taking_v0.scripted_env); with two learners allowed: "
                "'contingent'")


class TurnTaking(FacingPair, Task):
    name = "turn_taking"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 6000
    Options = TurnTakingOptions

    def __init__(self, n_agents: int, options=None, /, **values):
        super().__init__(n_agents, options, **values)
        #: the condition of the next episodes (the option, or :meth:`set_condition`'s)
        self.condition = self.options.condition
        #: the condition of the current episode (set at reset)
        self.episode_condition = self.condition

    def set_condition(self, condition: str) -> None:
        """The condition from the next reset on (one of :data:`CONDITIONS`; the two-learner form
        allows "contingent" only)."""
        check_choice(self.name, "condition", condition, CONDITIONS)
        if condition != "contingent" and not self.options.scripted_partner:
            raise ConfigError(f"{self.name}: condition={condition!r} needs the scripted "
                              "caregiver (turn_taking_v0.scripted_env); with two learners "
                              "allowed: 'contingent'")
        self.condition = condition

    def agent_defaults(self, i, settings):
        out = {"expressions": False, "voice": True, "vestibular": False, "vision": False,
               "audition": not (i == 1 and self.options.scripted_partner)}
        return {**out, **self.pair_defaults(i, settings)}

    # -- running -------------------------------------------------------------------------------
    def reset(self, env, rng):
        o = self.options
        self.episode_condition = self.condition
        self._weights = np.zeros(2) if o.reward_free else \
            np.array([1.0, 0.0 if o.scripted_partner else 1.0])
        self.measures = TurnMeasures(env.dt, o.window_s, o.min_vocal_s)
        self._kinds = (0, 0)
        self._answer = self._care_on = False

    def rewards(self, env):
        s = env.sounds
        self._kinds = (int(s[0, 0]), int(s[1, 0]))
        happened = self.measures.update(*self._kinds)
        self._answer, self._care_on = bool(happened["answer"]), bool(happened["caregiver_onset"])
        return self._weights * self._answer

    def plots(self):
        """Reward, each agent's sound kind (an id of SOUNDS) and the caregiver's utterance
        onsets as an event line: 2 on the step an answer begins (an onset within ``window_s``
        of the infant's offset, the reward's event), 1 on another onset, else 0."""
        return [Plot.reward(),
                Plot("sound", "kind id", lambda env: self._kinds),
                Plot("caregiver_answer", "2 answer, 1 other utterance",
                     lambda env: 2.0 if self._answer else float(self._care_on),
                     per_agent=False)]

    def info_spec(self, i):
        keys = ("condition", "infant_sound", "caregiver_sound", "answer", "answers",
                "is_success", *INFO_KEYS)
        return {k: "number" for k in keys}

    def terminations(self, env):
        m = self.measures
        common = {"condition": CONDITIONS.index(self.episode_condition),
                  "infant_sound": self._kinds[0], "caregiver_sound": self._kinds[1],
                  "answer": self._answer, "answers": m.answered, **m.infos(),
                  "is_success": m.answered >= self.options.success_answers}
        return np.zeros(2, bool), [dict(common) for _ in range(2)]


class TurnTakingCaregiver(Partner):
    """The scripted caregiver of ``turn_taking_v0.scripted_env``: per episode the task's
    condition (``env.task.episode_condition``) picks its schedule (:mod:`.schedule`).
    contingent: it answers the offsets of the infant's vocalisations (read from ``env.sounds``
    as the last step left them) with "speech" after the task's latency, with its probability;
    noncontingent: as many utterances as it made in this env's last contingent episode, at
    random times drawn at reset (before any: a Poisson process at ``timer_rate_hz``); replay:
    the utterances of ``onsets`` if given, else of this env's last contingent episode, at the
    same steps. Every utterance lasts ``utterance_s`` at ``caregiver_loudness``; its motors
    rest (all its joints are held). ``recorded``: the onsets (steps) of the last contingent
    episode, the running one included."""

    def __init__(self, onsets=None):
        if onsets is not None:
            try:
                onsets = [int(o) for o in onsets]
            except (TypeError, ValueError):
                onsets = None
            if onsets is None or any(o < 0 for o in onsets):
                raise ConfigError("TurnTakingCaregiver: onsets not allowed; allowed: a list of "
                                  "utterance onsets (control steps >= 0), e.g. "
                                  "TurnTakingCaregiver.recorded after a contingent episode")
        self.onsets = onsets
        self._recorded: list[int] | None = None
        self._live: ContingentSchedule | None = None
        self._schedule = None
        self.condition = None

    def __repr__(self):
        given = "None" if self.onsets is None else f"<{len(self.onsets)} onsets>"
        return f"TurnTakingCaregiver(onsets={given})"

    @property
    def recorded(self) -> list[int] | None:
        if self._live is not None and self._schedule is self._live:
            return list(self._live.onsets)
        return None if self._recorded is None else list(self._recorded)

    @property
    def events(self) -> list[dict]:
        """The eligible offsets of the running (or last) contingent episode: ``step``,
        ``answered``, ``latency_steps`` (:class:`~.schedule.ContingentSchedule`)."""
        return [] if self._live is None else [dict(e) for e in self._live.events]

    def check(self, env) -> None:
        """When the env is made: "replay" needs onsets to play back."""
        if env.task.condition == "replay" and self.onsets is None and self.recorded is None:
            raise ConfigError(
                "turn_taking: task option condition='replay' needs a recorded caregiver to play "
                "back, and this env has none: give turn_taking_v0.scripted_env(onsets=...) "
                "(TurnTakingCaregiver.recorded after a contingent episode), or make the env "
                "with condition='contingent' and switch with env.unwrapped.task."
                "set_condition('replay') after a contingent episode; allowed without onsets: "
                "'contingent', 'noncontingent'")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        self._recorded = self.recorded
        o = env.task.options
        self.condition = env.task.episode_condition
        self._dt = float(env.dt)
        steps = max(1, steps_of(o.utterance_s, self._dt))
        self._me = env.possible_agents.index(agent)
        self._other = 1 - self._me
        if self.condition == "contingent":
            self._live = ContingentSchedule(Latency(o.latency_mean_s, o.latency_sd_s),
                                            o.response_probability, steps, self._dt)
            self._schedule = self._live
        elif self.condition == "replay":
            onsets = self.onsets if self.onsets is not None else self._recorded
            if onsets is None:
                raise RuntimeError(
                    "turn_taking: condition 'replay' plays back the caregiver of an earlier "
                    "contingent episode, and this env has run none: run a contingent episode "
                    "first or give turn_taking_v0.scripted_env(onsets=...)")
            self._schedule = TimedSchedule(onsets, steps)
        else:
            if self._recorded is not None:
                n = min(len(self._recorded), env.max_steps // (steps + 1))
                onsets = yoked_onsets(n, env.max_steps, steps, rng)
            else:
                onsets = poisson_onsets(o.timer_rate_hz, env.max_steps, self._dt, steps, rng)
            self._schedule = TimedSchedule(onsets, steps)
        self._schedule.reset(rng)
        self._action = zero_action(env.action_space(agent))
        self._loud = np.array([o.caregiver_loudness], np.float32)

    def act(self, env, agent, observation):
        if self._schedule is None:
            raise RuntimeError("TurnTakingCaregiver.act() before reset(); reset the env first")
        infant_vocal = env.sounds[self._other, 0] != 0
        speaks = self._schedule.step(bool(infant_vocal))
        action = dict(self._action)
        action["voice"] = np.int64(SPEECH if speaks else 0)
        action["loudness"] = self._loud.copy()
        return action


# -- the env factories (``mimo_social.envs.turn_taking_v0`` re-exports them) --------------

def parallel_env(**kwargs):
    return make_parallel(TurnTaking, **kwargs)


def env(**kwargs):
    return make_aec(TurnTaking, **kwargs)


def scripted_env(partner=None, onsets=None, **kwargs):
    from ...partners import ScriptedPartners
    options = with_options(TurnTaking, kwargs.pop("task_options", None), scripted_partner=True)
    penv = parallel_env(task_options=options, **kwargs)
    partner = partner or TurnTakingCaregiver(onsets=onsets)
    if isinstance(partner, TurnTakingCaregiver):
        partner.check(penv)
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner})

