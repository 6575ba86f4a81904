"""One episode of a one-learner env with ``infant_0`` driven by a scripted policy, a uniformly
random or a zero action: shared by the tests of the tasks' baselines (imported by name: this
folder is on the path, as for the other rootdir-less helpers)."""

from __future__ import annotations

import numpy as np

from mimo_social.partners.base import zero_action


def learner_episode(env, policy, seed):
    """One episode of the one-learner env ``env`` from ``reset(seed=seed)``, ``infant_0``
    driven by ``policy``: a Partner (reset with a generator of ``seed``), "random" (the action
    space sampled, seeded with ``seed``) or "zero"; returns (success, return, steps)."""
    obs, _ = env.reset(seed=seed)
    inner = env.unwrapped
    space = env.action_space("infant_0")
    space.seed(seed)
    if not isinstance(policy, str):
        policy.reset(inner, "infant_0", np.random.default_rng(seed))
    total, steps = 0.0, 0
    while env.agents:
        a = (space.sample() if policy == "random" else zero_action(space) if policy == "zero"
             else policy.act(inner, "infant_0", obs["infant_0"]))
        obs, r, _, _, info = env.step({"infant_0": a})
        total += r["infant_0"]
        steps += 1
    return bool(info["infant_0"]["is_success"]), total, steps


def pickled_twin_runs(env, learner, seed, before, after=None):
    """``env`` reset with ``seed``, ``infant_0`` driven by the Partner ``learner`` for ``before``
    steps, then the env pickled and the learner deep-copied, and both pairs run on, to the end
    (``after`` None) or ``after`` steps. Returns the copy and each pair's list of (reward,
    info) of ``infant_0``: a copy that continues identically gives equal lists."""
    import copy
    import pickle
    env.reset(seed=seed)
    learner.reset(env.unwrapped, "infant_0", np.random.default_rng(seed))
    for _ in range(before):
        env.step({"infant_0": learner.act(env.unwrapped, "infant_0", None)})
    twin, twin_learner = pickle.loads(pickle.dumps(env)), copy.deepcopy(learner)
    outs = []
    for e, p in ((env, learner), (twin, twin_learner)):
        out = []
        while e.agents and (after is None or len(out) < after):
            _, r, _, _, info = e.step({"infant_0": p.act(e.unwrapped, "infant_0", None)})
            out.append((r["infant_0"], info["infant_0"]))
        outs.append(out)
    return twin, outs
