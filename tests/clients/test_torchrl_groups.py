"""TorchRL's PettingZooWrapper without a ``group_map`` groups agents by name (the part before
the last ``_<i>``): infants are ``infant_<i>`` and adults ``caregiver_<i>``, so a paradigm's
infant and its adult caregiver, whose spaces differ, fall into two groups of their own."""

import pytest

from client_envs import parallel
from mimo_social.core.wrappers import NumericInfos
from mimo_social.envs.catalog import entry

torchrl_pz = pytest.importorskip("torchrl.envs.libs.pettingzoo")


@pytest.mark.parametrize("name", ["still_face", "contingency", "imitation"])
def test_the_default_grouping_puts_infant_and_caregiver_apart(name):
    env = torchrl_pz.PettingZooWrapper(NumericInfos(parallel(entry(name)), strict=True),
                                       use_mask=True)
    assert env.group_map == {"infant": ["infant_0"], "caregiver": ["caregiver_0"]}
    obs = env.observation_spec
    assert "infant" in obs.keys() and "caregiver" in obs.keys()
    assert env.full_action_spec["caregiver", "action"].shape[0] == 1   # one agent in the group
    env.close()
