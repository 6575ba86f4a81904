"""N worlds of one CPU env's scene stepped together on MuJoCo Warp (``mujoco_warp``).

:class:`BatchedEnv` takes an env of the catalogue as built on the CPU (e.g.
``free_play_v0.parallel_env(n_agents=2)``), resets it once, puts its compiled model on the
Warp device and makes ``nworld`` copies of its reset state there. Each :meth:`BatchedEnv.step`
maps every agent's batched motor actions to controls as the CPU env does
(:mod:`mimo_social.gpu.controls`), advances every world by the env's ``frame_skip`` physics
steps of its ``timestep`` and reads every agent's proprioception and vestibular sense in the
CPU senses' layouts (:mod:`mimo_social.gpu.proprioception`, :mod:`mimo_social.gpu.vestibular`).
Actions and observations are torch tensors on the device (``wp.to_torch``: no copy); numpy
actions are taken too. On a GPU, Warp works on torch's current stream and the physics steps of
a control step are one CUDA graph (this path has not run on a GPU yet: no GPU was lent when it
was written, docs/gpu.md). :meth:`BatchedEnv.snapshot` and :meth:`BatchedEnv.load` put the
state of the CPU env, reset with another seed, into chosen worlds (the task env's resets:
:mod:`mimo_social.gpu.task_env`).

Touch: every agent's skin on the device (:mod:`mimo_social.gpu.skin`), in the CPU sense's
layout, where the CPU env has touch on (``touch=False`` leaves it out).
Muscles: torques in torch before every physics step (:mod:`mimo_social.gpu.muscles`).
Eyes: every agent's eye images rendered by MuJoCo Warp's batch renderer
(:mod:`mimo_social.gpu.eyes`), where the CPU env has vision on (``eyes=False`` leaves them out).
Expressions: each world's faces (:mod:`mimo_social.gpu.faces`), given to :meth:`BatchedEnv.step`
beside the motors. What stays on the CPU (docs/gpu.md): the other senses (audition, the
``faces`` sense) and the voice. The
task's logic is not here: :class:`~mimo_social.gpu.task_env.BatchedTaskEnv` adds it (reach,
high five); a plain :class:`BatchedEnv` restarts every world from the one reset state.
"""

from __future__ import annotations

import contextlib

import numpy as np

from ..core.world import World
from .controls import AgentControls
from .eyes import BatchedEyeSense, BatchedEyes
from .stacking import stack_rows
from .faces import BatchedFaces, carries_expression
from .device import describe, pick_device, require
from .contacts import BatchedContacts
from .proprioception import BatchedProprioception
from .skin import BatchedSkin, BatchedTouchSense, contact_rows
from .vestibular import BatchedVestibular

__all__ = ["BatchedEnv", "STATE_FIELDS", "DERIVED_FIELDS"]

#: the fields of MuJoCo Warp's data that hold a world's state, restored at a reset
STATE_FIELDS = ("time", "qpos", "qvel", "act", "history", "qacc_warmstart", "ctrl",
                "qfrc_applied", "xfrc_applied", "eq_active", "mocap_pos", "mocap_quat",
                "userdata")
#: the fields read each step (as tensors, no copy)
READ_FIELDS = ("qpos", "qvel", "qacc", "ctrl", "qfrc_actuator", "actuator_force", "qfrc_bias",
               "qfrc_spring", "sensordata", "site_xpos", "xpos", "xmat", "geom_xpos", "geom_xmat",
               "cdof", "subtree_com", "cam_xpos", "cam_xmat")
#: the derived fields a world's reset copies from the CPU env beside its state: what the
#: observations, the partners and the next step read before the physics recomputes them, and
#: the poses of the geoms fixed to the world (MuJoCo Warp computes those only once, when the
#: data is made: a task that moves a fixed body at reset, reach's ball, moves them per world)
DERIVED_FIELDS = ("qacc", "qfrc_actuator", "actuator_force", "qfrc_bias", "qfrc_spring",
                  "sensordata", "geom_xpos", "geom_xmat", "cam_xpos", "cam_xmat")


class BatchedEnv:
    """``nworld`` copies of ``env`` (a :class:`~mimo_social.core.env.MimoParallelEnv`) on the
    Warp device ``device`` (None: ``"cuda"`` when Warp sees a GPU, else ``"cpu"``).

    ``env`` is reset with ``seed``; that state is every world's start and reset state.
    ``nconmax`` / ``njmax``: contacts / constraint rows allocated per world (None: from the
    reset state, with room to spare); a step that needs more raises a RuntimeError naming
    the setting to raise. Steps are checked for divergence as the CPU world checks them
    (:attr:`World.VEL_LIMIT`, :attr:`World.ACC_LIMIT`), once per control step: a world past
    them is put back to the reset state and flagged in the step's ``unstable``. ``touch``:
    the agents' touch skins on the device (:mod:`mimo_social.gpu.skin`: the ``touch``
    observation of every agent that has touch in ``env``), or False to leave touch out.
    ``eyes``: the agents' eye images rendered on the device (:mod:`mimo_social.gpu.eyes`:
    ``eye_left`` / ``eye_right`` (and depth) of every agent that has vision in ``env``), or False.
    """

    def __init__(self, env, nworld: int, device: str | None = None, seed: int | None = 0,
                 nconmax: int | None = None, njmax: int | None = None,
                 batch_fields: tuple[str, ...] = (), touch: bool = True, eyes: bool = True):
        wp, mjw, torch = require()
        for key, value, what in (("touch", touch, "touch skins"), ("eyes", eyes, "eye images")):
            if not isinstance(value, bool):
                raise ValueError(f"{key}={value!r} not allowed; allowed: True (the agents' "
                                 f"{what} on the device, where the CPU env has them) or False")
        if isinstance(nworld, bool) or not isinstance(nworld, (int, np.integer)) or nworld < 1:
            raise ValueError(f"nworld={nworld!r} not allowed; allowed: an integer >= 1")
        self.nworld = int(nworld)
        self.device = pick_device(device)
        self.device_name = describe(self.device)
        self._wp, self._mjw, self._torch = wp, mjw, torch
        self.torch = torch
        self.env = env
        self.agents = list(env.possible_agents)
        self.frame_skip = int(env.physics.frame_skip)
        self.timestep = float(env.physics.timestep)
        self.dt = self.timestep * self.frame_skip
        env.reset(seed=seed)
        mjm, mjd = env.world.model, env.world.data
        self.nconmax, self.njmax = self._sizes(mjm, mjd, len(self.agents), nconmax, njmax)
        vision = env.systems.get("vision") if eyes else None
        acting = any(carries_expression(env, a) for a in self.agents)
        if vision is not None and acting and "mat_texid" not in batch_fields:
            batch_fields = tuple(batch_fields) + ("mat_texid",)   # each world's faces drawn
        with wp.ScopedDevice(self.device):
            self.model = mjw.put_model(mjm, {f: self.nworld for f in batch_fields})
            self.data = mjw.put_data(mjm, mjd, nworld=self.nworld, nconmax=self.nconmax,
                                     njmax=self.njmax)
        self.naconmax = self.nconmax * self.nworld
        self.tensors = {f: wp.to_torch(getattr(self.data, f)) for f in READ_FIELDS
                        if getattr(self.data, f).size}
        #: the model's per-world fields (``batch_fields``) as ``(nworld, ...)`` tensors
        self.model_tensors = {f: wp.to_torch(getattr(self.model, f)) for f in batch_fields}
        self.contacts = BatchedContacts(self.model, self.data, mjm, self.nworld, wp, mjw, torch,
                                        self._on_device)
        self._state = {f: wp.to_torch(getattr(self.data, f)) for f in STATE_FIELDS
                       if getattr(self.data, f, None) is not None
                       and getattr(self.data, f).size}
        self._start = {f: t[0].clone() for f, t in self._state.items()}
        tdev = self.tensors["qpos"].device
        system = env.systems.get("touch") if touch else None
        #: the agents' skins on the device (None: no agent has touch, or ``touch=False``)
        self.skin = None if system is None else BatchedSkin(system, mjm, self.nworld, torch,
                                                            tdev)
        #: every agent's expression in every world (drawn on the faces where eyes render)
        self.faces = BatchedFaces(env, self.nworld, torch, tdev, self.model_tensors.get("mat_texid"))
        #: the agents' eyes on the device (None: no agent has vision, or ``eyes=False``)
        self.eyes = None if vision is None else BatchedEyes(
            vision, mjm, self.model, self.data, self.nworld, wp, mjw, torch, tdev,
            self._on_device)
        self.controls, self.senses = [], []
        for i, name in enumerate(self.agents):
            act = env.actuation[i]
            delays = env.delay_steps(name)
            observed = _positional_reset_u(act, mjm, mjd)
            c = AgentControls(name, act, delays["motor"], env.controls[i], self.nworld,
                              torch, tdev, reset_observed=observed, model=mjm)
            self.controls.append(c)
            senses = []
            for s in env.senses[i]:
                if s.name == "proprioception":
                    senses.append(BatchedProprioception(s, delays["proprioception"], c,
                                                        self.nworld, torch, tdev,
                                                        face=self._face_reader(i)))
                elif s.name == "vestibular":
                    senses.append(BatchedVestibular(s, torch, tdev))
                elif s.name == "touch" and self.skin is not None:
                    senses.append(BatchedTouchSense(self.skin, s, delays["touch"], self.nworld,
                                                    torch, tdev))
                elif s.name == "vision" and self.eyes is not None:
                    senses.extend(BatchedEyeSense(self.eyes, i, k, delays["vision"], self.nworld,
                                                  torch, tdev) for k in self.eyes.keys(i))
            self.senses.append(senses)
        self._graph = None
        #: muscles update before every physics step (torch): no CUDA graph then
        self._muscles = [c.muscle for c in self.controls if c.muscle is not None]
        self.steps = 0

    # -- sizes -----------------------------------------------------------------------------------
    @staticmethod
    def _sizes(mjm, mjd, n_agents, nconmax, njmax) -> tuple[int, int]:
        """Contacts and constraint rows per world: given, or from the reset state with room for
        every agent lying on the floor touching another (an infant lying down: 30-40 contacts;
        4 rows a pyramidal contact, 6 an elliptic)."""
        if nconmax is None:
            nconmax = max(4 * int(mjd.ncon), 96 * n_agents)
        if njmax is None:
            rows = int(mjd.nefc) - 4 * int(mjd.ncon)     # limits, equalities, friction loss
            njmax = max(2 * max(rows, 0) + 6 * nconmax, 256)
        for key, v in (("nconmax", nconmax), ("njmax", njmax)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise ValueError(f"{key}={v!r} not allowed; allowed: an integer >= 1 or None")
        return int(nconmax), int(njmax)

    # -- the loop --------------------------------------------------------------------------------
    def reset(self, worlds=None) -> dict:
        """Every world (``worlds``: a bool mask or tensor of ``nworld``, the worlds to reset;
        None: all) back to the reset state; returns the observations (agent -> sense ->
        ``(nworld, size)`` tensor; rows of worlds not reset: not meaningful). Runs the
        forward dynamics of every world (see :meth:`load` for a reset that runs none)."""
        mask = self._mask(worlds)
        for f, t in self._state.items():
            t[mask] = self._start[f]
        for c in self.controls:
            c.reset(None if worlds is None else mask)
        if self.skin is not None:
            self.skin.reset(None if worlds is None else mask)
        self.faces.reset(None if worlds is None else mask)
        with self._on_device():
            self._mjw.forward(self.model, self.data)
        if self.eyes is not None:
            self.eyes.render(None if worlds is None else mask)
        if worlds is None:
            self.steps = 0
        return self._reset_obs(None if worlds is None else mask)

    def _face_reader(self, i: int):
        """Agent ``i``'s expression one-hot, read when its proprioception asks."""
        return lambda: self.faces.one_hot(i)

    def _mask(self, worlds):
        torch, dev = self._torch, self.tensors["qpos"].device
        if worlds is None:
            return torch.ones(self.nworld, dtype=torch.bool, device=dev)
        return torch.as_tensor(worlds, dtype=torch.bool, device=dev).reshape(self.nworld)

    def _reset_obs(self, mask) -> dict:
        return {a: {s.name: s.reset(self.tensors, mask) for s in senses}
                for a, senses in zip(self.agents, self.senses)}

    def snapshot(self, env) -> dict:
        """The state of ``env`` (the CPU env this batched env was made from, just reset: e.g.
        with another seed) that :meth:`load` puts into a world: the state fields, the derived
        fields the observations and partners read (:data:`DERIVED_FIELDS`), the model fields
        batched per world, and every agent's controls at reset (host work)."""
        mjm, mjd = env.world.model, env.world.data
        snap = {f: np.array(getattr(mjd, f), dtype=np.float64) for f in self._state}
        snap.update({f: np.array(getattr(mjd, f), dtype=np.float64) for f in DERIVED_FIELDS
                     if f in self.tensors})
        snap.update({"model." + f: np.array(getattr(mjm, f), dtype=np.float64)
                     for f in self.model_tensors})
        snap["controls"] = [np.array(c, dtype=np.float64) for c in env.controls]
        snap["observed"] = [_positional_reset_u(act, mjm, mjd) for act in env.actuation]
        snap["muscles"] = [(np.array(act.activation), np.array(act.force))
                           if c.muscle is not None else None
                           for act, c in zip(env.actuation, self.controls)]
        if self.skin is not None:
            snap["touch"] = BatchedSkin.reading(env.system("touch"))
        snap["expressions"] = BatchedFaces.shown(env)
        return snap

    def load(self, worlds, snaps) -> dict:
        """Put ``snaps`` (from :meth:`snapshot`, one per world) into the worlds ``worlds`` (a
        sequence of world indices); the other worlds are not touched (no physics runs: the
        derived fields come from the snapshots). Returns the observations as :meth:`reset`
        (rows of the worlds not loaded: not meaningful)."""
        idx = np.asarray(worlds, dtype=np.int64)
        if len(snaps) != len(idx):
            raise ValueError(f"{len(snaps)} snapshots for {len(idx)} worlds")
        if not len(idx):
            return self._reset_obs(self._mask(np.zeros(self.nworld, bool)))
        return self.load_rows(idx, stack_rows(list(snaps)))

    def load_rows(self, worlds, rows) -> dict:
        """:meth:`load` with the snapshots already stacked (:func:`~mimo_social.gpu.stacking.
        stack_rows`: each leaf ``(len(worlds), ...)``, numpy or torch tensors on the device,
        e.g. a reset bank's rows): one copy per field, nothing stacked on the host."""
        torch = self._torch
        dev = self.qpos.device
        idx = torch.as_tensor(worlds, dtype=torch.int64, device=dev).reshape(-1)
        fields = [(f, t) for f, t in self._state.items()] + \
            [(f, self.tensors[f]) for f in DERIVED_FIELDS if f in self.tensors] + \
            [("model." + f, t) for f, t in self.model_tensors.items()]
        for f, t in fields:
            t[idx] = torch.as_tensor(rows[f], device=t.device).reshape(
                (len(idx),) + tuple(t.shape[1:])).to(t.dtype)
        mask = torch.zeros(self.nworld, dtype=torch.bool, device=dev)
        mask[idx] = True
        for i, c in enumerate(self.controls):
            c.reset(mask, rows["controls"][i], rows["observed"][i], idx)
            if c.muscle is not None:
                c.muscle.reset(idx, *rows["muscles"][i])
        if self.skin is not None:
            self.skin.load(idx, rows["touch"])
        self.faces.reset(mask, rows["expressions"])
        if self.eyes is not None:
            self.eyes.render(mask)
        return self._reset_obs(mask)

    def step(self, actions, reset_unstable: bool = True,
             expressions: dict | None = None) -> tuple[dict, object]:
        """One control step of every world. ``actions``: agent -> ``(nworld, n_controls)``
        motor values (torch or numpy; each agent's motor Box, clipped into it);
        ``expressions``: agent -> ``(nworld,)`` expression ids for agents whose actions carry
        an expression (:class:`~mimo_social.gpu.faces.BatchedFaces`; None: unchanged). Returns the
        observations (agent -> sense -> ``(nworld, size)``) and ``unstable``, a bool tensor of
        the worlds that diverged (put back to the reset state unless ``reset_unstable`` is
        False: then the caller resets them)."""
        if not hasattr(actions, "keys") or set(actions) != set(self.agents):
            raise ValueError(f"actions must be a dict with one (nworld, n_controls) array per "
                             f"agent of {self.agents}; got "
                             f"{sorted(actions) if hasattr(actions, 'keys') else type(actions)}")
        checked = [c.check(actions[a]) for a, c in zip(self.agents, self.controls)]
        if expressions:
            self.faces.set(expressions)
        ctrl = self.tensors["ctrl"]
        for c, u in zip(self.controls, checked):
            c.step(u, ctrl)
        self._physics()
        self.steps += 1
        self._check_overflow()
        unstable = self._unstable()
        if self.skin is not None:
            self.skin.feel(contact_rows(self), self.tensors)
        if self.eyes is not None:
            self.eyes.step()
        obs = {a: {s.name: s.observe(self.tensors) for s in senses}
               for a, senses in zip(self.agents, self.senses)}
        if reset_unstable and bool(unstable.any()):
            fresh = self.reset(unstable)
            for a in self.agents:
                for k, v in fresh[a].items():
                    obs[a][k][unstable] = v[unstable]
        return obs, unstable

    def _physics(self) -> None:
        """``frame_skip`` physics steps of every world; on a GPU replayed as one CUDA graph."""
        wp = self._wp
        with self._on_device() as stream:
            if stream is None or self._muscles:
                self._steps()
                return
            if self._graph is None:
                with wp.ScopedCapture(stream=stream, force_module_load=True) as capture:
                    self._steps()
                self._graph = capture.graph
            wp.capture_launch(self._graph, stream=stream)

    def _steps(self) -> None:
        """``frame_skip`` physics steps, then the bodies', geoms' and sites' poses brought up to
        the state they left (MuJoCo's step leaves those of the state before its last
        integration), as the CPU world does after its steps (``mj_kinematics``); the contacts
        stay those of the last step's start, as on the CPU."""
        for _ in range(self.frame_skip):
            for muscle in self._muscles:
                muscle.substep(self.tensors)
            self._mjw.step(self.model, self.data)
        self._mjw.kinematics(self.model, self.data)

    @contextlib.contextmanager
    def _on_device(self):
        """Warp's work on the device; on a GPU on torch's current stream (the actions written
        by torch come before the physics that reads them, the observations after it): yields
        that Warp stream, None on the CPU."""
        wp = self._wp
        with wp.ScopedDevice(self.device):
            if not wp.get_device(self.device).is_cuda:
                yield None
                return
            stream = wp.stream_from_torch(self.tensors["qpos"].device)
            with wp.ScopedStream(stream):
                yield stream

    def _check_overflow(self) -> None:
        nacon = int(self.data.nacon.numpy()[0])
        nefc = int(self.data.nefc.numpy().max())
        if nacon > self.naconmax:
            raise RuntimeError(f"{nacon} contacts in the {self.nworld} worlds, beyond the "
                               f"{self.naconmax} allocated; give a larger nconmax (now "
                               f"{self.nconmax} per world)")
        if nefc > self.njmax:
            raise RuntimeError(f"{nefc} constraint rows in a world, beyond njmax={self.njmax}; "
                               f"give a larger njmax")

    def _unstable(self):
        torch = self._torch
        v, a = self.tensors["qvel"], self.tensors["qacc"]
        ok = (v.abs() <= World.VEL_LIMIT).all(dim=1) & (a.abs() <= World.ACC_LIMIT).all(dim=1)
        return ~ok.to(torch.bool)

    # -- reading ---------------------------------------------------------------------------------
    @property
    def qpos(self):
        """Every world's ``qpos``, ``(nworld, nq)`` float32 tensor (a view)."""
        return self.tensors["qpos"]

    def n_controls(self, agent: str) -> int:
        """The number of motor values of ``agent``'s actions."""
        return self.controls[self.agents.index(agent)].n

    def kinematics(self) -> None:
        """Every world's body, site and camera poses from its current ``qpos`` (MuJoCo Warp's
        ``kinematics``), e.g. after a task set joint angles by hand."""
        with self._on_device():
            self._mjw.kinematics(self.model, self.data)


def _positional_reset_u(act, mjm, mjd):
    """The controls a positional agent reports at reset (the targets of the pose it holds:
    :meth:`Positional.reset`), else None."""
    lo, hi = getattr(act, "lo", None), getattr(act, "hi", None)
    if lo is None or act.name != "positional":
        return None
    q = mjd.qpos[mjm.jnt_qposadr[mjm.actuator_trnid[act.actuator_ids, 0]]]
    return np.clip(2.0 * (q - lo) / (hi - lo) - 1.0, -1.0, 1.0)
