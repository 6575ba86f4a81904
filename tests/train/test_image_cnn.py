"""One image CNN and one running normaliser for the SB3 and the RLlib paths
(:mod:`mimo_social.train.image_cnn`, issue 29): the architecture, the renaming of the layer names
of states saved before, the running statistics, and an SB3 PPO saved before the change
(``data/sb3_ppo_eyes.zip``, written by ``data/make_eyes_cnn_models.py`` with the code of then)
loading and acting as it did. The RLlib side: ``test_rllib_eyes.py``."""

import ast
import io
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
import torch
from gymnasium import spaces
from stable_baselines3 import PPO
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from mimo_social.train import encoders, image_cnn, obs_norm
from mimo_social.train.image_cnn import MAX_FINAL_SIDE, ImageCNN, RunningMeanStd

DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="module", autouse=True)
def one_torch_thread():
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)


def test_the_module_imports_only_torch_numpy_and_gymnasium():
    tree = ast.parse(Path(image_cnn.__file__).read_text())
    roots = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            roots |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            roots.add("." if node.level else (node.module or "").split(".")[0])
    assert roots <= {"__future__", "typing", "torch", "numpy", "gymnasium"}, roots
    code = ("import sys, mimo_social.train.image_cnn; "
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'stable_baselines3', 'ray'}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=Path(__file__).resolve().parents[2])
    assert out.stdout.strip() == "[]"


def test_both_paths_use_the_one_cnn_and_normaliser():
    assert encoders.ImageEncoder is ImageCNN
    assert issubclass(obs_norm.RunningNorm, RunningMeanStd)
    assert issubclass(obs_norm.RunningNorm, BaseFeaturesExtractor)
    ex = encoders.EyesExtractor(spaces.Dict({
        "eye": spaces.Box(0, 255, (3, 32, 32), np.uint8),
        "vector": spaces.Box(-np.inf, np.inf, (4,), np.float32)}), normalize_vector=True)
    assert type(ex.encoders["eye"]) is ImageCNN and isinstance(ex.norm, RunningMeanStd)
    # the state-dict keys SB3 models were saved with
    assert sorted(ex.state_dict()) == sorted(
        [f"encoders.eye.cnn.{i}.{p}" for i in (0, 2, 4) for p in ("weight", "bias")]
        + ["encoders.eye.head.0.weight", "encoders.eye.head.0.bias",
           "norm.mean", "norm.var", "norm.count"])


@pytest.mark.parametrize("px,flat", [(32, 64 * 4 * 4), (64, 64 * 8 * 8), (96, 64 * 6 * 6),
                                     (128, 64 * 8 * 8)])
def test_the_cnn_fits_32_to_128_px(px, flat):
    cnn = ImageCNN((6, px, px), out_dim=20)
    convs = [m for m in cnn.cnn if isinstance(m, nn.Conv2d)]
    assert [(c.kernel_size, c.stride, c.out_channels) for c in convs[:2]] == [
        ((5, 5), (2, 2), 32), ((3, 3), (2, 2), 64)]
    assert len(convs) == (3 if px <= 64 else 4) and convs[0].in_channels == 6
    assert cnn.head[0].in_features == flat <= 64 * MAX_FINAL_SIDE ** 2
    images = torch.randint(0, 256, (3, 6, px, px), dtype=torch.uint8)
    out = cnn(images)
    assert out.shape == (3, 20) and (out >= 0).all()
    # raw 0..255 in: the layers see [0, 1]
    torch.testing.assert_close(out, cnn.head(cnn.cnn(images.float() / 255)))
    with pytest.raises(ValueError, match="not allowed"):
        ImageCNN((0, px, px))


def test_a_state_with_the_former_rllib_layer_names_loads():
    source, target = ImageCNN((3, 32, 32), 8), ImageCNN((3, 32, 32), 8)
    old = {k.replace("cnn.", "convs.").replace("head.", "out."): v
           for k, v in source.state_dict().items()}
    assert any(k.startswith("convs.") for k in old) and "out.0.weight" in old
    target.load_state_dict(old)                       # strict: every key found and used
    for key, value in source.state_dict().items():
        assert torch.equal(target.state_dict()[key], value), key
    # nested (the prefix of a module inside a module), today's names untouched
    outer, again = nn.ModuleDict({"eye": ImageCNN((3, 32, 32), 8)}), ImageCNN((3, 32, 32), 8)
    outer.load_state_dict({f"eye.{k}": v for k, v in old.items()})
    again.load_state_dict(source.state_dict())
    x = torch.randint(0, 256, (2, 3, 32, 32))
    torch.testing.assert_close(outer["eye"](x), source(x))
    torch.testing.assert_close(again(x), source(x))
    # an unknown layer name is still an error
    with pytest.raises(RuntimeError, match="Unexpected"):
        target.load_state_dict({**source.state_dict(), "convx.0.weight": torch.zeros(1)})


def test_running_mean_std_matches_the_statistics_of_all_batches():
    rng = np.random.default_rng(0)
    batches = [rng.normal(3.0, 2.0, (n, 4)).astype(np.float32) for n in (5, 17, 1, 40)]
    norm = RunningMeanStd(4)
    for b in batches:
        norm.update(torch.from_numpy(b))
    seen = np.concatenate([b for b in batches if len(b) > 1])   # a single row is skipped
    np.testing.assert_allclose(norm.mean.numpy(), seen.mean(0), rtol=1e-4)
    np.testing.assert_allclose(norm.var.numpy(), seen.var(0), rtol=1e-3)
    assert abs(float(norm.count) - len(seen)) < 1e-3
    x = torch.from_numpy(seen[:3])
    want = (x - norm.mean) / torch.sqrt(norm.var + 1e-8)
    torch.testing.assert_close(norm(x), want)
    assert float(norm(torch.full((1, 4), 1e6)).max()) == 10.0            # clipped
    assert sorted(norm.state_dict()) == ["count", "mean", "var"]


def test_running_norm_learns_in_training_mode_only():
    box = spaces.Box(-np.inf, np.inf, (2, 3), np.float32)
    norm = obs_norm.RunningNorm(box)
    assert norm.features_dim == 6 and sorted(norm.state_dict()) == ["count", "mean", "var"]
    x = torch.arange(24.0).reshape(4, 2, 3)
    norm.eval()
    torch.testing.assert_close(norm(x), x.flatten(1).clamp(-10, 10))
    assert float(norm.count) < 1e-3
    norm.train()
    out = norm(x)
    assert abs(float(norm.count) - 4) < 1e-3 and out.shape == (4, 6)
    torch.testing.assert_close(norm.mean, x.flatten(1).mean(0), rtol=1e-4, atol=0)


def test_min_std_floors_the_scale_of_an_input_that_only_jitters():
    # a held joint jitters by 1e-3 rad, a moving one by 0.5: without a floor both come out at
    # unit size; with min_std 0.01 the jitter stays a tenth of it and the moving joint keeps
    # its unit scale
    rng = np.random.default_rng(1)
    x = torch.from_numpy(np.stack([rng.normal(0.3, 1e-3, 5000), rng.normal(0.0, 0.5, 5000)],
                                  1).astype(np.float32))
    plain, floored = RunningMeanStd(2), RunningMeanStd(2, min_std=0.01)
    plain.update(x)
    floored.update(x)
    assert float(plain(x)[:, 0].std()) > 0.9
    assert 0.08 < float(floored(x)[:, 0].std()) < 0.12
    np.testing.assert_allclose(float(floored(x)[:, 1].std()), float(plain(x)[:, 1].std()),
                               rtol=1e-4)
    # the default is the former normaliser, number for number
    torch.testing.assert_close(RunningMeanStd(2, min_std=0.0).normalize(x), x.clamp(-10, 10))
    box = spaces.Box(-np.inf, np.inf, (2,), np.float32)
    assert obs_norm.RunningNorm(box, min_std=0.05).min_std == 0.05


def _saved_policy_keys(path: Path) -> set[str]:
    with zipfile.ZipFile(path) as z:
        return set(torch.load(io.BytesIO(z.read("policy.pth")), weights_only=True))


def test_a_ppo_saved_before_the_shared_cnn_loads_and_acts_the_same():
    """``sb3_ppo_eyes.zip``: PPO with ``policy_spec(..., image_dim=8, normalize_vector=True)``
    on two 32 px eyes and a 5-float vector, trained 64 steps, saved with the code before
    ``image_cnn``; its deterministic actions, action means and values on two fixed
    observations are in ``sb3_ppo_eyes.npz``."""
    path = DATA / "sb3_ppo_eyes.zip"
    assert path.stat().st_size < 200_000
    expected = np.load(DATA / "sb3_ppo_eyes.npz")
    model = PPO.load(path, device="cpu")               # strict: every saved key is used
    policy = model.policy
    assert set(policy.state_dict()) == _saved_policy_keys(path)
    ex = policy.features_extractor
    assert type(ex.encoders["eye_left"]) is ImageCNN
    assert ex.encoders["eye_left"] is ex.encoders["eye_right"]
    assert float(ex.norm.count) > 1                    # the saved statistics came back
    obs = {k[len("obs_"):]: expected[k] for k in expected.files if k.startswith("obs_")}
    actions, _ = model.predict(obs, deterministic=True)
    np.testing.assert_allclose(actions, expected["actions"], rtol=0, atol=1e-6)
    policy.set_training_mode(False)
    with torch.no_grad():
        tensor, _ = policy.obs_to_tensor(obs)
        means = policy.get_distribution(tensor).distribution.mean.numpy()
        values = policy.predict_values(tensor).numpy()[:, 0]
    np.testing.assert_allclose(means, expected["means"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(values, expected["values"], rtol=0, atol=1e-5)
