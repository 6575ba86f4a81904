"""The core episode loop (``mimo_social.core.episodes``) on real envs: its numbers equal the env
stepped by hand with the same seeds and actions, episode k is reset with seed + k, the policies'
reset generators are seeded as documented, a Gymnasium env and a ParallelEnv give the same
numbers, and wrong arguments say what is allowed."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces

from mimo_social.core.env import MimoParallelEnv
from mimo_social.core.episodes import Episode, run_episode, run_episodes
from mimo_social.core.wrappers import FlatObservationWrapper, FlattenParallel
from mimo_social.envs import high_five_v0, reach_v0
from mimo_social.envs.catalog import entry, register_envs
from mimo_social.partners.base import motor_action

SHORT = {"max_steps": 20}


class Wiggle:
    """Motor commands drawn from the generator of its last reset; notes each reset's first draw
    and what it was handed."""

    def __init__(self):
        self.draws, self.envs, self.obs = [], set(), []

    def reset(self, env, agent, rng):
        self.rng = rng
        self.draws.append(int(rng.integers(1 << 30)))
        self.envs.add(type(env))

    def act(self, env, agent, obs):
        self.envs.add(type(env))
        self.obs.append(obs)
        space = env.action_space(agent)
        motors = space["motors"] if isinstance(space, spaces.Dict) else space
        return motor_action(space, self.rng.uniform(-0.5, 0.5, motors.shape))


def first_draw(seed) -> int:
    return int(np.random.default_rng(seed).integers(1 << 30))


def by_hand(env, policies, seed):
    """A ParallelEnv stepped without the loop: returns per agent, length, last infos, and the
    first step whose info said is_success per agent."""
    obs, infos = env.reset(seed=seed)
    core = env.unwrapped
    for a, p in policies.items():
        p.reset(core, a, np.random.default_rng(seed))
    totals = dict.fromkeys(env.possible_agents, 0.0)
    first = dict.fromkeys(env.possible_agents)
    last, n = dict(infos), 0
    while env.agents:
        obs, rew, _, _, infos = env.step({a: policies[a].act(core, a, obs[a]) for a in env.agents})
        n += 1
        for a, r in rew.items():
            totals[a] += float(r)
        for a, info in infos.items():
            last[a] = info
            if first[a] is None and info.get("is_success"):
                first[a] = n
    return totals, n, last, first


def gym_by_hand(env, policy, seed):
    obs, _ = env.reset(seed=seed)
    policy.reset(env.unwrapped.parallel, "infant_0", np.random.default_rng(seed))
    total, n, done = 0.0, 0, False
    while not done:
        obs, r, term, trunc, _ = env.step(policy.act(env.unwrapped.parallel, "infant_0", obs))
        total, n, done = total + float(r), n + 1, term or trunc
    return total, n


def test_a_parallel_episode_equals_the_env_stepped_by_hand():
    env = high_five_v0.parallel_env(**SHORT)
    ep = run_episode(env, {"infant_0": Wiggle(), "infant_1": Wiggle()}, seed=3)
    totals, n, last, first = by_hand(env, {"infant_0": Wiggle(), "infant_1": Wiggle()}, 3)
    assert isinstance(ep, Episode) and ep.seed == 3
    assert ep.returns == totals and ep.length == n == SHORT["max_steps"]
    assert ep.steps == {"infant_0": n, "infant_1": n}
    assert ep.first_success == first
    assert set(ep.last_infos) == {"infant_0", "infant_1"}
    for a in ep.last_infos:
        assert ep.last_infos[a]["step"] == last[a]["step"] == n
        assert ep.success(a) == (None if "is_success" not in last[a]
                                 else bool(last[a]["is_success"]))
    env.close()


def test_episode_k_is_the_env_reset_with_seed_plus_k_and_the_policy_rng_is_seeded():
    env = reach_v0.parallel_env(**SHORT)
    policy = Wiggle()
    eps = run_episodes(env, {"infant_0": policy}, 3, seed=5)
    assert [e.seed for e in eps] == [5, 6, 7]
    assert policy.draws == [first_draw(5 + k) for k in range(3)]   # default: seed + k
    for k, ep in enumerate(eps):
        assert _same(ep, run_episode(env, {"infant_0": Wiggle()}, seed=5 + k))
        totals, n, _, _ = by_hand(env, {"infant_0": Wiggle()}, 5 + k)
        assert ep.returns == totals and ep.length == n
    assert len({e.returns["infant_0"] for e in eps}) == 3   # the seeds make a difference
    # policy seeds given: each episode's reset generator comes from its own
    policy = Wiggle()
    seeds = [[9, k] for k in range(2)]
    eps = run_episodes(env, {"infant_0": policy}, 2, seed=5, policy_seeds=seeds)
    assert policy.draws == [first_draw(s) for s in seeds]
    policy = Wiggle()
    run_episode(env, {"infant_0": policy}, seed=5, policy_rng=11)
    assert policy.draws == [first_draw(11)]
    env.close()


def _same(a: Episode, b: Episode) -> bool:
    """Two episodes with the same numbers (the infos hold arrays: compared key by key)."""
    def infos_equal(x, y):
        return x.keys() == y.keys() and all(np.array_equal(x[k], y[k]) for k in x)
    return (a.seed, a.returns, a.length, a.first_success, a.steps) == \
        (b.seed, b.returns, b.length, b.first_success, b.steps) and \
        all(infos_equal(a.last_infos[k], b.last_infos[k]) for k in a.last_infos)


def test_first_success_is_the_step_is_success_turns_true():
    env = reach_v0.parallel_env(max_steps=60)
    controller = entry("reach").controller
    ep = run_episode(env, {"infant_0": controller()}, seed=0)
    totals, n, last, first = by_hand(env, {"infant_0": controller()}, 0)
    assert first["infant_0"] is not None   # the controller reaches the ball in this episode
    assert ep.first_success == first and ep.length == n and ep.returns == totals
    assert ep.success() is True and ep.success("infant_0") is True
    # reach ends on success: the first success is the last step
    assert ep.first_success["infant_0"] == ep.length
    env.close()


def test_a_gymnasium_env_gives_the_numbers_of_its_parallel_env():
    register_envs()
    genv = gymnasium.make("mimo_social/Reach-v0", **SHORT)
    penv = reach_v0.parallel_env(**SHORT)
    gpol, ppol = Wiggle(), Wiggle()
    g = run_episodes(genv, gpol, 2, seed=1)
    p = run_episodes(penv, {"infant_0": ppol}, 2, seed=1)
    assert [e.returns for e in g] == [e.returns for e in p]
    assert [(e.length, e.first_success, e.steps) for e in g] == \
        [(e.length, e.first_success, e.steps) for e in p]
    assert set(g[0].last_infos) == {"infant_0"}   # keyed by the SingleAgentEnv's agent
    assert gpol.draws == ppol.draws == [first_draw(1), first_draw(2)]
    assert gpol.envs == ppol.envs == {MimoParallelEnv}   # the policies get the core env
    total, n = gym_by_hand(genv, Wiggle(), 1)
    assert g[0].returns == {"infant_0": total} and g[0].length == n
    # a one-entry mapping is the same as the policy
    assert _same(run_episode(genv, {"infant_0": Wiggle()}, seed=1), g[0])
    genv.close()
    penv.close()


def test_a_policy_gets_the_observation_of_the_env_stepped_and_the_core_env():
    flat = FlattenParallel(reach_v0.parallel_env(**SHORT))
    policy = Wiggle()
    calls = []
    ep = run_episode(flat, {"infant_0": policy}, seed=2,
                     on_step=lambda env, *rest: calls.append((env, *rest)))
    assert policy.envs == {MimoParallelEnv}
    assert all(isinstance(o, np.ndarray) and o.shape == flat.observation_space("infant_0").shape
               for o in policy.obs)
    # on_step after every step, the env given and dicts keyed by agent
    assert len(calls) == ep.length
    assert all(c[0] is flat and set(c[2]) == {"infant_0"} for c in calls)
    assert sum(float(c[2]["infant_0"]) for c in calls) == ep.returns["infant_0"]
    assert calls[-1][4]["infant_0"] and not calls[0][4]["infant_0"]   # truncated at the end
    flat.close()

    register_envs()
    genv = FlatObservationWrapper(gymnasium.make("mimo_social/Reach-v0", **SHORT))
    policy, calls, resets = Wiggle(), [], []
    ep = run_episode(genv, policy, seed=2, on_step=lambda *c: calls.append(c),
                     on_reset=lambda *c: resets.append(c))
    assert policy.envs == {MimoParallelEnv} and all(o.ndim == 1 for o in policy.obs)
    assert len(calls) == ep.length and set(calls[0][2]) == {"infant_0"}
    assert len(resets) == 1 and set(resets[0][1]) == set(resets[0][2]) == {"infant_0"}
    genv.close()


def test_a_scripted_partner_env_runs_its_learner_only():
    env = high_five_v0.scripted_env(**SHORT)
    ep = run_episode(env, {"infant_0": Wiggle()}, seed=4)
    totals, n, _, _ = by_hand(high_five_v0.scripted_env(**SHORT), {"infant_0": Wiggle()}, 4)
    assert ep.returns == totals and ep.length == n and list(ep.returns) == ["infant_0"]
    eps = run_episodes(env, {"infant_0": Wiggle()}, 2, seed=4, progress="high five")
    assert _same(eps[0], ep)
    env.close()


def test_success_is_none_where_the_task_reports_none():
    ep = Episode(seed=0, returns={"a": 1.0}, length=1, last_infos={"a": {}},
                 first_success={"a": None})
    assert ep.success() is None and ep.success("a") is None and ep.steps == {}
    with pytest.raises(KeyError, match="agent 'b' not in this episode"):
        ep.success("b")


class NoAct:
    def predict(self, obs, deterministic=True):
        return None, None


def test_wrong_arguments_say_what_is_allowed():
    env = high_five_v0.parallel_env(**SHORT)
    with pytest.raises(ValueError, match=r"no policy for agent\(s\) \['infant_1'\].*allowed: one "
                                         r"for every agent of \['infant_0', 'infant_1'\]"):
        run_episode(env, {"infant_0": Wiggle()})
    with pytest.raises(ValueError, match=r"policies for agent\(s\) \['infant_9'\] that this env"):
        run_episode(env, {"infant_0": Wiggle(), "infant_1": Wiggle(), "infant_9": Wiggle()})
    with pytest.raises(ValueError, match="policy for 'infant_1' .*NoAct.* has no act"):
        run_episode(env, {"infant_0": Wiggle(), "infant_1": NoAct()})
    with pytest.raises(ValueError, match="not allowed for a ParallelEnv; allowed: a mapping"):
        run_episode(env, Wiggle())
    both = {"infant_0": Wiggle(), "infant_1": Wiggle()}
    for bad in (0, -1, 1.5, True, "3"):
        with pytest.raises(ValueError, match=f"episodes={bad!r} not allowed; allowed: an integer"):
            run_episodes(env, both, bad)
    with pytest.raises(ValueError, match=r"policy_seeds=\[1\] not allowed; allowed: None or a "
                                         "sequence of 2 seeds"):
        run_episodes(env, both, 2, policy_seeds=[1])
    with pytest.raises(ValueError, match="progress=2 not allowed; allowed: None, False"):
        run_episodes(env, both, 1, progress=2)
    with pytest.raises(ValueError, match="seed=None not allowed"):
        run_episodes(env, both, 1, seed=None)
    with pytest.raises(ValueError, match="on_step=3 not allowed; allowed: None or a function"):
        run_episode(env, both, on_step=3)
    with pytest.raises(ValueError, match="env=.* not allowed; allowed: a PettingZoo ParallelEnv"):
        run_episode(object(), both)
    env.close()
    register_envs()
    genv = gymnasium.make("mimo_social/Reach-v0", **SHORT)
    with pytest.raises(ValueError, match=r"policies for \['infant_1'\] not allowed for this "
                                         "Gymnasium env; allowed: one policy, or a mapping with "
                                         "the one entry 'infant_0'"):
        run_episode(genv, {"infant_1": Wiggle()})
    with pytest.raises(ValueError, match="policy for 'infant_0' .* has no act"):
        run_episode(genv, NoAct())
    genv.close()
