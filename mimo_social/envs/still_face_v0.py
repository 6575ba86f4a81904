"""`still_face_v0`: the still-face paradigm as a PettingZoo env (see :mod:`.tasks.still_face`).

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns
a :class:`~mimo_social.core.env.MimoParallelEnv` with two learners (the infant ``infant_0`` and
the caregiver ``infant_1``, by default the kneeling adult; the task holds the caregiver still
in the still phase, whatever its actions); ``env(...)`` the AEC version;
``scripted_env(partner=None, **kwargs)`` a one-learner env (``infant_0`` learns) whose
caregiver ``infant_1`` is driven by a scripted :class:`~mimo_social.partners.Partner`, by
default :class:`~mimo_social.partners.contingent.ContingentCaregiver`: before every step the
wrapper sets a partner that has ``set_mode`` to ``"still"`` in the still phase and to
``"interactive"`` in the others (the task option ``scripted_partner`` is set: the caregiver has
no eyes and no reward).
"""

from ..partners.wrapper import ScriptedPartners
from ..tasks.still_face import PHASES, StillFace
from ._factory import make_aec, make_parallel, with_options

__all__ = ["parallel_env", "env", "scripted_env", "PhasedPartners", "StillFace"]

#: the scripted caregiver's mode in each phase
MODES = {"interaction": "interactive", "still": "still", "reunion": "interactive"}


def parallel_env(**kwargs):
    return make_parallel(StillFace, **kwargs)


def env(**kwargs):
    return make_aec(StillFace, **kwargs)


class PhasedPartners(ScriptedPartners):
    """:class:`~mimo_social.partners.wrapper.ScriptedPartners` that, before each step (and at
    reset), sets every partner with a ``set_mode`` method to the mode of the step's phase
    (:data:`MODES`), when it changes (a partner's ``mode`` attribute, where it has one, is
    its mode after its reset)."""

    def _sync(self):
        inner = self.env.unwrapped
        mode = MODES[PHASES[inner.task.phase_at(inner.steps)]]
        for name, partner in self.partners.items():
            if callable(getattr(partner, "set_mode", None)) and self._modes.get(name) != mode:
                partner.set_mode(mode)
                self._modes[name] = mode

    def reset(self, seed=None, options=None):
        out = super().reset(seed=seed, options=options)
        self._modes = {name: getattr(p, "mode", None) for name, p in self.partners.items()}
        self._sync()
        return out

    def step(self, actions):
        if self.__dict__.get("_seeds") is not None and self.env.agents:
            self._sync()
        return super().step(actions)


def scripted_env(partner=None, **kwargs):
    options = with_options(StillFace, kwargs.pop("task_options", None), scripted_partner=True)
    if partner is None:
        from ..partners.contingent import ContingentCaregiver
        partner = ContingentCaregiver()
    return PhasedPartners(parallel_env(task_options=options, **kwargs), {"infant_1": partner})
