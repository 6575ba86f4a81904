"""Issue 30: the paradigms measure the learner and report their effect for any policy.

- contingency's gaze measure is the learner's own with ``gaze_free`` (the default since issue
  30; held, ``gaze_free=False``, it is 1.0 for everyone): a learner that turns its head and eyes
  to the caregiver's face scores near 1, one that turns them away, random and zero score less;
- ``measures.effects`` of still face (still-phase drop and reunion recovery of smiling and gaze,
  the rise of self-touch) and of contingency (live minus replay and minus non-contingent) for a
  scripted partner, a function of the observation and an SB3 model;
- still face's ``still_response_reward`` pays the classic still-phase response, and only it.
"""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.core.episodes import run_episodes
from mimo_social.envs import contingency_v0, still_face_v0
from mimo_social.partners import Partner
from mimo_social.partners.gaze import GazeAtTarget
from mimo_social.tasks.contingency import ContingencyDetectorController
from mimo_social.tasks.contingency import measures as contingency_measures
from mimo_social.tasks.still_face import StillFaceInfantController
from mimo_social.tasks.still_face import measures as still_face_measures
from mimo_social.util.checks import ConfigError

A = "infant_0"
NO_EYES = [{"vision": False}, {}]         # no policy here reads the eyes (faster)
FREE = {"per_agent": NO_EYES}            # the default: the learner's head and eyes free
HELD = {"task_options": {"gaze_free": False}, "per_agent": NO_EYES}


class Looks(GazeAtTarget):
    """Turns its head and eyes to one target with its own motors and holds them there."""

    def __init__(self, target: str):
        super().__init__(targets=[target], hold_s=(3600.0, 3600.0), head_share=1.0)


class Random(Partner):
    """Uniform samples of the action space, seeded per episode."""

    def reset(self, env, agent, rng):
        self.space = env.action_space(agent)
        self.space.seed(int(rng.integers(2 ** 31)))

    def act(self, env, agent, obs):
        return self.space.sample()


class Zero(Partner):
    def act(self, env, agent, obs):
        space = env.action_space(agent)
        return {"motors": np.zeros(space["motors"].shape, np.float32), "expression": 0}


def gaze_fraction(policy, steps=300, **kwargs):
    env = contingency_v0.scripted_env(max_steps=steps, **kwargs)
    [episode] = run_episodes(env, {A: policy}, 1, 3)
    env.close()
    return episode.last_infos[A]["gaze_fraction"]


# -- contingency: the gaze measure ------------------------------------------------------------
def test_contingency_gaze_measure_follows_the_learners_head_and_eyes():
    looks = gaze_fraction(Looks("caregiver_0/head_centre"), **FREE)
    away = gaze_fraction(Looks("infant_0/right_hand"), **FREE)
    random, zero = gaze_fraction(Random(), **FREE), gaze_fraction(Zero(), **FREE)
    scripted = gaze_fraction(ContingencyDetectorController(), **FREE)
    assert looks > 0.9                          # measured 0.93 (0.3 s to turn, of 3 s)
    assert scripted > 0.9                       # measured 0.93
    assert away < 0.05 and zero < 0.05          # measured 0.00, 0.00
    assert random < looks - 0.5                 # measured 0.13
    # held (gaze_free=False), the gaze is the task's: 1.0 whatever the learner does
    held = contingency_v0.scripted_env(max_steps=50, **HELD)
    assert held.action_space(A)["motors"].shape == (0,)
    [episode] = run_episodes(held, {A: Random()}, 1, 3)
    assert episode.last_infos[A]["gaze_fraction"] == 1.0


def test_contingency_gaze_free_spaces_rest_pose_and_detector():
    env = contingency_v0.scripted_env(**FREE)
    assert env.unwrapped.task.options.gaze_free           # the default
    assert env.action_space(A)["motors"].shape == (9,)
    assert env.observation_space(A)["proprioception"].shape == (54,)
    with pytest.raises(ConfigError, match="gaze_free"):
        contingency_v0.scripted_env(task_options={"gaze_free": "yes"})
    # the zero action keeps the head at rest (head support): no joint of it moves
    inner = env.unwrapped
    env.reset(seed=0)
    a = inner.world.agents[0]
    q = a.qpos_adr[a.actuated_joint_idx]
    start = inner.world.data.qpos[q].copy()
    zero = Zero()
    for _ in range(100):
        env.step({A: zero.act(inner, A, None)})
    assert np.abs(inner.world.data.qpos[q] - start).max() < 1e-3
    env.close()
    # the scripted infant looks at the face when its gaze is free, and still succeeds live
    env = contingency_v0.scripted_env(max_steps=1000, **FREE)
    [episode] = run_episodes(env, {A: ContingencyDetectorController()}, 1, 1000)
    assert episode.last_infos[A]["gaze_fraction"] > 0.95 and episode.success()


# -- still face: the effect for any policy ----------------------------------------------------
SHORT_SF = {"task_options": {"phases_s": (1.0, 1.0, 1.0), "phase_jitter": 0.0},
            "per_agent": NO_EYES}


def test_still_face_effects_scripted_random_zero():
    scripted = still_face_measures.effects(StillFaceInfantController(), 2, 0, SHORT_SF)
    e = scripted["effects"]
    assert set(e) == set(still_face_measures.EFFECTS) and scripted["episodes"] == 2
    # measured: smile drop 1.00, recovery 0.99; gaze drop 0.76, recovery 0.63; self-touch 0.72
    assert e["smile_still_drop"][0] > 0.9 and e["smile_reunion_recovery"][0] > 0.9
    assert e["gaze_still_drop"][0] > 0.5 and e["gaze_reunion_recovery"][0] > 0.4
    assert e["self_touch_still_rise"][0] > 0.5
    ph = scripted["summary"]["phases"]
    assert e["smile_still_drop"][0] == pytest.approx(ph["interaction"]["smile"][0]
                                                     - ph["still"]["smile"][0])
    zero = still_face_measures.effects(Zero(), 2, 0, SHORT_SF)
    assert all(v == (0.0, 0.0) for v in zero["effects"].values()) and zero["return"][0] == 0.0
    random = still_face_measures.effects(Random(), 2, 0, SHORT_SF)["effects"]
    assert all(abs(m) < 0.3 for m, _ in random.values())       # measured within +-0.13
    text = still_face_measures.format_effects(scripted)
    assert "smile_still_drop: +1.000" in text


def test_effects_take_a_function_and_an_sb3_model():
    """A function ``obs -> action`` and an SB3 model (flat observation, flat action, as the
    project's learners are trained) drive the learner, deterministic or sampled; a model of
    other spaces is refused, naming them."""
    import gymnasium as gym
    from gymnasium import spaces
    from stable_baselines3 import PPO
    from mimo_social.core.wrappers import flat_action_space, flat_observation_space
    kw = {"task_options": {"phases_s": (0.1, 0.1, 0.1), "phase_jitter": 0.0},
          "per_agent": [{"vision": {"width": 8, "height": 8}}, {}]}
    seen = []

    def smile(obs):
        seen.append(sorted(obs))
        return {"motors": np.zeros(17, np.float32), "expression": 1}   # happy

    out = still_face_measures.effects(smile, 1, 0, kw)
    assert seen[0] == ["eye_left", "eye_right", "proprioception"]
    assert out["summary"]["phases"]["interaction"]["smile"][0] == 1.0
    env = still_face_v0.scripted_env(**kw)
    obs_space = flat_observation_space(env.observation_space(A))
    act_space = flat_action_space(env.action_space(A))
    env.close()

    class Dummy(gym.Env):      # the spaces SB3 builds a model for (never stepped)
        observation_space, action_space = obs_space, act_space

    model = PPO("MlpPolicy", Dummy(), n_steps=8, batch_size=8, seed=0, device="cpu")
    for deterministic in (True, False):
        res = still_face_measures.effects(model, 1, 0, kw, deterministic=deterministic)
        assert np.isfinite([m for m, _ in res["effects"].values()]).all()
    with pytest.raises(ValueError, match="policy=3 not allowed; allowed: an object with act"):
        still_face_measures.as_learner(3)
    bad = PPO("MlpPolicy", Dummy(), n_steps=8, batch_size=8, device="cpu")
    bad.observation_space = spaces.Box(-1, 1, (5,), np.float32)
    with pytest.raises(ValueError, match=r"the model observes \(5,\)"):
        still_face_measures.effects(bad, 1, 0, kw)
    # contingency held: a face-only agent, whose model acts in Discrete(7)
    neutral = Neutral()
    res = contingency_measures.effects(neutral, 1, 0, {"max_steps": 30, **HELD})
    assert neutral.calls == 90 and res["summary"]["live"]["smiling_fraction"][0] == 0.0
    assert contingency_measures.as_learner(neutral) is not neutral


class Neutral:
    """A stand-in for an SB3 model of the held contingency without eyes (flat observation of 0
    floats, a Discrete action): ``predict`` always answers the neutral face."""

    from gymnasium import spaces as _spaces
    observation_space = _spaces.Box(0.0, 1.0, (0,), np.float32)
    action_space = _spaces.Discrete(7)

    def __init__(self):
        self.calls = 0

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        assert obs.shape == (0,) and episode_start.shape == (1,)
        self.calls += 1
        return np.int64(0), state


# -- contingency: the effect for any policy ---------------------------------------------------
def test_contingency_effects_scripted_random_zero():
    kw = {"max_steps": 1000, **FREE}      # the default: the learner's gaze its own
    scripted = contingency_measures.effects(ContingencyDetectorController(), 2, 1000, kw)
    live = scripted["live_minus_replay"]
    timer = scripted["live_minus_non_contingent"]
    assert set(live) == set(contingency_measures.EFFECT_MEASURES)
    # measured (2 blocks of 1000 steps): live minus replay smiling +0.05, contingency index
    # +0.67; minus non-contingent +0.13, +1.08 (10 blocks of 2000 steps: the task table); the
    # detector looks at the face in every condition: no gaze difference
    assert live["smiling_fraction"][0] > 0.02 and live["contingency_index"][0] > 0.2
    assert timer["smiling_fraction"][0] > 0.05 and timer["contingency_index"][0] > 0.2
    assert abs(live["gaze_fraction"][0]) < 0.02
    assert all(scripted["summary"][c]["gaze_fraction"][0] > 0.95 for c in scripted["summary"])
    zero = contingency_measures.effects(Zero(), 2, 1000, kw)
    for key in ("live_minus_replay", "live_minus_non_contingent"):
        assert all(v == (0.0, 0.0) for v in zero[key].values())
    assert all(zero["summary"][c]["gaze_fraction"][0] == 0.0 for c in zero["summary"])
    free = contingency_measures.effects(Random(), 2, 1000, kw)
    # a random head: its gaze on the face is rare in every condition (measured <= 0.16)
    assert all(free["summary"][c]["gaze_fraction"][0] < 0.3 for c in free["summary"])
    assert "| gaze_fraction |" in contingency_measures.format_effects(free)


# -- still face: the classic response's reward ------------------------------------------------
def test_still_response_reward_pays_the_classic_response_only():
    kw = {"task_options": {"phases_s": (1.0, 1.0, 1.0), "phase_jitter": 0.0}, "per_agent": NO_EYES}
    base = {"phases_s": (1.0, 1.0, 1.0), "phase_jitter": 0.0}
    with pytest.raises(ConfigError, match=r"still_response_reward=0.5 .*arms_free=False"):
        still_face_v0.parallel_env(task_options={"still_response_reward": 0.5,
                                                 "arms_free": False})
    with pytest.raises(ConfigError, match="still_response_reward"):
        still_face_v0.parallel_env(task_options={"still_response_reward": -1.0})
    returns = {}
    for r in (0.0, 0.5):
        env = still_face_v0.scripted_env(task_options={**base, "still_response_reward": r},
                                         per_agent=NO_EYES)
        steps = []
        [episode] = run_episodes(env, {A: StillFaceInfantController()}, 1, 0,
                                 on_step=lambda e, o, rw, te, tr, info: steps.append(info[A]))
        returns[r] = episode.returns[A]
        response = sum(bool(i["still_response"]) for i in steps)
        engaged = episode.last_infos[A]["engaged_steps"]
        assert all(i["phase"] == 1 and i["self_touch"] and not i["smiling"]
                   and not i["gaze_on_face"] for i in steps if i["still_response"])
        unshared = sum(bool(i["smiling"]) and not i["engaged"] for i in steps)
        assert returns[r] == pytest.approx(engaged + r * response - unshared)
        env.close()
    assert returns[0.5] > returns[0.0] + 10          # measured +36 (72 response steps of 100)
    # self-touch while smiling, or smiling at the still face, earns nothing of it
    env = still_face_v0.scripted_env(task_options={**base, "still_response_reward": 0.5},
                                     per_agent=NO_EYES)
    [smiling] = run_episodes(env, {A: StillFaceInfantController(still_face="happy")}, 1, 0)
    last = smiling.last_infos[A]
    assert smiling.returns[A] <= last["engaged_steps"] - 90   # smiling at the still face costs
    [zero] = run_episodes(env, {A: Zero()}, 1, 0)
    assert zero.returns[A] == 0.0
    del kw
