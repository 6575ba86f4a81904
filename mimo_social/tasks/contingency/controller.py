"""``ContingencyDetectorController``: the scripted infant of the contingency paradigm.

reads:
    each step, from the world: its own face and the other agent's (``env.world.expression_of``);
    nothing else
estimates:
    Watson's contingency of the other's smiles on its own: ``p_after``, the share of its own smiles
    followed by the other's smile onset within ``window_s`` (1.5 s), minus ``p_base``, the share of
    its quiet windows (``window_s`` long, no smile onset of its own in them nor in the ``window_s``
    before) in which the other begins to smile; with prior counts (1 of 2 smiles answered, 1 of 4
    windows hit: an estimate of 0.25 at the start)
looks:
    with head and eye motors (the task option ``gaze_free``, on by default) at the other's face:
    :class:`~mimo_social.partners.gaze.GazeAtTarget`'s PD law on its head and eye motors, target
    the other's ``head_centre`` site (its other motors, if any, at rest); without them its gaze
    is the task's to hold
acts:
    smiles through its own ``expression`` action. From a neutral face it
    bids, a brief smile of ``bid_s`` (0.05 s), at a rate (per second) of ``base_rate`` (1.5) x
    exp(``gain`` (5) x (estimate - ``expected`` (0.25))), kept within 0.05-10; then it waits,
    neutral, up to ``window_s`` for an answer. An answer (the other's smile beginning after the
    bid began) it returns: it smiles as long as the other smiles (what it sees of the other's face
    now, so its smile ends a control step after the other's). Then a neutral pause drawn from
    ``pause_s`` (0.05-1 s) and, after an answered bid while its estimate is at least
    ``expected``, a new bid at once (a run of bids, each answered anew); but with probability
    ``probe`` (0.3) it stays neutral for a whole window instead (a test: does the other smile
    anyway?). Smiles of the other that answer no bid it does not return; unanswered bids and
    smiles that come regardless of its own lower its estimate and its bidding
why the pause and the probes:
    a replay of a live session is as rhythmic as the live answers; a learner that renewed its smile
    at a fixed moment would lock onto the replayed rhythm and see it as contingent. Random pauses
    move its smiles out of the recorded phase, and quiet probe windows measure how often the other
    smiles unprompted (never, when live)
expected pattern:
    more smiling (share of the steps), a higher contingency index and more shared smiling in live
    than in replay and non-contingent (`contingency_v0`'s table, `condition_summary`)

It writes no state; its randomness (when a bout begins) comes from the generator given at reset.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from ...expressions.faces import EXPRESSIONS
from ...util.checks import ConfigError, check_number, check_numbers, show
from ...partners.base import Partner, agent_index, zero_action
from ...partners.gaze import NEEDED as GAZE_MOTORS, GazeAtTarget

__all__ = ["ContingencyDetectorController"]

HAPPY = EXPRESSIONS.index("happy")
NEUTRAL = EXPRESSIONS.index("neutral")
#: prior counts: (answered, smiles) and (hit blocks, blocks)
PRIOR_AFTER = (1.0, 2.0)
PRIOR_BASE = (1.0, 4.0)
RATE_LIMITS = (0.05, 10.0)


class ContingencyDetectorController(Partner):
    """A contingency-detecting infant (see the module table)."""

    def __init__(self, window_s=1.5, base_rate=1.5, gain=5.0, expected=0.25, bid_s=0.05,
                 pause_s=(0.05, 1.0), probe=0.3):
        who = "ContingencyDetectorController"
        self.window_s = check_number(who, "window_s", window_s, 0.05, 10.0)
        self.base_rate = check_number(who, "base_rate", base_rate, 0.0, 100.0)
        self.gain = check_number(who, "gain", gain, 0.0, 100.0)
        self.expected = check_number(who, "expected", expected, -1.0, 1.0)
        self.bid_s = check_number(who, "bid_s", bid_s, 0.01, 10.0)
        self.pause_s = check_numbers(who, "pause_s", pause_s, 2, 0.0, 10.0,
                                     "(min, max) seconds, 0 <= min <= max <= 10")
        if self.pause_s[1] < self.pause_s[0]:
            raise ConfigError(f"{who}: pause_s={show(pause_s)} not allowed; allowed: (min, max) "
                              "seconds, 0 <= min <= max <= 10")
        self.probe = check_number(who, "probe", probe, 0.0, 1.0)
        self._action = None

    def __repr__(self):
        return (f"ContingencyDetectorController(window_s={self.window_s}, base_rate="
                f"{self.base_rate}, gain={self.gain}, expected={self.expected:.3g}, "
                f"bid_s={self.bid_s}, pause_s={self.pause_s}, probe={self.probe})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        space = env.action_space(agent)
        if not (isinstance(space, spaces.Dict) and "expression" in space.spaces):
            raise ValueError(f"ContingencyDetectorController acts through the expression, but "
                             f"{agent}'s action space has none ({space}); build the env with "
                             "expressions=True")
        me = agent_index(env, agent)
        others = [k for k in range(len(env.possible_agents)) if k != me]
        if not others:
            raise ValueError(f"ContingencyDetectorController: {agent} has no partner in this env")
        self._me, self._other = me, others[0]
        self._action = zero_action(space)
        self._gaze = None
        if set(GAZE_MOTORS) <= set(env.world.agents[me].actuated_names):
            face = f"{env.possible_agents[self._other]}/head_centre"
            self._gaze = GazeAtTarget(targets=[face], hold_s=(3600.0, 3600.0), head_share=1.0)
            # one target: its generator draws nothing that matters (this one's stays untouched)
            self._gaze.reset(env, agent, np.random.default_rng(0))
        self._dt = float(env.dt)
        self._window = max(1, int(round(self.window_s / self._dt)))
        self._pause = 0
        self._bid = max(1, int(round(self.bid_s / self._dt)))
        self.t = 0
        self._prev = (False, False)
        self.answered, self.smiles = PRIOR_AFTER
        self.hits, self.blocks = PRIOR_BASE
        self._open: list[int] = []         # own bids still waiting for an answer
        self._last_onset = -10 ** 9
        self._quiet = None                 # the running quiet window: [start, other's onset]
        self._probe_until = -1             # neutral until this step (a probe)
        self._in_bout = False
        self._bout_start = 0
        self._answer_at = None          # step of the answer to the current smile
        self._renewing = False          # smile again right after the pause
        self._idle_since = -10 ** 9

    @property
    def estimate(self) -> float:
        """The contingency it believes in: p_after - p_base."""
        return self.answered / self.smiles - self.hits / self.blocks

    @property
    def rate(self) -> float:
        """Its smile onsets per second now (from the neutral face)."""
        r = self.base_rate * math.exp(self.gain * (self.estimate - self.expected))
        return float(np.clip(r, *RATE_LIMITS))

    def _observe(self, env):
        """Update the estimate with the faces as the last step left them."""
        self.t += 1
        t = self.t
        mine = env.world.expression_of(self._me) == HAPPY
        theirs = env.world.expression_of(self._other) == HAPPY
        my_on, their_on = mine and not self._prev[0], theirs and not self._prev[1]
        self._prev = (mine, theirs)
        my_on = my_on and not theirs       # a bid: a smile begun while the other's face is not
        still = []
        for t0 in self._open:
            if their_on and t > t0:
                self.answered += 1
                self.smiles += 1
            elif t - t0 >= self._window:
                self.smiles += 1
            else:
                still.append(t0)
        self._open = still
        if my_on:
            self._open.append(t)
            self._last_onset = t
        # quiet windows: window-long spans without a smile onset of its own, starting at
        # least a window after its last one
        q = self._quiet
        if q is not None:
            q[1] |= their_on
            if my_on:
                self._quiet = None
            elif t - q[0] + 1 >= self._window:
                self.blocks += 1
                self.hits += q[1]
                self._quiet = None
        elif not mine and t - self._last_onset >= self._window:
            self._quiet = [t, their_on]
        return theirs, their_on

    def act(self, env, agent, observation):
        if self._action is None:
            raise RuntimeError("ContingencyDetectorController.act() before reset(); reset the "
                               "env first")
        theirs, their_on = self._observe(env)
        t = self.t
        if self._in_bout:
            answer = their_on and t > self._bout_start and self._answer_at is None
            if answer and t - self._bout_start <= self._window:
                self._answer_at = t
            if self._answer_at is not None:
                done = not theirs
            else:   # the bid, then the neutral wait; an answer is returned at once
                done = t - self._bout_start >= self._window
            if done:
                self._end_bout(t)
        elif t - self._idle_since >= self._pause and t >= self._probe_until:
            if self._renewing or self.rng.random() < 1.0 - math.exp(-self.rate * self._dt):
                self._in_bout = True
                self._bout_start = t
                self._answer_at = None
        smile = self._in_bout and (self._answer_at is not None
                                   or t - self._bout_start < self._bid)
        face = HAPPY if smile else NEUTRAL
        motors = self._action["motors"].copy() if self._gaze is None else \
            self._gaze.act(env, agent, observation)["motors"]
        return {"motors": motors, "expression": np.int64(face)}

    def _end_bout(self, t: int) -> None:
        """A bid's bout is over (its answer returned, or none came): a neutral pause, then a new
        bid at once after an answered one while the estimate holds, unless a probe."""
        self._in_bout = False
        self._idle_since = t
        self._pause = int(round(self.rng.uniform(*self.pause_s) / self._dt))
        self._renewing = self._answer_at is not None and self.estimate >= self.expected
        if self._renewing and self.rng.random() < self.probe:
            self._renewing = False
            self._probe_until = t + self._pause + self._window
