"""The PettingZoo ParallelEnv: N infants in one world, built from a task object.

Actions per agent: a ``Box`` of the agent's motor controls (spring-damper: one value in [-1, 1]
per motor; muscles: two values in [0, 1] per motor), or, when expressions or the voice are on, a
``Dict`` of ``"motors"``, ``"expression"`` (``Discrete(7)``) and ``"voice"`` (``Discrete(6)``)
with ``"loudness"`` (``Box(0, 1, (1,))``): :mod:`mimo_social.core.actions`. Motor values outside
the Box are **clipped** (learners' Gaussian policies overshoot); NaN/inf, a wrong shape, an
unknown agent, an id out of range or a loudness outside [0, 1] raise ``ValueError`` naming the
agent, the field and what is allowed. ``env.sounds``: every agent's sound of the last step.
A simulation that goes unstable ends the episode for every agent with the reason in
``infos[agent]["instability"]`` (a 1 in the numeric infos).

Infos are numbers by default: each agent's the same keys at reset and at every step
(:meth:`MimoParallelEnv.info_keys`, what clients that make tensors of them need, e.g. TorchRL's
``PettingZooWrapper``); ``info_text=True`` gives the text infos they are made from (the
expression's name, the reason of an instability, touched parts, a task's target part; key ->
kind: :meth:`MimoParallelEnv.info_spec`; the encoding: :mod:`mimo_social.core.infos`).

The senses come from the registry :data:`mimo_social.senses.SENSES`: for each registered sense
that an agent has on, a sense of its own, or one shared system for the world (the skin reads the
contacts once for everyone, the eyes of everyone share one renderer) with a sense per agent.
A sense with nothing to read (proprioception when every joint of the agent is held) is left out:
its key is absent from the observation, never an array of size 0.

Sensorimotor delays (``AgentConfig.delays``, :mod:`mimo_social.core.delays`): a sense delayed by
``k`` control steps observes at step ``t`` what it read at ``t - k`` (the reading at reset before
that); the controls applied at step ``t`` are those given at ``t - k`` (before that, those in force
at reset). ``env.controls``, the actuation part of proprioception and the infos' ``cost`` describe
the applied controls; task observations, sense infos and the expression are not delayed.
:meth:`MimoParallelEnv.delay_steps` gives each agent's delays in steps.
"""

from __future__ import annotations

import time
from typing import Any, Mapping, Sequence

import mujoco
import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from ..body.actuation import MODELS as ACTUATION_MODELS
from ..expressions.faces import EXPRESSIONS
from ..scenery import SCENES, check_scene_clear
from ..senses import SENSES
from ..util.checks import check_bool, check_choice, check_seed
from ..util.names import reject_old_names
from ..expressions.voice import SOUNDS, level_db
from .actions import action_space, check_action_keys, checked_action
from .config import ConfigError, env_settings, parse_physics, resolve_agents
from .delays import MotorDelay, SenseDelay, delay_steps, fill_sensor_history
from .ages import age_changes, age_options, grow
from .infos import InfoEncoder
from .rendering import SceneRendering
from .task import Task, agent_user_settings, check_start_poses
from .world import World

__all__ = ["MimoParallelEnv", "TIMING_KEYS"]

TIMING_KEYS = ("actuation", "physics", *SENSES, "task", "other")
def _empty(space) -> bool:
    """Whether an observation space holds no value (a Box with a 0 in its shape)."""
    shape = getattr(space, "shape", None)
    return shape is not None and 0 in shape


class MimoParallelEnv(SceneRendering, ParallelEnv):
    """N agents in one world doing ``task`` (PettingZoo's ParallelEnv API).

    What task hooks, partners and tools may read (the public view of the env):

    * ``env.world``: the compiled world (``model``, ``data``, per-agent index tables);
    * ``env.systems``: dict sense name -> the shared system of that sense (``"touch"``: the
      skin of every agent, ``"vision"``: the eyes of every agent), only for senses some agent
      has on; ``env.system(name)`` returns one or raises a ValueError saying how to turn it on;
    * ``env.controls``: per agent (index order) the motor controls applied at the last step,
      after clipping (with a motor delay of k steps: those given k steps before);
    * ``env.steps``: control steps since the last reset;
    * ``env.agent_configs``, ``env.physics``, ``env.dt``, ``env.timing`` (seconds per
      component, keys :data:`TIMING_KEYS`).
    """
    metadata = {"name": "mimo_social", "render_modes": ["rgb_array"], "is_parallelizable": True}
    #: the render modes accepted: "human" too (PettingZoo's render_test builds it), though it has
    #: no window here: ``render()`` then raises a RuntimeError saying to use "rgb_array"
    RENDER_MODES = ("rgb_array", "human")

    def __init__(self, task: Task, physics: Mapping[str, Any] | None = None,
                 per_agent: Sequence[Mapping[str, Any]] | None = None,
                 render_mode: str | None = None, max_steps: int | None = None,
                 render_size: tuple[int, int] = (480, 640), scene: str = "floor",
                 info_text: bool = False, **agent_settings):
        self.render_mode, self.max_steps, self.render_size = env_settings(
            render_mode, max_steps, render_size, task.default_max_steps,
            self.RENDER_MODES)
        #: where the agents are: "floor" (the bare floor) or "playroom" (docs/playroom.md)
        self.scene = check_choice("env", "scene", scene, SCENES)
        #: False (default): infos as numbers (info_keys); True: the text infos (info_spec)
        self.info_text = check_bool("env", "info_text", info_text)
        self.task = task
        n = task.n_agents
        defaults = [task.agent_defaults(i, own) for i, own in
                    enumerate(agent_user_settings(n, agent_settings, per_agent))]
        self.agent_configs = resolve_agents(n, agent_settings, per_agent, defaults)
        self.physics = parse_physics(physics, task.physics_overrides)
        self.frame_skip = self.physics.frame_skip
        self.dt = self.physics.timestep * self.frame_skip
        self.metadata = dict(self.metadata, render_fps=int(round(1.0 / self.dt)))
        # each agent's delays in control steps (vestibular: MuJoCo's sensor delay, set by World)
        self._delays = [delay_steps(cfg, self.dt) for cfg in self.agent_configs]
        task.configs = tuple(self.agent_configs)
        setups = [task.setup(i, cfg) for i, cfg in enumerate(self.agent_configs)]
        self.world = World(setups, task.props(), self.physics, scene=self.scene)
        check_start_poses(self.world)   # agents placed inside each other: a ConfigError
        check_scene_clear(self.world)   # ... or inside the play room's furniture
        self.possible_agents = list(self.world.names)
        self.agents = list(self.possible_agents)
        self._index = {name: i for i, name in enumerate(self.possible_agents)}
        self._bind()
        self._bind_task()
        self._rng = np.random.default_rng()
        self._pending_ages: dict[int, dict] = {}   # age changes for the next reset (set_age)
        self._was_reset = False   # step() before the first reset() is an error, not a crash
        self._renderer = None
        self.timing = dict.fromkeys(TIMING_KEYS, 0.0)
        self.steps = 0

    def _bind(self):
        """Actuation and senses of every agent, and the observation and action spaces.

        Each sense of the registry is built for the agents that have it on
        (:class:`mimo_social.senses.base.SenseEntry`); a sense with a shared system adds it to
        ``self.systems``, run once per step before the senses read.
        """
        w = self.world
        self.actuation, self.senses = [], []
        self.systems = {}
        self._obs_spaces, self._act_spaces = {}, {}
        self._needs_substep = False
        for i, (cfg, a) in enumerate(zip(self.agent_configs, w.agents)):
            by_name = {j.name: j for j in w.tables[i].joints}
            act = ACTUATION_MODELS[cfg.actuation]([by_name[n] for n in a.actuated_names],
                                                  a.actuator_ids)
            self._needs_substep |= act.needs_substep
            self.actuation.append(act)
            self.senses.append([])
        for key, entry in SENSES.items():
            configs = [getattr(c, key) for c in self.agent_configs]
            if not any(configs):
                continue
            system, per_agent = entry.build(w, configs, self.actuation)
            if system is not None:
                self.systems[key] = system
            for i, sense in enumerate(per_agent):
                # a sense with nothing to read (proprioception of an agent whose joints are all
                # held) is left out: its key is absent, never an array of size 0
                if sense is not None and not all(_empty(s) for s in sense.spaces.values()):
                    self.senses[i].append(sense)
        for i, name in enumerate(self.possible_agents):
            obs = {}
            for sense in self.senses[i]:
                obs.update(sense.spaces)
            obs.update(self.task.task_spaces(self, i))
            # an agent whose senses on have nothing to read (a scripted partner without eyes,
            # every joint held) observes an empty dict; every sense off is a mistake
            if not obs and not any(getattr(self.agent_configs[i], key) for key in SENSES):
                raise ConfigError(f"{name}: every sense is off; turn on at least one of "
                                  f"{', '.join(SENSES)}")
            self._obs_spaces[name] = spaces.Dict(obs)
            self._act_spaces[name] = action_space(self.agent_configs[i], self.actuation[i])
        self._expression = np.zeros(len(self.possible_agents), dtype=np.int64)
        # every agent's sound this step: (kind id of SOUNDS, level in dB SPL at 1 m)
        self._sounds = np.zeros((len(self.possible_agents), 2))
        self._voice_adult = np.array([c.body == "adult" for c in self.agent_configs])
        if "audition" in self.systems:
            self.systems["audition"].connect(self._sounds)
        self.controls = [np.zeros(act.n_controls) for act in self.actuation]
        n = len(self.possible_agents)
        self._sense_delays, self._motor_delays = [None] * n, [None] * n
        for i in range(n):
            self._delay_rings(i)

    def _delay_rings(self, i: int) -> None:
        """Agent ``i``'s rings: per sense (None: undelayed; vestibular: MuJoCo's), motors."""
        self._sense_delays[i] = [SenseDelay(k) if (k := self._delays[i][s.name]) and
                                 s.name != "vestibular" else None for s in self.senses[i]]
        k = self._delays[i]["motor"]
        self._motor_delays[i] = MotorDelay(k, self.actuation[i].n_controls) if k else None

    def advance(self, n: int) -> str | None:
        """``n`` physics steps with the controls in force, through the world's own step (the
        actuation models' per-step updates included, the state checked after each step); the
        reason string if the simulation went unstable (the world then restarted), else None.
        :meth:`step` advances ``frame_skip`` of them; a task settling its start state (at reset)
        advances as many as it needs."""
        w = self.world
        if not self._needs_substep:
            return w.step(n)
        m, d = w.model, w.data
        acts = self.actuation   # a model without per-step dynamics has a no-op substep

        def substep():
            for act in acts:
                act.substep(m, d)
        return w.step(n, substep)

    def _bind_task(self):
        """The task's index tables for this world (:meth:`Task.bind`): at construction, and at
        a reset when the task object was bound to another env's world since."""
        self.task.bind(self)
        self.task.bound_world = self.world

    def delay_steps(self, agent) -> dict[str, int]:
        """The delays of ``agent`` (name) in control steps, channel -> k (``round(ms / (1000 *
        dt))``, halves up; 0: undelayed)."""
        return dict(self._delays[self._index[self._check_agent(agent)]])

    def system(self, name: str):
        """The shared system of a sense (``"touch"``: the skin of every agent, ``"vision"``: the
        eyes of every agent), else a ValueError saying how to turn it on."""
        try:
            return self.systems[name]
        except KeyError:
            raise ValueError(f"this env has no {name} system (no agent has {name} on); make it "
                             f"with {name}=True; systems here: {sorted(self.systems)}") from None

    # -- PettingZoo API --------------------------------------------------------------------------
    def observation_space(self, agent):
        return self._obs_spaces[self._check_agent(agent)]

    def action_space(self, agent):
        return self._act_spaces[self._check_agent(agent)]

    def _check_agent(self, agent):
        if agent not in self._index:
            reject_old_names(agent, self.possible_agents)
            raise KeyError(f"unknown agent {agent!r}; agents of this env: {self.possible_agents}")
        return agent

    # -- another age at reset, without compiling (core/regrow.py) --------------------------------
    def set_age(self, age_months: float | None = None, motor_age_months: float | None = None,
                agent: str | None = None) -> None:
        """The body age and / or the motor age (months, 0 to 33; None: unchanged) of ``agent``
        (None: every infant) from the next :meth:`reset` on, written into the compiled model
        without compiling it again (:mod:`mimo_social.core.regrow`); ``reset(options=
        {"age_months": ..., "motor_age_months": ...})`` does the same at that reset (a number
        for every infant, or a dict agent -> months). Adults have no age: a ConfigError."""
        values = {"age_months": age_months, "motor_age_months": motor_age_months}
        for i, fields in age_changes(self.possible_agents, self.agent_configs, values, agent,
                                     "set_age").items():
            self._pending_ages.setdefault(i, {}).update(fields)

    def _grow(self, changes: dict) -> None:
        """Apply age changes (agent index -> {setting: months}): the world, motors, senses and
        props (:func:`~mimo_social.core.ages.grow`), then the delays and the task."""
        changed = grow(self, changes)
        if changed is None:        # the ages as they were: nothing to do
            return
        for i in changed:
            self._delays[i] = delay_steps(self.agent_configs[i], self.dt)
            self._delay_rings(i)
        self._bind_task()

    def reset(self, seed: int | None = None, options: dict | None = None):
        ages = age_options(options)   # a bad option or age: an error before anything changes
        changes = age_changes(self.possible_agents, self.agent_configs, ages, None,
                              "reset(options)") if ages else {}
        if check_seed(seed, "reset") is not None:   # a seed that is not an integer >= 0: a ConfigError
            self._rng = np.random.default_rng(int(seed))
        pending = self.__dict__.setdefault("_pending_ages", {})
        for i, fields in changes.items():
            pending.setdefault(i, {}).update(fields)
        if pending:
            self._pending_ages = {}
            self._grow(pending)
        w = self.world
        w.reset()
        for act in self.actuation:
            act.reset(w.model, w.data)
        self._expression[:] = 0
        self._sounds[:] = 0.0
        for c in self.controls:
            c[:] = 0.0
        if self.task.bound_world is not w:   # the task object was used by another env since
            self._bind_task()
        self.task.reset(self, self._rng)
        mujoco.mj_forward(w.model, w.data)
        check_start_poses(w, w.data, "after reset")   # a task placed agents inside each other
        fill_sensor_history(w.model, w.data, w.delayed_sensors)   # delayed vestibular sensors
        for system in self.systems.values():
            system.reset(w.model, w.data)
        self._update_shared()
        self.agents = list(self.possible_agents)
        self.steps = 0
        self._was_reset = True
        for c, ring in zip(self.controls, self._motor_delays):
            if ring is not None:
                ring.reset(c)
        obs = {a: self._observe(i, reset=True) for i, a in enumerate(self.agents)}
        infos = {a: self._info(i) for i, a in enumerate(self.agents)}
        return obs, self._infos_out(infos)

    def step(self, actions: Mapping[str, Any]):
        t0 = time.perf_counter()
        timing = self.timing
        if not getattr(self, "_was_reset", True):
            raise RuntimeError("step() called before reset(); call reset(seed=...) first")
        if not self.agents:
            raise RuntimeError("step() called after the episode ended; call reset() first")
        self._apply_actions(actions)
        t1 = time.perf_counter()
        timing["actuation"] += t1 - t0
        self.task.before_physics(self)
        t2 = time.perf_counter()
        timing["task"] += t2 - t1
        reason = self.advance(self.frame_skip)
        t3 = time.perf_counter()
        timing["physics"] += t3 - t2
        self.steps += 1
        self._update_shared()
        obs = {a: self._observe(self._index[a]) for a in self.agents}
        t4 = time.perf_counter()
        rewards = self.task.rewards(self)
        terminated, task_infos = self.task.terminations(self)
        t5 = time.perf_counter()
        timing["task"] += t5 - t4
        truncated = self.steps >= self.max_steps
        rew, term, trunc, infos = {}, {}, {}, {}
        for a in self.agents:
            i = self._index[a]
            rew[a] = float(rewards[i])
            term[a] = bool(terminated[i]) or reason is not None
            trunc[a] = truncated and not term[a]
            infos[a] = self._info(i)
            infos[a].update(task_infos[i])
            if reason is not None:
                infos[a]["instability"] = reason
        self.agents = [a for a in self.agents if not (term[a] or trunc[a])]
        timing["other"] += time.perf_counter() - t5
        return obs, rew, term, trunc, self._infos_out(infos)

    def _apply_actions(self, actions):
        if not (type(actions) is dict and actions.keys() == set(self.agents)):
            # not the common case (a dict with one action per live agent): look closer
            self._check_action_keys(actions)
        # every live agent's action is read and checked before any is applied: a bad action
        # leaves the env as it was (no agent's controls or face changed)
        checked = []
        index, actuation, check = self._index, self.actuation, self._checked_action
        for a in self.agents:
            i = index[a]
            checked.append((i, actuation[i], *check(i, a, actions[a])))
        w = self.world
        for i, act, expression, sound, u in checked:
            if expression is not None:
                self._expression[i] = expression
                w.set_expression(i, expression)
            if sound is not None:   # the sound of this control step
                self._sounds[i] = sound[0], level_db(*sound, self._voice_adult[i])
            # the env's own buffer: the caller's array is never written to nor kept
            c = self.controls[i]
            ring = self._motor_delays[i]
            # clipped into [low, high] by two ufuncs (np.clip's wrappers cost a few µs more)
            if ring is None:
                np.minimum(np.maximum(u, act.control_low, out=c), act.control_high, out=c)
            else:   # the controls given k steps ago are applied
                slot = ring.slot()
                np.minimum(np.maximum(u, act.control_low, out=slot), act.control_high, out=slot)
                np.copyto(c, ring.advance())
            act.apply(w.model, w.data, c)

    def check_action(self, agent: str, action) -> tuple[int | None, np.ndarray]:
        """``agent``'s action checked as :meth:`step` checks it (its voice too), nothing
        applied: its expression id (None with expressions off) and its motor commands (a float
        array of the motor Box's shape, finite, not clipped). A ValueError names the agent, the
        field (``motors``, ``expression``, ``voice``, ``loudness``), the value and what is
        allowed (:mod:`mimo_social.core.actions`); an unknown agent is a KeyError naming the
        agents. The recorder checks the actions it is given with it."""
        expression, _, motors = self._checked_action(self._index[self._check_agent(agent)],
                                                     agent, action)
        return expression, motors

    def _checked_action(self, i: int, agent: str, action):
        return checked_action(agent, self.agent_configs[i], self.actuation[i], action)

    def _check_action_keys(self, actions) -> None:
        check_action_keys(actions, self.agents, self._index, self.possible_agents)

    @property
    def sounds(self) -> np.ndarray:
        """Every agent's sound at the last step, ``(n_agents, 2)`` float64, read-only: per agent
        (index order) the kind id of :data:`~mimo_social.expressions.voice.SOUNDS` and its level
        in dB SPL at 1 m (silence, and agents with voice off: 0, 0). A sound lasts the control
        step it was given in; reset makes every agent silent."""
        view = self._sounds.view()
        view.flags.writeable = False
        return view

    def mute(self, agent: int) -> None:
        """Silence agent ``agent`` (its index) for this control step, whatever its action said:
        for a task's ``before_physics`` that holds an agent still (the still face's caregiver);
        what others hear this step and ``sounds`` say silence."""
        self._sounds[int(agent)] = 0.0

    def _observe(self, i: int, reset: bool = False) -> dict:
        m, d = self.world.model, self.world.data
        out = {}
        timing = self.timing
        t = time.perf_counter()
        for sense, ring in zip(self.senses[i], self._sense_delays[i]):
            if ring is None:
                sense.observe(m, d, out)
            else:
                reading = {}
                sense.observe(m, d, reading)
                out.update(ring.reset(reading) if reset else ring.push(reading))
            t2 = time.perf_counter()
            timing[sense.name] += t2 - t
            t = t2
        out.update(self.task.observe(self, i))
        timing["task"] += time.perf_counter() - t
        return out

    def _update_shared(self):
        m, d = self.world.model, self.world.data
        for system in self.systems.values():
            t = time.perf_counter()
            system.update(m, d)
            self.timing[system.name] += time.perf_counter() - t

    def _info(self, i: int) -> dict:
        act = self.actuation[i]
        u = self.controls[i]
        cost, weighted = act.costs(u)
        info = {"expression": EXPRESSIONS[self._expression[i]], "step": self.steps,
                "time": float(self.world.data.time), "cost": cost, "weighted_cost": weighted}
        if self.agent_configs[i].voice:
            info["voice"] = SOUNDS[int(self._sounds[i, 0])]
        for sense in self.senses[i]:
            if hasattr(sense, "info"):
                info.update(sense.info())
        return info

    def info_spec(self, agent) -> dict:
        """What ``infos[agent]`` may hold, key -> kind, for numeric views of the infos
        (:class:`mimo_social.core.wrappers.NumericInfos`): the env's keys, each sense's
        (``info_spec()`` of a sense) and the task's (``task.info_spec(i)``). Kinds:
        ``"number"``, ``"flag"`` (1 when present and true, else 0), ``"count"`` (a list's
        length), a tuple of strings (the string's index), ``"touch"`` (the touch info's counts)
        or a dict of sub-keys -> kinds (a nested dict)."""
        i = self._index[self._check_agent(agent)]
        spec = {"expression": tuple(EXPRESSIONS), "step": "number", "time": "number",
                "cost": "number", "weighted_cost": "number", "instability": "flag"}
        if self.agent_configs[i].voice:
            spec["voice"] = tuple(SOUNDS)
        for sense in self.senses[i]:
            if hasattr(sense, "info_spec"):
                spec.update(sense.info_spec())
        if hasattr(self.task, "info_spec"):
            spec.update(self.task.info_spec(i))
        return spec

    def info_keys(self, agent) -> tuple[str, ...]:
        """The keys of ``agent``'s numeric infos (the default; ``info_text=False``), in order:
        the same at reset and at every step."""
        return self._encoder().keys(self._check_agent(agent))

    def _encoder(self) -> InfoEncoder:
        enc = self.__dict__.get("_info_encoder")
        if enc is None:
            enc = self._info_encoder = InfoEncoder({a: self.info_spec(a)
                                                    for a in self.possible_agents})
        return enc

    def _infos_out(self, infos: dict) -> dict:
        return infos if self.info_text else self._encoder().encode_all(infos)

    def _has_faces(self) -> bool:
        return any(c.expressions for c in self.agent_configs)

    def state(self) -> np.ndarray:
        """The world's ``qpos`` then ``qvel``, then, when some agent has expressions on, every
        agent's expression id (float32, in :attr:`state_space`)."""
        d = self.world.data
        parts = [d.qpos, d.qvel]
        if self._has_faces():
            parts.append(self._expression)
        return np.concatenate(parts).astype(np.float32)

    @property
    def state_space(self) -> spaces.Box:
        """A float32 Box of the :meth:`state` values (the same object every time): unit
        quaternions of free and ball joints in [-1, 1] (MuJoCo keeps them normalised),
        expression ids in [0, 6], everything else unbounded (positions, velocities, and angles,
        which soft joint limits do not bound)."""
        space = self.__dict__.get("_state_space")
        if space is None:
            m = self.world.model
            low = np.full(m.nq + m.nv, -np.inf, np.float32)
            for j, kind in enumerate(m.jnt_type):
                start = int(m.jnt_qposadr[j])
                if kind == mujoco.mjtJoint.mjJNT_FREE:
                    low[start + 3:start + 7] = -1.0
                elif kind == mujoco.mjtJoint.mjJNT_BALL:
                    low[start:start + 4] = -1.0
            high = -low
            if self._has_faces():
                n = len(self.possible_agents)
                low = np.concatenate([low, np.zeros(n, np.float32)])
                high = np.concatenate([high, np.full(n, len(EXPRESSIONS) - 1, np.float32)])
            space = self._state_space = spaces.Box(low, high, dtype=np.float32)
        return space

    def close(self):
        for system in self.systems.values():
            if hasattr(system, "close"):
                system.close()
        self.close_renderer()

    # -- pickling (renderers never travel) -------------------------------------------------------
    def __getstate__(self):
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state
