"""Agent names: infants ``infant_<i>``, adult caregivers ``caregiver_<i>``, each kind counted in
world order; the name keys every dict of the env and prefixes the agent's bodies in the model.
The old name of an adult (``infant_<world index>``) is refused with its new name."""

import pickle

import numpy as np
import pytest

from mimo_social.core.config import ConfigError
from mimo_social.envs import (contingency_v0, free_play_v0, high_five_v0, imitation_v0,
                              mirror_v0, still_face_v0)
from mimo_social.partners import ScriptedPartners, Still
from mimo_social.util.names import agent_names, old_name_hint, old_names

BLIND = [{"vision": False}, {"vision": False}]
ADULT = {"body": "adult", "posture": "kneeling"}
RENAMED = "agent 'infant_1' is the adult caregiver: it is now named 'caregiver_0'"


def zero_actions(env, agents):
    def zero(space):
        if hasattr(space, "items"):
            return {k: zero(s) for k, s in space.items()}
        return np.zeros(space.shape, space.dtype)
    return {a: zero(env.action_space(a)) for a in agents}


def test_names_count_within_each_kind_in_world_order():
    assert agent_names(["infant", "adult"]) == ["infant_0", "caregiver_0"]
    assert agent_names(["infant", "infant"]) == ["infant_0", "infant_1"]
    assert agent_names(["adult", "infant", "adult", "infant"]) == [
        "caregiver_0", "infant_0", "caregiver_1", "infant_1"]
    assert old_names(["infant_0", "caregiver_0"]) == {"infant_1": "caregiver_0"}
    assert old_names(["infant_0", "infant_1"]) == {}
    assert old_name_hint("infant_1", ["infant_0", "caregiver_0"]).startswith(RENAMED)
    assert old_name_hint("infant_1", ["infant_0", "infant_1"]) == ""    # a name of this world
    assert old_name_hint("infant_7", ["infant_0", "caregiver_0"]) == ""  # never an agent here


@pytest.mark.parametrize("module", [still_face_v0, contingency_v0, imitation_v0],
                         ids=["still_face", "contingency", "imitation"])
def test_the_adult_caregiver_of_the_paradigms_is_caregiver_0(module):
    env = module.parallel_env(per_agent=BLIND)
    assert env.possible_agents == ["infant_0", "caregiver_0"]
    assert env.world.names == ["infant_0", "caregiver_0"]
    assert [t.body for t in env.world.tables] == ["infant", "adult"]
    scripted = module.scripted_env(per_agent=BLIND)
    assert scripted.possible_agents == ["infant_0"] and list(scripted.partners) == ["caregiver_0"]


def test_two_infants_keep_their_names_and_an_adult_partner_is_renamed():
    assert high_five_v0.parallel_env().possible_agents == ["infant_0", "infant_1"]
    env = high_five_v0.scripted_env(per_agent=[{}, ADULT])
    assert list(env.partners) == ["caregiver_0"]
    infant = mirror_v0.scripted_env(per_agent=[{"vision": False}, {}])
    assert list(infant.partners) == ["infant_1"]


def test_body_prefixes_in_the_compiled_model_follow_the_names():
    env = still_face_v0.parallel_env(per_agent=BLIND)
    m = env.world.model
    prefixes = {m.body(b).name.split("/")[0] for b in range(1, m.nbody)
                if "/" in m.body(b).name}
    assert {"infant_0", "caregiver_0"} <= prefixes and "infant_1" not in prefixes
    head = m.body("caregiver_0/head").id
    assert head in env.world.agents[1].body_ids
    assert m.geom(int(env.world.agents[1].head_geom)).name == "caregiver_0/head"


def test_a_world_of_two_adults_and_a_mixed_world():
    env = free_play_v0.parallel_env(n_agents=2, body="adult", posture="kneeling")
    assert env.possible_agents == ["caregiver_0", "caregiver_1"]
    obs, infos = env.reset(seed=0)
    assert set(obs) == set(infos) == {"caregiver_0", "caregiver_1"}
    mixed = free_play_v0.parallel_env(n_agents=3, per_agent=[ADULT, {}, ADULT])
    assert mixed.possible_agents == ["caregiver_0", "infant_0", "caregiver_1"]
    assert mixed.world.model.body("caregiver_1/head").id > 0
    # the old name of the third agent (infant_2) is now caregiver_1
    with pytest.raises(ValueError, match="'infant_2' is the adult caregiver: it is now named "
                                         "'caregiver_1'"):
        mixed.action_space("infant_2")


def test_observations_rewards_and_infos_are_keyed_by_the_new_names():
    env = still_face_v0.parallel_env(per_agent=BLIND, max_steps=3)
    obs, infos = env.reset(seed=0)
    assert set(obs) == set(infos) == {"infant_0", "caregiver_0"}
    out = env.step(zero_actions(env, env.agents))
    for d in out:
        assert set(d) == {"infant_0", "caregiver_0"}
    scripted = still_face_v0.scripted_env(per_agent=BLIND, max_steps=3, info_text=True)
    _, infos = scripted.reset(seed=0)
    _, rewards, _, _, infos = scripted.step(zero_actions(scripted, ["infant_0"]))
    assert set(rewards) == {"infant_0"}
    assert set(infos["infant_0"]["partner_rewards"]) == {"caregiver_0"}


def test_pickled_copies_keep_the_names():
    env = still_face_v0.scripted_env(per_agent=BLIND)
    env.reset(seed=1)
    copy = pickle.loads(pickle.dumps(env))
    assert copy.possible_agents == ["infant_0"] and list(copy.partners) == ["caregiver_0"]
    inner = copy.unwrapped
    assert inner.possible_agents == inner.world.names == ["infant_0", "caregiver_0"]
    assert inner.world.model.body("caregiver_0/head").id > 0


def test_the_old_name_of_an_adult_is_refused_with_its_new_name():
    env = still_face_v0.parallel_env(per_agent=BLIND)
    env.reset(seed=0)
    for call in (env.action_space, env.observation_space):
        with pytest.raises(ValueError, match=RENAMED):
            call("infant_1")
    actions = zero_actions(env, env.agents)
    actions["infant_1"] = actions.pop("caregiver_0")
    with pytest.raises(ValueError, match=RENAMED):
        env.step(actions)
    with pytest.raises(ValueError, match=RENAMED):
        ScriptedPartners(still_face_v0.parallel_env(per_agent=BLIND), {"infant_1": Still()})
    # a name that was never an agent stays an unknown agent
    with pytest.raises(KeyError, match="unknown agent 'infant_5'"):
        env.action_space("infant_5")
    # in a world of two infants infant_1 is an agent as before
    assert high_five_v0.parallel_env().action_space("infant_1") is not None


def test_setting_errors_name_the_caregiver():
    with pytest.raises(ConfigError, match="caregiver_0"):
        free_play_v0.parallel_env(n_agents=2, per_agent=[{}, {"body": "adult", "bogus": 1}])
