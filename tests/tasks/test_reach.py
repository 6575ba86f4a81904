"""Reach (paper Sec. VI-A): the table's constants, success only by the hand, the ball at arm's
length, and the baselines: the scripted ReachController solves it, random and zero actions do
not, and a forearm push does not pay.

``python tests/tasks/test_reach.py 30`` prints the baseline figures of the task's table.
"""

import pickle
import re
import sys

import mujoco
import numpy as np
import pytest

import mimo_social  # noqa: F401  (registers the ids)
from mimo_social.core.kinematics import reach_sites
from mimo_social.envs import reach_v0
from mimo_social.tasks.reach.controller import ReachController
from mimo_social.envs.task_docs import parse_docstring
from mimo_social.tasks import reach as reach_task
from mimo_social.tasks.reach import ReachOptions

A = "infant_0"
TABLE = dict(parse_docstring(reach_task.__doc__, "reach")[1])


def _row(name: str) -> str:
    assert name in TABLE, f"no row {name!r} in the reach table"
    return TABLE[name]


def _shoulder(env) -> np.ndarray:
    m, d = env.world.model, env.world.data
    return d.xpos[m.joint(f"{A}/right_shoulder_horizontal").bodyid[0]].copy()


# -- policies -----------------------------------------------------------------------------------
class ForearmPush(ReachController):
    """A hack: the arm driven (through its motors, like the controller) to the posture that puts
    the middle of the forearm at the ball's centre, pushing it with the forearm."""

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        a = w.agents[0]
        k = a.actuated_joint_idx[:7]
        qadr, dadr = a.qpos_adr[k], a.dof_adr[k]
        lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
        g = m.geom(f"{A}/right_lower_arm").id
        ball = d.xpos[w.prop_bodies["ball"]].copy()
        s = mujoco.MjData(m)
        s.qpos[:] = d.qpos
        s.qpos[qadr] = 0.5 * (lo + hi)
        jac = np.zeros((3, m.nv))
        for _ in range(200):
            mujoco.mj_kinematics(m, s)
            mujoco.mj_comPos(m, s)
            err = ball - s.geom_xpos[g]
            mujoco.mj_jac(m, s, jac, None, s.geom_xpos[g], m.geom_bodyid[g])
            J = jac[:, dadr]
            step = J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(3), err)
            s.qpos[qadr] = np.clip(s.qpos[qadr] + np.clip(step, -0.2, 0.2), lo, hi)
        self.target_angles = self.target_angles.copy()
        self.target_angles[:7] = s.qpos[qadr]


def run(policy: str, episodes: int, first_seed: int = 0, **env_kwargs):
    """Episodes of one policy (``controller``, ``random``, ``zero``, ``forearm``) on seeds
    first_seed.. : a list of (success, return, steps, forearm touched the ball)."""
    env = reach_v0.parallel_env(**env_kwargs)
    m = env.world.model
    ball, forearm = m.geom("ball").id, m.geom(f"{A}/right_lower_arm").id
    space = env.action_space(A)
    agent = {"controller": ReachController(), "forearm": ForearmPush()}.get(policy)
    out = []
    for seed in range(first_seed, first_seed + episodes):
        obs, _ = env.reset(seed=seed)
        space.seed(1000 + seed)
        if agent is not None:
            agent.reset(env, A, np.random.default_rng(seed))
        ret, steps, success, arm = 0.0, 0, False, False
        while env.agents:
            if agent is not None:
                action = agent.act(env, A, obs[A])
            elif policy == "random":
                action = space.sample()
            else:
                action = np.zeros(space.shape, space.dtype)
            obs, rew, _, _, infos = env.step({A: action})
            ret += float(rew[A])
            steps += 1
            success = infos[A]["is_success"]
            d = env.world.data
            c = d.contact[:d.ncon]
            arm = arm or bool(np.any(((c.geom1 == ball) & (c.geom2 == forearm))
                                     | ((c.geom2 == ball) & (c.geom1 == forearm))))
        out.append((success, ret, steps, arm))
    env.close()
    return out


def _rate(results) -> float:
    return sum(r[0] for r in results) / len(results)


# -- the table's constants ----------------------------------------------------------------------
def test_control_step_episode_length_and_rewards_are_the_tables():
    env = reach_v0.parallel_env()
    physics = _row("physics")
    step_ms = float(re.search(r"control step (\d+) ms", physics).group(1))
    substep_ms = float(re.search(r"physics steps of (\d+) ms", physics).group(1))
    assert env.dt == pytest.approx(step_ms / 1000)
    assert env.world.model.opt.timestep == pytest.approx(substep_ms / 1000)
    assert env.frame_skip == int(re.search(r"frame_skip=(\d+)", physics).group(1))
    assert env.max_steps == int(re.search(r"truncation at (\d+) steps", _row("termination")).group(1))
    reward = _row("reward")
    assert ReachOptions().success_reward == float(re.search(r"`\+(\d+)`", reward).group(1))
    assert "-distance(right fingertips, ball centre)" in reward
    assert f"`min_distance` = {ReachOptions().min_distance * 100:.0f} cm" in _row("reset")
    assert tuple(env.world.model.opt.gravity) == (0.0, 0.0, 0.0)
    assert env.action_space(A).shape == (8,)
    assert set(env.observation_space(A).spaces) == {"proprioception"}
    env.close()


def test_reward_is_minus_the_fingertips_distance_until_the_hand_touches():
    env = reach_v0.parallel_env()
    env.reset(seed=1)
    w = env.world
    m, d = w.model, w.data
    a = w.agents[0]
    _, rew, term, _, infos = env.step({A: np.zeros(8, np.float32)})
    tip = d.site_xpos[a.fingertip_sites[0]]
    dist = np.linalg.norm(tip - d.xpos[w.prop_bodies["ball"]])
    assert not term[A] and rew[A] == pytest.approx(-dist) == pytest.approx(-infos[A]["distance"])
    # the fingertips put 5 mm into the ball (a state write, for the test): success, +100, the end
    k = a.actuated_joint_idx[:7]
    d.qpos[a.qpos_adr[k]] = a.joint_range[k].mean(axis=1)   # as the reset's check: from the
    d.qpos[a.qpos_adr[a.joint_names.index("right_fingers")]] = 0.0   # middle, fingers straight
    ball = env.task.ball_position
    u = (ball - _shoulder(env)) / np.linalg.norm(ball - _shoulder(env))
    left = reach_sites(m, d, a.qpos_adr[k], a.dof_adr[k], a.joint_range[k, 0], a.joint_range[k, 1],
                       a.fingertip_sites[0], ball - 0.02 * u)
    assert left < 0.003
    d.qvel[:] = 0.0
    mujoco.mj_forward(m, d)
    _, rew, term, _, infos = env.step({A: np.zeros(8, np.float32)})
    assert term[A] and rew[A] == 100.0 and infos[A]["is_success"]
    assert env.agents == []
    env.close()


def test_the_forearm_on_the_ball_is_no_success():
    """The ball held against the middle of the forearm: contact, but no success and -distance."""
    env = reach_v0.parallel_env()
    env.reset(seed=0)
    w = env.world
    m, d = w.model, w.data
    g = m.geom(f"{A}/right_lower_arm").id
    axis = d.geom_xmat[g].reshape(3, 3)[:, 2]
    side = np.cross(axis, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    env.task.place_ball(env, d.geom_xpos[g] + (m.geom_size[g, 0] + 0.025 - 0.003) * side)
    for _ in range(3):
        _, rew, term, _, infos = env.step({A: np.zeros(8, np.float32)})
        c = d.contact[:d.ncon]
        assert any({int(x.geom1), int(x.geom2)} == {g, m.geom("ball").id} for x in c)
        assert not term[A] and not infos[A]["is_success"]
        assert rew[A] == pytest.approx(-infos[A]["distance"]) and rew[A] < 0
    env.close()


def test_the_ball_starts_in_reach_clear_of_the_body_and_out_of_the_forearms_reach():
    env = reach_v0.parallel_env()
    w = env.world
    m, d = w.model, w.data
    a = w.agents[0]
    ball = m.geom("ball").id
    positions = []
    for seed in range(30):
        env.reset(seed=seed)
        gap = min(mujoco.mj_geomDistance(m, d, ball, int(g), 1.0, None) for g in a.geom_ids)
        assert gap >= 0.019
        r = np.linalg.norm(env.task.ball_position - _shoulder(env))
        assert 0.25 <= r <= 0.305
        assert np.allclose(d.xpos[w.prop_bodies["ball"]], env.task.ball_position)
        positions.append(env.task.ball_position.copy())
    assert len({tuple(np.round(p, 4)) for p in positions}) == 30   # a new place every episode
    # the forearm's outer surface never comes within min_distance - r of the shoulder
    k = a.actuated_joint_idx
    lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
    g = m.geom(f"{A}/right_lower_arm").id
    radius, half = m.geom_size[g, :2]
    rng = np.random.default_rng(0)
    far = 0.0
    for _ in range(3000):
        d.qpos[a.qpos_adr[k]] = lo + (hi - lo) * rng.random(len(k))
        mujoco.mj_kinematics(m, d)
        axis = d.geom_xmat[g].reshape(3, 3)[:, 2]
        for end in (d.geom_xpos[g] + half * axis, d.geom_xpos[g] - half * axis):
            far = max(far, np.linalg.norm(end - _shoulder(env)) + radius)
    assert far < ReachOptions().min_distance - 0.025
    env.close()


def test_a_pickled_env_keeps_the_ball_where_the_episode_put_it():
    env = reach_v0.parallel_env()
    env.reset(seed=4)
    space = env.action_space(A)
    space.seed(0)
    actions = [space.sample() for _ in range(15)]
    for act in actions[:5]:
        env.step({A: act})
    clone = pickle.loads(pickle.dumps(env))
    for act in actions[5:]:
        a = env.step({A: act})
        b = clone.step({A: act})
        np.testing.assert_array_equal(a[0][A]["proprioception"], b[0][A]["proprioception"])
        assert a[1][A] == b[1][A]
    np.testing.assert_array_equal(clone.world.data.xpos, env.world.data.xpos)


@pytest.mark.parametrize("module, options, match", [
    (reach_v0, {"min_distance": 0.5}, r"reach: task option min_distance=0.5"),
    (reach_v0, {"moved_threshold": 0.01}, r"unknown task option.*allowed: \['min_distance'"),
])
def test_options_are_checked(module, options, match):
    with pytest.raises(ValueError, match=match):
        module.parallel_env(task_options=options)


# -- baselines: controller, random, zero, a hack --------------------------------------------------
def test_the_controller_reaches_the_ball_in_20_seeded_episodes():
    results = run("controller", 20)
    assert _rate(results) >= 0.8, results        # measured: 20 of 20
    assert max(r[2] for r in results) < 300      # within 3 s (measured: at most 1.6 s)


@pytest.mark.parametrize("kwargs", [{"hands": "five_fingers"}, {"actuation": "muscle"}])
def test_the_controller_with_five_fingers_and_muscles(kwargs):
    assert _rate(run("controller", 10, **kwargs)) >= 0.8    # measured: 10 of 10 each


def test_random_and_zero_actions_rarely_succeed_fast():
    """10 seeded episodes each (the slow test runs 30): at most 2 successes (20 %)."""
    assert sum(r[0] for r in run("random", 10)) <= 2
    assert sum(r[0] for r in run("zero", 10)) <= 2


@pytest.mark.slow
def test_random_and_zero_actions_succeed_in_at_most_20_percent_of_30_episodes():
    assert _rate(run("random", 30)) <= 0.2
    assert _rate(run("zero", 30)) <= 0.2


def test_a_forearm_push_scores_less_than_the_controller():
    hack, ctrl = run("forearm", 10), run("controller", 10)
    assert np.mean([r[1] for r in hack]) < np.mean([r[1] for r in ctrl])
    assert not any(r[3] for r in hack)   # the forearm cannot get to the ball at all


if __name__ == "__main__":   # the baseline figures of the task's table
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    for policy in ("controller", "random", "zero", "forearm"):
        res = run(policy, n)
        ok = [r for r in res if r[0]]
        print(f"{policy:10s} seeds 0-{n - 1}: success {len(ok)}/{n} ({100 * len(ok) / n:.0f} %), "
              f"return {np.mean([r[1] for r in res]):.1f} +- {np.std([r[1] for r in res]):.1f}, "
              f"steps to success "
              f"{np.mean([r[2] for r in ok]) if ok else float('nan'):.0f}, "
              f"forearm on the ball in {sum(r[3] for r in res)}")
