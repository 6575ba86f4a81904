"""The scripted-partner wrapper: only learners are exposed, partners act through their actions."""

import pytest

from mimo_social.envs import high_five_v0
from mimo_social.partners import Partner, ScriptedPartners, Still, zero_action


class Recording(Partner):
    """Holds the right elbow motor at +1 and remembers what it was given."""

    def reset(self, env, agent, rng):
        self.seen = []
        self.draw = rng.random()

    def act(self, env, agent, observation):
        self.seen.append(observation)
        a = zero_action(env.action_space(agent))
        k = env.world.agents[env.possible_agents.index(agent)].actuated_names.index("right_elbow")
        a["motors"][k] = 1.0
        return a


def test_only_learners_are_exposed_and_partner_acts():
    partner = Recording()
    env = ScriptedPartners(high_five_v0.parallel_env(info_text=True), {"infant_1": partner})
    assert env.possible_agents == ["infant_0"]
    obs, infos = env.reset(seed=3)
    assert set(obs) == {"infant_0"} and set(infos) == {"infant_0"}
    inner = env.unwrapped
    a1 = inner.world.agents[1]
    elbow = a1.qpos_adr[a1.joint_names.index("right_elbow")]
    q0 = inner.world.data.qpos[elbow]
    for _ in range(20):
        obs, rew, term, trunc, infos = env.step({"infant_0": zero_action(env.action_space("infant_0"))})
    # the partner's motor command moved its elbow, and it was given its own observation
    assert inner.world.data.qpos[elbow] - q0 > 0.05
    assert len(partner.seen) == 20 and partner.seen[0] is not None
    assert "proprioception" in partner.seen[0]
    assert set(infos["infant_0"]["partner_rewards"]) == {"infant_1"}


def test_partner_rng_follows_the_reset_seed():
    draws = []
    for _ in range(2):
        p = Recording()
        env = ScriptedPartners(high_five_v0.parallel_env(), {"infant_1": p})
        env.reset(seed=11)
        draws.append(p.draw)
    assert draws[0] == draws[1]


def test_bad_use_is_reported():
    base = high_five_v0.parallel_env()
    with pytest.raises(ValueError, match="not agents of this env"):
        ScriptedPartners(base, {"infant_7": Still()})
    with pytest.raises(ValueError, match="at least one learner"):
        ScriptedPartners(base, {"infant_0": Still(), "infant_1": Still()})
    with pytest.raises(TypeError, match="reset"):
        ScriptedPartners(base, {"infant_1": object()})
    env = ScriptedPartners(base, {"infant_1": Still()})
    env.reset(seed=0)
    with pytest.raises(ValueError, match="scripted agent"):
        env.step({"infant_0": zero_action(env.action_space("infant_0")),
                  "infant_1": zero_action(base.action_space("infant_1"))})
    with pytest.raises(KeyError, match="learners"):
        env.action_space("infant_1")
