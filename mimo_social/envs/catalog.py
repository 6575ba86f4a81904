"""The one list of envs.

Every env of the package is one :class:`EnvEntry` of :data:`CATALOG`: its task name (what
``mimo-social train --task`` takes), its versioned PettingZoo module (``parallel_env``, ``env``
and, for social tasks, ``scripted_env``), its Gymnasium id, and from the task's folder its
scripted controller and a paradigm's measures. Registration, training, the baselines, the
paradigms, the benchmark, the package docstring, the docs and the tests read this list; a new
task is its folder ``mimo_social/tasks/<task>/``, its two-line ``<task>_v0`` shim here and one
entry below.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

from ..core.gym_adapter import SingleAgentEnv
from ..tasks import (catch, contingency, free_play, handover, high_five, imitation,
                     joint_attention, mirror, reach, rollover, selfbody, social_touch, standup,
                     still_face, turn_taking)
from . import (catch_v0, contingency_v0, free_play_v0, handover_v0, high_five_v0, imitation_v0,
               joint_attention_v0, mirror_v0, reach_v0, rollover_v0, selfbody_v0, social_touch_v0,
               standup_v0, still_face_v0, turn_taking_v0)

__all__ = ["EnvEntry", "CATALOG", "KINDS", "DEFAULT_DEMONSTRATOR", "entry", "names", "make_gym",
           "register_envs"]

#: what an entry is: a sandbox without a goal, a one-agent task of the paper, or a social task
#: (two learners, or one learner and a scripted partner)
KINDS = ("sandbox", "one-agent", "social")
#: the name of a task's default controller among its demonstrators
DEFAULT_DEMONSTRATOR = "scripted"


@dataclass(frozen=True)
class EnvEntry:
    """One env: ``name`` (the task name: its folder ``mimo_social/tasks/<name>/``), ``module``
    (its ``<task>_v0`` module), ``gym_id`` (the Gymnasium id: the env itself for one agent, the
    scripted form for a social task), ``kind`` (one of :data:`KINDS`), a one-line ``summary``,
    the task's scripted ``controller`` and a paradigm's ``measures``."""

    name: str
    module: ModuleType
    gym_id: str
    kind: str
    summary: str
    gym_defaults: tuple = ()   # keyword arguments the Gymnasium id passes by default
    #: the scripted controller that solves the task (a Partner class made without arguments,
    #: from the task's ``controller.py``), for the one-learner env; None where the task has none
    controller: type | None = None
    #: a paradigm's measures (its ``measures.py`` module: ``run(learner, episodes, seed, env)``
    #: -> summary, in the scripted env, ``rows(summaries)`` -> table lines, ``UNIT``); None for a task
    #: whose success and return say it all
    measures: ModuleType | None = None
    #: further Gymnasium ids of the same task, each a variant of its options: ``(gym_id,
    #: defaults)`` pairs, ``defaults`` keyword pairs as in ``gym_defaults`` (merged over them),
    #: ``task_options`` as pairs too (the entry stays hashable); the user's ``task_options`` are
    #: merged over the variant's
    gym_variants: tuple = ()
    #: further controllers that solve the task another way, by name: ``(name, class)`` pairs
    #: (``bc_kwargs`` ``demonstrator`` picks one to clone; the default, ``controller``, is
    #: :data:`DEFAULT_DEMONSTRATOR`)
    demonstrators: tuple = ()

    def demonstrator_names(self) -> tuple[str, ...]:
        """The names ``controller_class`` takes: the default controller's, then the others'."""
        return (DEFAULT_DEMONSTRATOR, *(n for n, _ in self.demonstrators)) \
            if self.controller is not None else ()

    def controller_class(self, name: str | None = None) -> type:
        """The controller ``name`` (None: the default ``controller``); a ValueError naming the
        allowed names otherwise."""
        if name in (None, DEFAULT_DEMONSTRATOR) and self.controller is not None:
            return self.controller
        others = dict(self.demonstrators)
        if name not in others:
            raise ValueError(f"task {self.name!r}: demonstrator={name!r} not allowed; allowed: "
                             f"{list(self.demonstrator_names()) or 'none (no controller)'}")
        return others[name]

    @property
    def gym_ids(self) -> tuple[str, ...]:
        """Every Gymnasium id of the task: ``gym_id`` first, then its variants'."""
        return (self.gym_id, *(v[0] for v in self.gym_variants))

    def variant_defaults(self, gym_id: str) -> dict:
        """What the variant ``gym_id`` sets over the entry's ``gym_defaults`` (``task_options``
        as a dict); a ValueError naming the allowed ids for an id that is not a variant."""
        variants = dict(self.gym_variants)
        if gym_id not in variants:
            raise ValueError(f"task {self.name!r}: gym_id={gym_id!r} not allowed; allowed: "
                             f"{list(self.gym_ids)}")
        out = dict(variants[gym_id])
        if "task_options" in out:
            out["task_options"] = dict(out["task_options"])
        return out

    def gym_kwargs(self, gym_id: str | None = None, **kwargs) -> dict:
        """The env keywords ``gym.make(gym_id, **kwargs)`` builds the env with: the id's
        defaults, then ``kwargs`` (``task_options`` merged, not replaced)."""
        out = dict(self.gym_defaults)
        if gym_id is not None and gym_id != self.gym_id:
            out = _merged(out, self.variant_defaults(gym_id))
        return _merged(out, kwargs)

    @property
    def module_name(self) -> str:
        """``reach_v0`` ..."""
        return self.module.__name__.rsplit(".", 1)[1]

    @property
    def social(self) -> bool:
        return self.kind == "social"

    def parallel_env(self, **kwargs):
        """The PettingZoo ParallelEnv with every agent learning."""
        return self.module.parallel_env(**kwargs)

    def scripted_env(self, **kwargs):
        """One learner (``infant_0``) and a scripted partner (social tasks); else the env."""
        if self.social:
            return self.module.scripted_env(**kwargs)
        return self.module.parallel_env(**kwargs)

    def gym_env(self, gym_id: str | None = None, **kwargs) -> SingleAgentEnv:
        """The one-learner env as a Gymnasium env (what ``gym.make(gym_id)`` returns; None:
        the entry's own ``gym_id``, else one of its variants')."""
        return SingleAgentEnv(self.scripted_env(**self.gym_kwargs(gym_id, **kwargs)))


def _merged(defaults: dict, given: dict) -> dict:
    """``given`` over ``defaults``; two ``task_options`` dicts are merged (``given``'s win)."""
    out = {**defaults, **given}
    old, new = defaults.get("task_options"), given.get("task_options")
    if isinstance(old, dict) and isinstance(new, dict):
        out["task_options"] = {**old, **new}
    return out


CATALOG: tuple[EnvEntry, ...] = (
    EnvEntry("free_play", free_play_v0, "mimo_social/FreePlay-v0", "sandbox",
             "infants (1-8) on the floor, optional props, no goal", (("n_agents", 1),)),
    EnvEntry("reach", reach_v0, "mimo_social/Reach-v0", "one-agent",
             "reach a ball in front of the body with the right hand",
             controller=reach.ReachController),
    EnvEntry("standup", standup_v0, "mimo_social/Standup-v0", "one-agent",
             "stand up from a crouch holding a crib rail",
             controller=standup.StandupController),
    EnvEntry("rollover", rollover_v0, "mimo_social/RollOver-v0", "one-agent",
             "roll over on the floor: from the back to the belly (start='prone': the reverse)",
             controller=rollover.RollOverController,
             gym_variants=(("mimo_social/RollOverProne-v0",
                            (("task_options", (("start", "prone"),)),)),)),
    EnvEntry("selfbody", selfbody_v0, "mimo_social/SelfBody-v0", "one-agent",
             "touch a named primitive of one's own body with the right hand",
             controller=selfbody.SelfBodyController),
    EnvEntry("catch", catch_v0, "mimo_social/Catch-v0", "one-agent",
             "catch a falling ball and hold it",
             controller=catch.CatchController),
    EnvEntry("high_five", high_five_v0, "mimo_social/HighFive-v0", "social",
             "two infants meet with their right hands",
             controller=high_five.HighFiveController),
    EnvEntry("mirror", mirror_v0, "mimo_social/Mirror-v0", "social",
             "show the partner's facial expression, seen through the eyes",
             controller=mirror.MirrorController),
    EnvEntry("joint_attention", joint_attention_v0, "mimo_social/JointAttention-v0", "social",
             "follow the partner's gaze to one of four toys",
             controller=joint_attention.GazeFollowController,
             demonstrators=(("checking", joint_attention.CheckingFollowController),
                            ("sensed", joint_attention.SensedFollowController))),
    EnvEntry("social_touch", social_touch_v0, "mimo_social/SocialTouch-v0", "social",
             "touch a named part of the partner's body",
             controller=social_touch.SocialTouchController),
    EnvEntry("handover", handover_v0, "mimo_social/Handover-v0", "social",
             "take a ball from the partner's hand",
             controller=handover.ReceiveController),
    EnvEntry("contingency", contingency_v0, "mimo_social/Contingency-v0", "social",
             "smile with a caregiver who answers live, replays a session or smiles on a timer",
             controller=contingency.ContingencyDetectorController,
             measures=contingency.measures),
    EnvEntry("still_face", still_face_v0, "mimo_social/StillFace-v0", "social",
             "face-to-face play, the caregiver's still face, reunion: per-phase measures",
             controller=still_face.StillFaceInfantController,
             measures=still_face.measures),
    EnvEntry("imitation", imitation_v0, "mimo_social/Imitation-v0", "social",
             "reproduce the action a caregiver demonstrated, seen through the eyes",
             controller=imitation.ImitationController,
             measures=imitation.measures),
    EnvEntry("turn_taking", turn_taking_v0, "mimo_social/TurnTaking-v0", "social",
             "vocal turn-taking: a caregiver who answers the infant's sounds, or speaks regardless",
             controller=turn_taking.TurnTakingInfantController,
             measures=turn_taking.measures),
)

_BY_NAME = {e.name: e for e in CATALOG}
_BY_ID = {i: e for e in CATALOG for i in e.gym_ids}


def names(kind: str | None = None) -> tuple[str, ...]:
    """Task names, all or of one kind."""
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind={kind!r}; allowed: {list(KINDS)}")
    return tuple(e.name for e in CATALOG if kind is None or e.kind == kind)


def entry(name: str) -> EnvEntry:
    """The entry of a task name, else a ValueError naming every allowed one."""
    try:
        return _BY_NAME[name]
    except (KeyError, TypeError):
        raise ValueError(f"task {name!r} not allowed; allowed: {', '.join(_BY_NAME)}") from None


def make_gym(gym_id: str, **kwargs) -> SingleAgentEnv:
    """Entry point of every Gymnasium id of the package."""
    return _BY_ID[gym_id].gym_env(gym_id, **kwargs)


def register_envs() -> None:
    """Register every Gymnasium id (idempotent)."""
    import gymnasium as gym

    for e in CATALOG:
        for gym_id in e.gym_ids:
            if gym_id not in gym.registry:
                gym.register(id=gym_id, entry_point="mimo_social.envs.catalog:make_gym",
                             kwargs={"gym_id": gym_id}, disable_env_checker=False)


def describe() -> str:
    """The catalogue as text (the package docstring lists it)."""
    width = max(len(e.module_name) for e in CATALOG)
    return "\n".join(f"  {e.module_name:<{width}}  {e.gym_id:<30} {e.kind:<9} {e.summary}"
                     for e in CATALOG)
