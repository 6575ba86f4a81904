"""The demo: an 18-month-old and a kneeling caregiver play a high five, then the caregiver hands
the infant a ball; recorded, with both agents' eyes and skin, to one Rerun ``.rrd`` file.

One env (:func:`demo_env`: :class:`~mimo_social.experiments.demo_task.HighFiveThenHandover`,
``infant_0`` the published 18-month-old, ``caregiver_0`` the adult body kneeling, both with 64x64
eyes, skin on both arms and hands, faces), in the play room by default (``scene="playroom"``;
``"floor"``: the bare floor), runs two episodes one after the other, recorded by one
:class:`~mimo_social.recording.recorder.Recorder` on one continuous timeline (one recording):

1. **high five**: the caregiver holds its right hand out, palm forward; the infant's scripted
   controller brings its right palm onto it. At the high five (both right hands feel the
   other) both smile; they hold it :data:`CELEBRATE_S`.
2. **handover**: the caregiver holds the ball out in its palm; the infant holds an open hand
   beside it, the caregiver tips the ball into it and lets go once the infant's hand carries
   it. The infant looks surprised when the ball first touches its hand; both smile once the
   infant holds it alone. The scene then runs on (the infant holding the ball) to the end.
   (The ball waits on the mat beside the caregiver during the high five; the handover's reset
   lays it in the caregiver's palm.)

A phase that has not succeeded after :data:`HIGH_FIVE_WAIT_S` / :data:`HANDOVER_WAIT_S` is
reported as such (the high five then gives way to the handover). Every agent acts only through
its own action space (motors and the expression). The command is :mod:`mimo_social.cli.demo`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..core.factory import make_parallel
from ..expressions.faces import EXPRESSIONS
from ..recording.recorder import Recorder
from ..scenery import SCENES
from ..util.checks import ConfigError, check_int, check_number, show
from .demo_task import PHASES, HighFiveThenHandover, phase_partners

__all__ = ["CAREGIVER", "CELEBRATE_S", "DEFAULT_RECORDING", "DEFAULT_SCENE", "DEFAULT_SECONDS",
           "EYE_SIZE", "HANDOVER_WAIT_S", "HIGH_FIVE_WAIT_S", "SCENES", "DemoRun", "demo_env",
           "record_demo"]

DEFAULT_RECORDING = "recordings/demo.rrd"
#: simulated seconds the demo runs by default (the interaction takes about 5 s)
DEFAULT_SECONDS = 6.0
#: where it happens by default: the play room (docs/playroom.md); ``"floor"``: the bare floor
DEFAULT_SCENE = "playroom"
#: the shortest run: one control step
MIN_SECONDS = 0.01
#: the caregiver's settings (``caregiver_0``)
CAREGIVER = {"body": "adult", "posture": "kneeling"}
#: edge of the eye images (pixels)
EYE_SIZE = 64
#: simulated seconds of smiles after the high five, before the ball comes
CELEBRATE_S = 0.8
#: at most this long (simulated s) for the high five, then the handover starts anyway
HIGH_FIVE_WAIT_S = 3.0
#: at most this long (simulated s) for the handover
HANDOVER_WAIT_S = 6.0


@dataclass(frozen=True)
class DemoRun:
    """What :func:`record_demo` wrote and what happened.

    ``seconds``: the recording's simulated length; ``high_five_s`` / ``handover_s``: when the
    high five / the handover succeeded on the recording's ``sim_time`` timeline (None: it did
    not); ``faces``: every expression shown, as (sim_time s, agent, expression);
    ``contact_events``: new contacts between the two agents' body parts; ``eye_frames``: eye
    image pairs recorded; ``stopped``: why the run ended before ``seconds`` (None: it ran to
    the end); ``phases``: the phases that started (both, unless ``seconds`` cut the run in the
    first)."""

    path: Path
    scene: str
    seed: int
    steps: int
    seconds: float
    high_five_s: float | None
    handover_s: float | None
    contact_events: int
    eye_frames: int
    faces: tuple = field(default_factory=tuple)
    stopped: str | None = None
    agents: tuple = ("infant_0", "caregiver_0")
    phases: tuple = PHASES


def demo_env(scene: str = DEFAULT_SCENE, eye_size: int = EYE_SIZE):
    """The demo's env: the infant ``infant_0`` and the kneeling caregiver ``caregiver_0`` with
    faces, ``eye_size`` eyes and the handover's skin, in ``scene``."""
    return make_parallel(HighFiveThenHandover, per_agent=[{}, dict(CAREGIVER)],
                         expressions=True, vision={"width": eye_size, "height": eye_size},
                         task_options={"end_on_success": False}, max_steps=10**9,
                         scene=check_scene(scene), info_text=True)   # a reason if unstable


def check_scene(scene) -> str:
    if not isinstance(scene, str) or scene not in SCENES:
        raise ConfigError(f"demo: scene={show(scene)} not allowed; allowed: {list(SCENES)}")
    return scene


class _Director:
    """The faces of the two agents, changed by the events of the interaction, and when each
    phase succeeded."""

    def __init__(self, agents):
        self.receiver, self.giver = agents
        self.shown = {a: "neutral" for a in agents}
        self.times: dict[str, float] = {}

    def reset(self):
        self.shown = {a: "neutral" for a in self.shown}   # the world resets faces to neutral

    def react(self, phase: str, info: dict, now: float) -> list[tuple[str, str]]:
        """The receiver's ``info`` after a step at ``now`` (s): the faces that change,
        (agent, expression)."""
        before = dict(self.shown)
        if info.get("is_success") and phase not in self.times:
            self.times[phase] = now
            self.shown = {a: "happy" for a in self.shown}
        elif phase == "handover" and info.get("receiver_parts") and phase not in self.times \
                and self.shown[self.receiver] == "neutral":
            self.shown[self.receiver] = "surprised"   # the ball first touches its hand
        return [(a, e) for a, e in self.shown.items() if before[a] != e]

    def apply(self, actions: dict) -> dict:
        for a, action in actions.items():
            if isinstance(action, dict) and "expression" in action:
                action["expression"] = EXPRESSIONS.index(self.shown[a])
        return actions


def record_demo(path: str | Path = DEFAULT_RECORDING, seconds: float = DEFAULT_SECONDS,
                seed: int = 0, scene: str = DEFAULT_SCENE, progress: bool = True) -> DemoRun:
    """Run the demo (see the module docstring) for ``seconds`` simulated seconds (the script
    is cut there if it is not done) and record it to ``path`` (its folder is created)."""
    seconds = check_number("demo", "seconds", seconds, MIN_SECONDS)
    seed = check_int("demo", "seed", seed, 0, 2**32 - 1)
    check_scene(scene)
    path = Path(path)
    env = demo_env(scene)
    try:
        return _run(env, path, seconds, seed, scene, progress)
    finally:
        env.close()


def _run(env, path, seconds, seed, scene, progress) -> DemoRun:
    task = env.task
    dt = env.dt
    total = max(1, round(seconds / dt))
    receiver = env.possible_agents[0]
    director = _Director(env.possible_agents)
    faces, started = [], []
    steps, offset, now, stopped = 0, 0.0, 0.0, None
    bar = tqdm(total=total, desc="demo", unit="step", disable=not progress)
    with Recorder(env, path, recording_name=f"mimo-social demo (seed {seed}, {scene})") as rec:
        for k, phase in enumerate(PHASES):
            if steps >= total:
                break
            task.phase = phase
            started.append(phase)
            obs, _ = env.reset(seed=seed + k)
            if k:   # the recorder continues the timeline one step after the last episode
                offset = now + dt - float(env.world.data.time)
            director.reset()
            rec.log_reset(obs)
            faces += [(offset + float(env.world.data.time), a, "neutral") for a in director.shown]
            partners = phase_partners(env, phase)
            for j, (a, p) in enumerate(partners.items()):
                p.reset(env, a, np.random.default_rng([seed, k, j]))
            wait = HIGH_FIVE_WAIT_S if phase == "high_five" else HANDOVER_WAIT_S
            phase_steps = 0
            while steps < total:
                actions = director.apply({a: p.act(env, a, obs.get(a))
                                          for a, p in partners.items()})
                obs, rewards, _, _, infos = env.step(actions)
                rec.log_step(actions, rewards, obs)
                steps += 1
                phase_steps += 1
                bar.update()
                now = offset + float(env.world.data.time)
                info = infos.get(receiver, {})
                # a face chosen now shows from the next step on
                faces += [(now + dt, a, e) for a, e in director.react(phase, info, now)]
                done_at = director.times.get(phase)
                if not env.agents:
                    stopped = ("the ball fell" if info.get("dropped")
                               else next((i.get("instability") for i in infos.values()
                                          if i.get("instability")), "every agent is done"))
                    break
                if phase == "high_five" and (
                        (done_at is not None and now - done_at >= CELEBRATE_S - 1e-9)
                        or (done_at is None and phase_steps * dt >= HIGH_FIVE_WAIT_S - 1e-9)):
                    break
                if phase == "handover" and done_at is None and phase_steps * dt >= wait - 1e-9:
                    stopped = f"no handover within {wait:g} s"
                    break
            if stopped:
                break
        bar.close()
        contact_events, eye_frames = rec.contact_events, rec.eye_frames
    faces = tuple(f for f in faces if f[0] <= now + 1e-9)
    return DemoRun(path, scene, seed, steps, now, director.times.get("high_five"),
                   director.times.get("handover"), contact_events, eye_frames, faces, stopped,
                   tuple(env.possible_agents), tuple(started))
