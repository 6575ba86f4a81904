"""Privileged cues, catalogue-wide: what a task gives a learner beyond its own senses is a named
option, off by default, named in the task table, and it does change what the learner observes.

A privileged cue is something of the partner's or the target's state that reaches a learner
through the task rather than through its own eyes, skin or body (the task aiming the learner's
gaze at the partner's hand puts that hand's place into the learner's proprioception). Each task
declares such options in ``Options.privileged``; each task's own tests show, by changing only the
target or the partner with everything else fixed, that the learner's non-image observations
stay the same with the option off (tests/tasks/test_<task>.py).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mimo_social.envs.catalog import CATALOG
from mimo_social.envs.task_docs import task_doc

SOCIAL = [e for e in CATALOG if e.social]


def _row(doc, key: str) -> str:
    for k, v in doc.rows:
        if k.split(" (")[0] == key:
            return v
    raise AssertionError(f"{doc.entry.name}: no {key!r} row")


@pytest.mark.parametrize("e", SOCIAL, ids=[e.name for e in SOCIAL])
def test_privileged_options_are_declared_off_and_named_in_the_table(e):
    doc = task_doc(e)
    options = doc.task_cls.Options
    fields = {f.name: f for f in dataclasses.fields(options)}
    row = _row(doc, "privileged cues")
    for name in options.privileged:
        assert name in fields, f"{e.name}: privileged option {name!r} is no option"
        assert fields[name].default is False, f"{e.name}: {name} must be off by default"
        assert f"`{name}`" in row, f"{e.name}: the privileged-cues row does not name `{name}`"
        with pytest.raises(Exception, match=name):
            options(**{name: "yes"})        # a bool, checked


@pytest.mark.parametrize("e", SOCIAL, ids=[e.name for e in SOCIAL])
def test_turning_a_privileged_cue_on_changes_the_learners_observation(e):
    """The declared cue is real: with it on, the learner's first non-image observation differs
    from the one without it (same seed), so a leak test with it off can fail."""
    options = task_doc(e).task_cls.Options
    if not options.privileged:
        pytest.skip(f"{e.name} declares no privileged option")

    def first_obs(**task_options):
        env = e.scripted_env(vision=False, task_options=task_options)
        obs, _ = env.reset(seed=11)
        o = obs["infant_0"]
        env.close()
        # an agent whose senses have nothing to read observes an empty dict (mirror's learner
        # without eyes: every joint held): 0 floats
        return np.concatenate([np.zeros(0)] + [np.ravel(o[k]) for k in sorted(o)])

    off = first_obs()
    for name in options.privileged:
        on = first_obs(**{name: True})
        assert on.shape != off.shape or not np.array_equal(on, off), name
