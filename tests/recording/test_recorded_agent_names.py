"""A recording names each agent as the env does: the adult caregiver's entities are under
``caregiver_0`` (its bodies, its agent panel), and the summary lists it by that name."""

import numpy as np

from mimo_social.envs import still_face_v0
from mimo_social.recording import format_summary, record_episode, summarize


def test_the_caregivers_entities_use_its_name(tmp_path):
    env = still_face_v0.parallel_env(per_agent=[{"vision": False}, {"vision": False}],
                                     max_steps=3)
    path = tmp_path / "still_face.rrd"
    zero = {a: {"motors": np.zeros(env.action_space(a)["motors"].shape, np.float32),
                "expression": 0} for a in env.possible_agents}
    record_episode(env, path, policy=lambda obs: {a: zero[a] for a in obs}, seed=0)
    s = summarize(path)
    assert s["agents"] == ["infant_0", "caregiver_0"]
    entities = set(s["entities"])
    assert "/world/caregiver_0/head" in entities
    assert any(e.startswith("/agents/caregiver_0/") for e in entities)
    assert not any("infant_1" in e for e in entities)
    assert "caregiver_0" in format_summary(s)
