"""Five-fingered and touching bodies under bang-bang actions stay stable at the default physics.

History (docs/reliability.md, "Instability"): under MuJoCo 4.0.0 the Newton solver with the
sparse constraint Jacobian stalled at its iteration limit and returned a wrong acceleration when
contacts coupled branches of the body tree (fingers of one hand touching each other, the other
hand, the floor, or another infant): a finger, toe or knee jumped to 2,300-9,000 rad/s in one
step. The cause was MuJoCo's sparse Cholesky factorization (google-deepmind/mujoco#3767: rows
whose descendants differ put into one supernode), fixed in 4.0.1; the package made the dense
Jacobian its default meanwhile. It now requires MuJoCo >= 4.0.1 and its default is the sparse
Jacobian again (faster: 0.88x dense's physics time for one infant, 0.59x for eight): every run
of ``RUNS`` (and the two pairs below) runs 10,000 bang-bang control steps with seeds 0, 1 and 2
without a divergence (``pytest -m slow tests/body/test_hand_stability.py``); the fast tests
here check short runs of the same cases in the default test run.
"""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import free_play_v0

# Two infants sitting face to face 0.69 m apart, their toes touching (within the start check's
# 1 cm). Until issue 31 they sat 0.26 m apart, a thigh 7.4 cm inside the other's, which the env
# now refuses: the start where MuJoCo 4.0.0's sparse factorization went wrong in the very
# first physics step.
FACE_TO_FACE = [{"position": [-0.345, 0.0], "facing": [1.0, 0.0]},
                {"position": [0.345, 0.0], "facing": [-1.0, 0.0]}]


def first_steps(hands, physics=None, n=5):
    """Largest joint speed after each of the first ``n`` physics steps from rest (controls 0),
    or None for a step the world flags as diverged."""
    env = free_play_v0.parallel_env(n_agents=2, hands=hands, posture="sitting",
                                     per_agent=FACE_TO_FACE, physics=physics)
    env.reset(seed=0)
    world = env.world
    return [None if world.step(1) else float(np.abs(world.data.qvel).max()) for _ in range(n)]


def bang_bang(steps, seed=0, **settings):
    """Every motor at its lowest or highest control, redrawn each control step; the control
    steps at which an agent's info reports an instability."""
    env = free_play_v0.parallel_env(max_steps=10 ** 6, **settings)
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    flagged = []
    for step in range(steps):
        actions = {}
        for agent in env.agents:
            space = env.action_space(agent)
            motors = space["motors"] if hasattr(space, "spaces") else space
            u = np.where(rng.random(motors.shape[0]) < 0.5, motors.low, motors.high)
            u = u.astype(np.float32)
            actions[agent] = {"motors": u, "expression": 0} if hasattr(space, "spaces") else u
        _, _, _, _, infos = env.step(actions)
        if any(info["instability"] for info in infos.values()):
            flagged.append(step)
            env.reset(seed=seed + step + 1)
    return flagged


def test_mujoco_has_the_sparse_factorization_fix():
    major, minor, patch = (int(x) for x in mujoco.__version__.split(".")[:3])
    assert (major, minor, patch) >= (4, 0, 1), mujoco.__version__


@pytest.mark.parametrize("hands", ["mitten", "five_fingers"])
@pytest.mark.parametrize("jacobian", [None, "dense"])
def test_two_touching_infants_stay_sane_in_their_first_steps(hands, jacobian):
    """The start that diverged in its first physics step under MuJoCo 4.0.0 (sparse)."""
    speeds = first_steps(hands, None if jacobian is None else {"jacobian": jacobian})
    assert None not in speeds and max(speeds) < 200.0


def test_five_fingered_newborn_with_muscles_survives_bang_bang():
    """Under MuJoCo 4.0.0 with the sparse Jacobian seed 0 diverged at control step 430 (a big
    toe at 2,320 rad/s after a stalled solve)."""
    assert bang_bang(600, hands="five_fingers", age_months=0, strength=3.0,
                     actuation="muscle", n_agents=1) == []


def test_published_five_fingered_body_survives_bang_bang():
    """18 months, strength 1, seed 0: under MuJoCo 4.0.0 with the sparse Jacobian it diverged at
    control step 1766 (a ring finger's spread joint at 7,290 rad/s)."""
    assert bang_bang(1900, hands="five_fingers", strength=1.0, n_agents=1) == []


# Bang-bang runs of docs/reliability.md: name -> settings. With the sparse Jacobian under MuJoCo
# 4.0.0 each of the first seven diverged 1 to 5 times in 10,000 control steps (seed 0); under
# 4.0.1 none diverges with seeds 0, 1 and 2.
RUNS = {
    "18 months, strength 1": dict(hands="five_fingers", strength=1.0, n_agents=1),
    "18 months, strength 3": dict(hands="five_fingers", strength=3.0, n_agents=1),
    "scale 0.5, strength 1": dict(hands="five_fingers", scale=0.5, n_agents=1),
    "newborn, muscles, strength 3": dict(hands="five_fingers", age_months=0, strength=3.0,
                                         actuation="muscle", n_agents=1),
    "two sitting face to face, strength 3": dict(hands="five_fingers", strength=3.0,
                                                 n_agents=2, posture="sitting",
                                                 per_agent=FACE_TO_FACE),
    "five-fingered adult, strength 3": dict(hands="five_fingers", body="adult", strength=3.0,
                                            n_agents=1),
    "two mitten infants sitting face to face, strength 3": dict(
        hands="mitten", strength=3.0, n_agents=2, posture="sitting", per_agent=FACE_TO_FACE),
    "two five-fingered infants standing hand to hand, strength 3": dict(
        hands="five_fingers", strength=3.0, n_agents=2, posture="standing",
        per_agent=[{"position": [-0.17, 0.0], "facing": [1.0, 0.0]},
                   {"position": [0.17, 0.0], "facing": [-1.0, 0.0]}]),
}
SEEDS = (0, 1, 2)


@pytest.mark.parametrize("name", list(RUNS))
def test_a_short_bang_bang_run_of_each_case_does_not_diverge(name):
    assert bang_bang(300, seed=0, **RUNS[name]) == []


@pytest.mark.slow
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("name", list(RUNS))
def test_ten_thousand_bang_bang_steps_without_a_divergence(name, seed):
    assert bang_bang(10_000, seed=seed, **RUNS[name]) == []


def step_cost(settings, physics, steps=400, repeats=3):
    """Wall time of one env step (ms) under bang-bang actions: the least mean of ``repeats``
    blocks of ``steps`` (a shared machine's other load inflates some blocks)."""
    import time
    env = free_play_v0.parallel_env(max_steps=10 ** 6, physics=physics, **settings)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    best = np.inf
    for _ in range(repeats):
        total = 0.0
        for _ in range(steps):
            actions = {}
            for agent in env.agents:
                motors = env.action_space(agent)["motors"]
                u = np.where(rng.random(motors.shape[0]) < 0.5, motors.low, motors.high)
                actions[agent] = {"motors": u.astype(np.float32), "expression": 0}
            start = time.perf_counter()
            _, _, ended, cut, _ = env.step(actions)
            total += time.perf_counter() - start
            if not env.agents or any(ended.values()) or any(cut.values()):
                env.reset(seed=0)
        best = min(best, 1e3 * total / steps)
    return best


if __name__ == "__main__":   # python tests/body/test_hand_stability.py: the figures of the docs
    for name, settings in RUNS.items():
        for seed in SEEDS:
            flagged = bang_bang(10_000, seed=seed, **settings)
            print(f"{name}, seed {seed}: {len(flagged)} divergences in 10,000 bang-bang "
                  f"control steps (at steps {flagged})", flush=True)
    for hands, n in (("five_fingers", 1), ("five_fingers", 2), ("five_fingers", 4),
                     ("mitten", 2), ("mitten", 4), ("mitten", 8)):
        sparse, dense = (step_cost(dict(hands=hands, n_agents=n), physics)
                         for physics in (None, {"jacobian": "dense"}))
        print(f"{n} x {hands}: env step {sparse:.2f} ms sparse, {dense:.2f} ms dense "
              f"({dense / sparse:.2f} x)")
