"""TorchRL's PettingZooWrapper on every catalogue env as made: its infos become tensors, so it
needs the same numeric info keys at reset and at every step (the envs' default; the text infos
are behind ``info_text=True``), and ``return_state=True`` reads ``state_space`` as a space.
TorchRL's default grouping (by name: ``infant``, ``caregiver``) stacks a group's agents, so it
needs the same spaces within a group: social touch's toucher (its right arm) and touched infant
(its whole body) differ and take one group per agent."""

import pytest

from client_envs import SHORT, entries, parallel
from mimo_social.core.wrappers import NumericInfos

torchrl_pz = pytest.importorskip("torchrl.envs.libs.pettingzoo")
from torchrl.envs.utils import check_env_specs  # noqa: E402

#: envs whose agents of one name group have different spaces
PER_AGENT_GROUPS = ("social_touch",)


def _group_map(entry):
    """TorchRL's default (None: agents grouped by name) but where agents of one group differ."""
    from torchrl.envs.utils import MarlGroupMapType
    return MarlGroupMapType.ONE_GROUP_PER_AGENT if entry.name in PER_AGENT_GROUPS else None


@pytest.mark.parametrize("entry", entries())
def test_pettingzoo_wrapper_specs_and_rollout_on_the_env_as_made(entry):
    made = parallel(entry)
    env = torchrl_pz.PettingZooWrapper(made, return_state=True, use_mask=True,
                                       group_map=_group_map(entry))
    check_env_specs(env, seed=0)
    rollout = env.rollout(SHORT + 3, break_when_any_done=False)
    assert rollout["state"].shape[-1] == env.state_space.shape[0]
    for group, agents in env.group_map.items():
        info = rollout["next", group, "info"]
        assert set(info.keys()) == set(made.info_keys(agents[0]))
        assert "step" in info.keys() and "instability" in info.keys()
    env.close()


def test_the_default_grouping_separates_only_agents_whose_spaces_differ():
    """Every env but social touch: agents of one name group have the same spaces, so TorchRL's
    default grouping stacks them."""
    for e in entries():
        entry = e.values[0]
        env = parallel(entry)
        by_group = {}
        for a in env.possible_agents:
            by_group.setdefault(a.rsplit("_", 1)[0], []).append(a)
        same = all(env.observation_space(a) == env.observation_space(g[0])
                   and env.action_space(a) == env.action_space(g[0])
                   for g in by_group.values() for a in g)
        assert same == (entry.name not in PER_AGENT_GROUPS), entry.name
        env.close()


def test_text_infos_are_behind_an_option():
    """``info_text=True``: strings and dicts in infos, which TorchRL cannot make tensors of;
    the env as made (and NumericInfos over the text env) can."""
    from mimo_social.envs import selfbody_v0
    with pytest.raises(Exception):
        torchrl_pz.PettingZooWrapper(selfbody_v0.parallel_env(max_steps=SHORT, info_text=True))
    for made in (selfbody_v0.parallel_env(max_steps=SHORT),
                 NumericInfos(selfbody_v0.parallel_env(max_steps=SHORT, info_text=True))):
        env = torchrl_pz.PettingZooWrapper(made)
        td = env.reset(seed=0)
        info = td[next(iter(env.group_map)), "info"]
        assert {"is_success", "distance", "target_part", "touch/parts"} <= set(info.keys())
        env.close()


# -- NumericInfos itself --------------------------------------------------------------------------
@pytest.mark.parametrize("entry", entries())
def test_numeric_infos_have_the_same_number_keys_at_reset_and_every_step(entry):
    env = NumericInfos(parallel(entry), strict=True)   # strict: every key and string declared
    _, infos = env.reset(seed=1)
    seen = [infos]
    while env.agents:
        actions = {a: env.action_space(a).sample() for a in env.agents}
        seen.append(env.step(actions)[-1])
    for infos in seen:
        for agent, info in infos.items():
            assert tuple(info) == env.info_keys(agent)
            assert all(type(v) is float for v in info.values()), info


def test_numeric_infos_encode_strings_lists_touch_and_missing_values():
    from mimo_social.envs import social_touch_v0
    raw = social_touch_v0.parallel_env(max_steps=SHORT)
    env = NumericInfos(raw, missing=-7.0)
    keys = env.info_keys("infant_0")
    assert {"touch/parts", "touch/self", "touch/agents", "touch/object"} <= set(keys)
    _, infos = env.reset(seed=0)
    info = infos["infant_0"]
    assert info["fingertip_distance"] == -7.0           # a task key before the first step
    assert info["expression"] == 0.0 and info["instability"] == 0.0
    # the encoding itself, on a made-up info
    task = raw.task
    made = {"target_part": task.targets[-1], "touched_parts": ["a", "b", "c"],
            "first_touch": None, "expression": "happy", "instability": "qacc diverged",
            "touch": {"hand": {"self": True, "agents": [], "object": True},
                      "arm": {"self": False, "agents": ["infant_1"], "object": False}},
            "is_success": True, "unknown": "dropped"}
    out = env._encode("infant_0", made)
    assert out["target_part"] == len(task.targets) - 1
    assert out["touched_parts"] == 3 and out["first_touch"] == 0
    assert out["expression"] == 1.0 and out["instability"] == 1.0 and out["is_success"] == 1.0
    assert (out["touch/parts"], out["touch/self"], out["touch/agents"], out["touch/object"]) \
        == (2, 1, 1, 1)
    assert "unknown" not in out and tuple(out) == keys
    strict = NumericInfos(raw, strict=True)
    with pytest.raises(ValueError, match="infant_0.*unknown"):
        strict._encode("infant_0", made)
    with pytest.raises(ValueError, match="infant_0.*target_part"):
        strict._encode("infant_0", {"target_part": "no such part"})


def test_numeric_infos_extra_keys_flatten_a_nested_dict():
    """A scripted partner's rewards (added by the partner wrapper) declared with ``extra``."""
    from mimo_social.envs import high_five_v0
    env = NumericInfos(high_five_v0.scripted_env(max_steps=SHORT),
                       extra={"partner_rewards": {"infant_1": "number"}}, strict=True)
    _, infos = env.reset(seed=0)
    assert infos["infant_0"]["partner_rewards/infant_1"] == 0.0
    act = {"infant_0": env.action_space("infant_0").sample()}
    info = env.step(act)[-1]["infant_0"]
    assert tuple(info) == env.info_keys("infant_0")
    with pytest.raises(TypeError, match="kind 'text' not allowed"):
        NumericInfos(high_five_v0.parallel_env(), extra={"x": "text"})


def test_numeric_infos_keep_scripted_partners_rewards():
    """A scripted-partner env declares ``partner_rewards`` itself: the numeric view carries the
    partner's reward of each step (0 at reset), equal to the text info's."""
    from mimo_social.envs import high_five_v0
    plain = high_five_v0.scripted_env(info_text=True)
    numeric = NumericInfos(high_five_v0.scripted_env())
    (learner,) = plain.possible_agents
    _, info = numeric.reset(seed=3)
    plain.reset(seed=3)
    assert info[learner]["partner_rewards/infant_1"] == 0.0
    space = plain.action_space(learner)
    space.seed(0)
    for _ in range(5):
        act = {learner: space.sample()}
        *_, pinfo = plain.step(act)
        *_, ninfo = numeric.step(act)
        assert ninfo[learner]["partner_rewards/infant_1"] == pinfo[learner]["partner_rewards"]["infant_1"]
