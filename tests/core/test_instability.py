"""A simulation that diverges is flagged in the control step where it happens, before any of its
values reach an observation: ``infos[agent]["instability"]`` says why, every agent's episode ends,
and the world is put back to its initial pose at rest. Bang-bang actions at the strongest allowed
body do not diverge at the default physics."""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.body.tables import SCALE_RANGE, STRENGTH_RANGE
from mimo_social.core.world import World
from mimo_social.envs import free_play_v0

#: what no observation value may pass without the instability flag: far above anything a sane
#: step returns (a few hundred), far below what a diverging simulation produced before the
#: check (up to 5.6e10)
OBS_BOUND = 1e5


def free_play_text(**kwargs):
    """Free play with text infos: an instability's reason."""
    return free_play_v0.parallel_env(info_text=True, **kwargs)


def bang_bang(env, rng):
    """Every motor at its lowest or highest command, drawn anew each step."""
    actions = {}
    for a in env.agents:
        space = env.action_space(a)
        box = space["motors"] if "motors" in getattr(space, "spaces", {}) else space
        u = np.where(rng.random(box.shape) < 0.5, box.low, box.high).astype(np.float32)
        actions[a] = {"motors": u, "expression": 0} if box is not space else u
    return actions


def largest_value(obs) -> float:
    """The largest magnitude of any float observation (inf for a NaN/inf)."""
    top = 0.0
    for per_agent in obs.values():
        for x in per_agent.values():
            x = np.asarray(x)
            if x.dtype.kind == "f":
                top = max(top, float(np.abs(x).max()) if np.isfinite(x).all() else np.inf)
    return top


def run_bang_bang(env, steps: int, seed: int) -> tuple[int, float]:
    """Flagged steps and the largest observation value returned without the flag."""
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)
    flagged, top = 0, 0.0
    for _ in range(steps):
        obs, _, term, _, infos = env.step(bang_bang(env, rng))
        if any("instability" in i for i in infos.values()):
            flagged += 1
            assert all(term.values()) and not env.agents
            assert largest_value(obs) <= OBS_BOUND     # the restarted world is sane
        else:
            top = max(top, largest_value(obs))
        if not env.agents:
            env.reset()
    return flagged, top


def test_a_speed_past_the_limit_is_flagged_in_the_same_step():
    """5 km/s is far beyond any body part's speed yet far below MuJoCo's own check (1e10): it
    used to run on unflagged."""
    env = free_play_text(n_agents=2, expressions=False)
    env.reset(seed=0)
    w = env.world
    dof = w.agents[0].free_dof                    # infant_0 flung along x
    w.data.qvel[dof] = 5e3
    t0 = float(w.data.time)
    obs, rewards, term, trunc, infos = env.step({a: np.zeros(44, np.float32) for a in env.agents})
    assert all(term.values()) and not any(trunc.values()) and env.agents == []
    for a in infos:
        reason = infos[a]["instability"]
        assert "diverged" in reason and "speed" in reason and "infant_0/root" in reason, reason
    # the world is back at its initial pose, at rest; the clock went on
    np.testing.assert_array_equal(w.data.qpos, w.initial_qpos)
    assert not w.data.qvel.any()
    assert infos["infant_0"]["time"] > t0
    assert largest_value(obs) <= OBS_BOUND
    assert all(np.isfinite(r) for r in rewards.values())


def test_a_nan_is_flagged_and_the_world_restarts_from_its_initial_pose():
    """MuJoCo meets the NaN and resets the data to the model's default pose; the world goes on to
    its own initial pose (the posture the episode started in), and the next episode runs."""
    env = free_play_text(n_agents=1, expressions=False)
    env.reset(seed=0)
    w = env.world
    w.data.qvel[10] = np.nan
    obs, _, term, _, infos = env.step({"infant_0": np.zeros(44, np.float32)})
    assert term["infant_0"] and "instability" in infos["infant_0"]
    np.testing.assert_array_equal(w.data.qpos, w.initial_qpos)
    assert np.isfinite(largest_value(obs))
    env.reset(seed=1)
    _, _, term, _, infos = env.step({"infant_0": np.zeros(44, np.float32)})
    assert not term["infant_0"] and "instability" not in infos["infant_0"]


def test_instability_reads_the_state_without_changing_it():
    env = free_play_text(n_agents=1, expressions=False)
    env.reset(seed=0)
    w = env.world
    assert w.instability() is None
    w.data.qvel[7] = -3 * World.VEL_LIMIT
    reason = w.instability()
    assert reason and "speed" in reason and f"{-3 * World.VEL_LIMIT:.3g}" in reason
    assert w.data.qvel[7] == -3 * World.VEL_LIMIT


def test_a_diverging_solver_never_returns_huge_observations_unflagged():
    """Two solver iterations for a small five-fingered body (set in the compiled model: the
    config refuses fewer than 10): the simulation diverges again and again; every step either
    carries the flag or returns sane values."""
    env = free_play_text(n_agents=1, hands="five_fingers", scale=0.5, strength=3)
    env.world.model.opt.iterations = 2
    flagged, top = run_bang_bang(env, steps=300, seed=0)
    assert flagged >= 3                        # it did diverge, more than once
    assert top <= OBS_BOUND, f"an observation value of {top:.3g} came without the flag"


@pytest.mark.parametrize("scale", [SCALE_RANGE[0], 1.0])
def test_bang_bang_at_the_top_allowed_strength_does_not_diverge(scale):
    """The strongest allowed body, smallest and standard size, at the default physics: no
    instability and no huge value in 2000 bang-bang steps (strength 10 diverged every ~160)."""
    env = free_play_text(n_agents=1, strength=STRENGTH_RANGE[1], scale=scale)
    flagged, top = run_bang_bang(env, steps=2000, seed=1)
    assert flagged == 0
    assert top <= OBS_BOUND
