"""Writes the saved models that ``tests/train/test_image_cnn.py`` (SB3) and
``tests/train/test_rllib_eyes.py`` (RLlib) load: a tiny SB3 PPO with the eyes' CNN
(``sb3_ppo_eyes.zip``, its expected outputs in ``sb3_ppo_eyes.npz``) and the state of a tiny
RLlib ``EyesPPOModule`` (one eye) with its expected outputs (``rllib_eyes_state.npz``).

The files in this folder were written by the code before the image CNN became one module
(issue 29: ``ImageEncoder`` of ``encoders.py`` with layers ``cnn`` / ``head``, ``ImageCNN`` of
``rllib/module.py`` with layers ``convs`` / ``out``), so the tests show that models saved then
still load and compute the same. Rerunning it writes files in today's layout (only for a
deliberate change of the format). Weights keep 4 bits of mantissa (float32 still) and the SB3
zip is re-packed with deflate, so each file stays under 200 KB.

    python tests/train/data/make_eyes_cnn_models.py sb3             # the main venv
    .venv-rllib/bin/python tests/train/data/make_eyes_cnn_models.py rllib
"""

import sys
import zipfile
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch
from gymnasium import spaces

HERE = Path(__file__).resolve().parent
PX, N_VECTOR, N_OBS = 32, 5, 2
EYES = ("eye_left", "eye_right")


def observation_space(eyes: tuple[str, ...] = EYES) -> spaces.Dict:
    parts = {eye: spaces.Box(0, 255, (3, PX, PX), np.uint8) for eye in eyes}
    parts["vector"] = spaces.Box(-np.inf, np.inf, (N_VECTOR,), np.float32)
    return spaces.Dict(parts)


def fixed_observations(seed: int = 123, eyes: tuple[str, ...] = EYES) -> dict[str, np.ndarray]:
    """``N_OBS`` observations (batched), the same on every call."""
    rng = np.random.default_rng(seed)
    obs = {eye: rng.integers(0, 256, (N_OBS, 3, PX, PX), dtype=np.uint8) for eye in eyes}
    obs["vector"] = (rng.normal(size=(N_OBS, N_VECTOR)) * 3 + 2).astype(np.float32)
    return obs


class RandomEyes(gym.Env):
    """Random eyes and vector, reward the first action's sign: something to train on."""

    def __init__(self):
        self.observation_space = observation_space()
        self.action_space = spaces.Box(-1, 1, (2,), np.float32)
        self.t = 0

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return self.observation_space.sample(), {}

    def step(self, action):
        self.t += 1
        obs = self.observation_space.sample()
        obs["vector"] = (self.np_random.normal(size=N_VECTOR) * 3 + 2).astype(np.float32)
        return obs, float(action[0]), False, self.t >= 16, {}


def _coarsen(module: torch.nn.Module) -> None:
    """Keep 4 bits of each weight's mantissa (float32 still): the files compress well."""
    with torch.no_grad():
        for p in module.parameters():
            p.view(torch.int32).bitwise_and_(-(1 << 19))


def _deflate(path: Path) -> None:
    """Re-pack an SB3 zip (written uncompressed) with deflate; ``PPO.load`` reads either."""
    with zipfile.ZipFile(path) as z:
        members = [(info, z.read(info)) for info in z.infolist()]
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as z:
        for info, data in members:
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)


def make_sb3() -> None:
    from stable_baselines3 import PPO

    from mimo_social.train.encoders import policy_spec

    torch.set_num_threads(1)
    env = RandomEyes()
    env.observation_space.seed(0)
    policy, kw = policy_spec(env.observation_space, image_dim=8, normalize_vector=True)
    model = PPO(policy, env, n_steps=32, batch_size=16, n_epochs=2, seed=0, device="cpu",
                policy_kwargs={**kw, "net_arch": [16]})
    model.learn(64)                  # weights and the vector's running statistics move
    _coarsen(model.policy)
    # a fresh optimizer (no Adam moments: they would triple the file)
    model.policy.optimizer = model.policy.optimizer_class(
        model.policy.parameters(), lr=model.lr_schedule(1), **model.policy.optimizer_kwargs)
    model.save(HERE / "sb3_ppo_eyes.zip")
    _deflate(HERE / "sb3_ppo_eyes.zip")
    obs = fixed_observations()
    actions, _ = model.predict(obs, deterministic=True)
    model.policy.set_training_mode(False)
    with torch.no_grad():
        tensor, _ = model.policy.obs_to_tensor(obs)
        means = model.policy.get_distribution(tensor).distribution.mean.numpy()
        values = model.policy.predict_values(tensor).numpy()[:, 0]
    np.savez(HERE / "sb3_ppo_eyes.npz", actions=actions, means=means, values=values,
             **{f"obs_{k}": v for k, v in obs.items()})


def make_rllib() -> None:
    from mimo_social.train.rllib.module import EyesPPOModule

    torch.manual_seed(0)
    one_eye = EYES[:1]   # (the state stores each eye's copy of a shared CNN: one keeps it small)
    module = EyesPPOModule(observation_space=observation_space(one_eye),
                           action_space=spaces.Box(-1, 1, (2,), np.float32),
                           model_config={"image_dim": 8, "fcnet_hiddens": [16],
                                         "normalize_vector": True})
    _coarsen(module)
    train_obs = fixed_observations(seed=7, eyes=one_eye)
    module.forward_train({"obs": {k: torch.from_numpy(v) for k, v in train_obs.items()}})
    obs = fixed_observations(eyes=one_eye)
    batch = {"obs": {k: torch.from_numpy(v) for k, v in obs.items()}}
    with torch.no_grad():
        dist = module.forward_inference(batch)["action_dist_inputs"].numpy()
        values = module.compute_values(batch).numpy()
    state = {f"state/{k}": np.asarray(v) for k, v in module.get_state().items()}
    np.savez_compressed(HERE / "rllib_eyes_state.npz", dist_inputs=dist, values=values,
                        **{f"obs_{k}": v for k, v in obs.items()}, **state)


if __name__ == "__main__":
    {"sb3": make_sb3, "rllib": make_rllib}[sys.argv[1]]()
