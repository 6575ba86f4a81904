"""Eyes through a CNN with RLlib: an agent with eyes sees the image Dict (uint8 channel-first
eyes, float32 ``"vector"``) and PPO / APPO get the CNN module of
:mod:`mimo_social.train.rllib.module`; ``flat_obs`` keeps the flat Box and RLlib's default MLP.
Skipped where ray's RLlib is not installed (``scripts/test_rllib.sh`` runs them in
``.venv-rllib``)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("ray.rllib")
import torch  # noqa: E402
from gymnasium import spaces  # noqa: E402

EYES = {"max_steps": 20, "per_agent": [{"vision": {"width": 32, "height": 32}}, {}]}
#: saved with the code of before (data/make_eyes_cnn_models.py)
OLD_STATE = Path(__file__).resolve().parent / "data" / "rllib_eyes_state.npz"
TINY = {"train_batch_size_per_learner": 40, "minibatch_size": 20, "num_epochs": 1,
        "fcnet_hiddens": [16], "image_dim": 16}


def _spec(task, mode, algo="ppo", **kw):
    from mimo_social.train.rllib import build_config

    config = build_config(task, mode, algo, seed=0, num_env_runners=0, env_kwargs=EYES, **kw)
    specs = config.rl_module_spec.rl_module_specs
    return config, specs["infant_0"]


def _obs_batch(task, mode, n=3, **kw):
    from mimo_social.train.rllib import learner_env

    env = learner_env(task, mode, **EYES, **kw)
    try:
        obs, _ = env.reset(seed=0)
        seen = [obs["infant_0"]]
        for _ in range(n - 1):
            obs, *_ = env.step({a: env.action_space(a).sample() for a in env.agents})
            seen.append(obs["infant_0"])
    finally:
        env.close()
    if isinstance(seen[0], dict):
        return {k: torch.from_numpy(np.stack([o[k] for o in seen])) for k in seen[0]}
    return torch.from_numpy(np.stack(seen))


def _convs(module):
    return [m for m in module.modules() if isinstance(m, torch.nn.Conv2d)]


def test_a_vision_task_gets_the_cnn_module_on_image_dicts():
    config, spec = _spec("joint_attention", "scripted")
    space = spec.observation_space
    assert isinstance(space, spaces.Dict)
    assert {k: (s.shape, s.dtype) for k, s in space.spaces.items() if k != "vector"} == {
        "eye_left": ((3, 32, 32), np.uint8), "eye_right": ((3, 32, 32), np.uint8)}
    assert space["vector"].dtype == np.float32
    assert config.env_config["flat"] is False
    module = spec.build()
    assert type(module).__name__ == "EyesPPOModule"
    # SB3's CNN: 5x5/2 32ch, then 3x3/2 64ch down to 4x4 at 32 px; one CNN for both eyes
    assert [(c.in_channels, c.out_channels, c.kernel_size, c.stride) for c in _convs(module)] \
        == [(3, 32, (5, 5), (2, 2)), (32, 64, (3, 3), (2, 2)), (64, 64, (3, 3), (2, 2))]
    obs = _obs_batch("joint_attention", "scripted")
    with torch.no_grad():
        out = module.forward_train({"obs": obs})
        values = module.compute_values({"obs": obs})
    n = spec.action_space.shape[0]
    dist = out["action_dist_inputs"]
    assert dist.shape == (3, 2 * n)                  # diagonal Gaussian: means, log stds
    assert float(dist[:, :n].abs().max()) < 0.05     # SB3's gain 0.01 on the action means
    assert torch.equal(dist[:, n:], torch.zeros(3, n))
    assert values.shape == (3,)
    action = module.get_exploration_action_dist_cls().from_logits(dist).sample()
    assert action.shape == (3, n)


def test_a_face_only_learner_gets_categorical_logits_and_appo_its_target_network():
    _, spec = _spec("mirror", "scripted", "appo")
    assert isinstance(spec.action_space, spaces.Discrete)
    module = spec.build()
    assert type(module).__name__ == "EyesAPPOModule" and _convs(module)
    obs = _obs_batch("mirror", "scripted")
    module.make_target_networks()
    with torch.no_grad():
        logits = module.forward_inference({"obs": obs})["action_dist_inputs"]
        target = module.forward_target({"obs": obs})
    assert logits.shape == (3, spec.action_space.n)
    assert torch.allclose(next(iter(target.values())), logits)


def test_flat_obs_and_sac_keep_the_flat_box_and_rllibs_default_module():
    for kw in ({"flat_obs": True}, {}):
        algo = "ppo" if kw else "sac"
        config, spec = _spec("mirror", "scripted", algo, **kw)
        assert isinstance(spec.observation_space, spaces.Box)
        assert spec.observation_space.shape == (2 * 32 * 32 * 3,)
        assert config.env_config["flat"] is True
        assert "Eyes" not in getattr(spec.module_class, "__name__", "")
        if algo == "ppo":   # (SAC's module needs the model config its algorithm adds)
            assert not _convs(spec.build())


def test_options_the_image_path_refuses():
    from mimo_social.train import TrainInputError
    from mimo_social.train.rllib import build_config

    with pytest.raises(TrainInputError, match="flat"):
        build_config("mirror", "scripted", "ppo", env_kwargs=EYES, flat_obs=True, frame_stack=2)
    with pytest.raises(TrainInputError, match="no agent"):
        build_config("high_five", "shared", "ppo", env_kwargs={"max_steps": 5}, frame_stack=2)
    with pytest.raises(TrainInputError, match="image_dim"):
        build_config("high_five", "shared", "ppo", env_kwargs={"max_steps": 5},
                     algo_kwargs={"image_dim": 8})
    # eyes on one agent only, normalised: the filter cannot take the mix
    with pytest.raises(TrainInputError, match="flat_obs"):
        build_config("joint_attention", "independent", "ppo", normalize_obs=True,
                     env_kwargs={"max_steps": 5,
                                 "per_agent": [{"vision": {"width": 32, "height": 32}},
                                               {"vision": False}]})


def test_frame_stack_stacks_eye_channels_and_normalize_obs_normalises_in_the_module():
    _, spec = _spec("joint_attention", "scripted", frame_stack=2, normalize_obs=True)
    assert spec.observation_space["eye_left"].shape == (6, 32, 32)
    module = spec.build()
    assert _convs(module)[0].in_channels == 6
    obs = _obs_batch("joint_attention", "scripted", n=4, frame_stack=2)
    state = {k: np.array(v) for k, v in module.get_state().items() if "norm" in k}
    assert state, "no running statistics in the module"
    module.forward_train({"obs": obs})               # the learner's pass updates them
    after = module.get_state()
    assert any(not np.allclose(after[k], v) for k, v in state.items())


def _small_module(eyes, algo="ppo"):
    from ray.rllib.core.rl_module.rl_module import RLModuleSpec

    from mimo_social.train.rllib.module import EyesAPPOModule, EyesPPOModule

    parts = {eye: spaces.Box(0, 255, (3, 32, 32), np.uint8) for eye in eyes}
    parts["vector"] = spaces.Box(-np.inf, np.inf, (5,), np.float32)
    return RLModuleSpec(module_class=EyesAPPOModule if algo == "appo" else EyesPPOModule,
                        observation_space=spaces.Dict(parts),
                        action_space=spaces.Box(-1, 1, (2,), np.float32),
                        model_config={"image_dim": 8, "fcnet_hiddens": [16],
                                      "normalize_vector": True}).build()


def test_the_module_uses_the_one_image_cnn_of_both_paths():
    from mimo_social.train import image_cnn
    from mimo_social.train.rllib import module as rllib_module

    assert rllib_module.ImageCNN is image_cnn.ImageCNN
    assert rllib_module.RunningMeanStd is image_cnn.RunningMeanStd
    module = _small_module(("eye_left", "eye_right"))
    cnns = module.encoder.cnns
    assert type(cnns["eye_left"]) is image_cnn.ImageCNN and cnns["eye_left"] is cnns["eye_right"]
    assert "encoder.cnns.eye_right.cnn.4.weight" in module.get_state()
    assert "encoder.cnns.eye_left.head.0.bias" in module.get_state()


def test_a_module_state_saved_before_the_shared_cnn_loads():
    """``rllib_eyes_state.npz``: the state of an ``EyesPPOModule`` (one 32 px eye, a 5-float
    vector, ``image_dim`` 8, ``fcnet_hiddens`` [16], ``normalize_vector``) saved when the module
    had its own CNN (layers ``convs.*`` / ``out.0``), with its action-distribution inputs and
    values on two observations. ``set_state`` is what RLlib's checkpoint restore calls, with
    ``strict=False``: a layer left out would pass silently, so the values are compared."""
    data = np.load(OLD_STATE)
    old = {k[len("state/"):]: data[k] for k in data.files if k.startswith("state/")}
    assert "encoder.cnns.eye_left.convs.0.weight" in old
    obs = {k[len("obs_"):]: torch.from_numpy(data[k]) for k in data.files
           if k.startswith("obs_")}
    today = {k.replace(".convs.", ".cnn.").replace("eye_left.out.", "eye_left.head."): v
             for k, v in old.items()}
    torch.manual_seed(1)
    module = _small_module(("eye_left",))
    assert sorted(module.get_state()) == sorted(today)
    module.set_state(old)
    state = module.get_state()
    for key, value in today.items():   # (RLlib passes float64 through float32: the count)
        np.testing.assert_allclose(np.asarray(state[key]), value, rtol=1e-7, atol=0,
                                   err_msg=key)
    with torch.no_grad():
        dist = module.forward_inference({"obs": obs})["action_dist_inputs"].numpy()
        values = module.compute_values({"obs": obs}).numpy()
    np.testing.assert_allclose(dist, data["dist_inputs"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(values, data["values"], rtol=0, atol=1e-5)

    # APPO's checkpoint holds the same names under its target network's
    appo = _small_module(("eye_left",), "appo")
    appo.make_target_networks()
    appo.set_state({**old, **{f"_old_{k}": v for k, v in old.items()
                              if k.startswith(("encoder.", "pi."))}})
    with torch.no_grad():
        target = next(iter(appo.forward_target({"obs": obs}).values())).numpy()
    np.testing.assert_allclose(target, data["dist_inputs"], rtol=0, atol=1e-6)

    # two eyes sharing one CNN: the state held a copy under each eye (the MLPs are wider here)
    both = _small_module(("eye_left", "eye_right"))
    cnn_state = {k: v for k, v in old.items() if k.startswith("encoder.cnns.")}
    both.set_state({**{k: v for k, v in both.get_state().items()
                       if not k.startswith("encoder.cnns.")},
                    **cnn_state, **{k.replace("eye_left", "eye_right"): v
                                    for k, v in cnn_state.items()}})
    state = both.get_state()
    for key in ("cnn.0.weight", "cnn.4.bias", "head.0.weight"):
        for eye in ("eye_left", "eye_right"):
            np.testing.assert_array_equal(np.asarray(state[f"encoder.cnns.{eye}.{key}"]),
                                          today[f"encoder.cnns.eye_left.{key}"])


@pytest.fixture(scope="module")
def local_ray():
    import ray

    from mimo_social.train.rllib.runner import init_ray

    if ray.is_initialized():
        ray.shutdown()
    init_ray(None, 2)
    yield
    ray.shutdown()


def test_training_on_image_dicts_without_flattening(local_ray, tmp_path):
    """The learner's eyes on, scripted partner: on mirror (a face-only learner) APPO's env
    runner (a Ray actor) hands the module the image Dict and an iteration trains on it; on
    joint attention (eyes and a vector, Box actions) train_rllib with PPO and --normalize-obs
    writes its progress and checkpoint (the vector statistics in the module, no
    MeanStdFilter), eval reloads it."""
    from ray.rllib.core.rl_module.rl_module import RLModule

    from mimo_social.train.rllib import build_config, evaluate_rllib, train_rllib

    appo = {"train_batch_size_per_learner": 40, "fcnet_hiddens": [16], "image_dim": 16}
    algo = build_config("mirror", "scripted", "appo", 0, num_env_runners=1, env_kwargs=EYES,
                        algo_kwargs=appo).build_algo()
    try:
        (seen,) = algo.env_runner_group.foreach_env_runner(
            lambda runner: runner.get_spaces()["infant_0"][0], remote_worker_ids=[1],
            local_env_runner=False)
        sampled = 0
        for _ in range(5):   # (APPO's first results may come before any sample)
            sampled = algo.train().get("env_runners", {}).get(
                "num_env_steps_sampled_lifetime", 0)
            if sampled >= 40:
                break
        assert sampled >= 40
    finally:
        algo.stop()
    assert isinstance(seen, spaces.Dict)
    assert {k: (s.shape, s.dtype) for k, s in seen.spaces.items()} == {
        "eye_left": ((3, 32, 32), np.uint8), "eye_right": ((3, 32, 32), np.uint8)}

    out = tmp_path / "ja"
    res = train_rllib("joint_attention", "ppo", 80, 0, out, mode="scripted", num_env_runners=0,
                      env_kwargs=EYES, algo_kwargs=TINY, eval_every=40, eval_episodes=1,
                      normalize_obs=True, progress=False)
    assert res["timesteps"] >= 80
    config = json.loads((out / "config.json").read_text())
    assert config["observation"] == {"flat": False, "frame_stack": 1}
    with open(out / "progress.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["timesteps"]) for r in rows] == [40, 80]
    assert all(np.isfinite(float(r["eval_return_mean_infant_0"])) for r in rows)
    module = RLModule.from_checkpoint(out / "checkpoint/learner_group/learner/rl_module/infant_0")
    assert isinstance(module.observation_space, spaces.Dict) and _convs(module)
    assert module.get_state()["encoder.norm.count"] > 40   # updated by the learner
    assert not (out / "checkpoint" / "mimo_obs_filter.pkl").exists()
    ev = evaluate_rllib(out, 1)
    assert ev["agents"]["infant_0"]["lengths"][0] <= 20
