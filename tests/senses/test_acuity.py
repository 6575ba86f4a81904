"""Visual development (issue 18): the acuity table, the blur's law measured on sine gratings in
cycles per degree through the eye's geometry, and the blur in an env's eye images."""

import math
import pickle

import numpy as np
import pytest

from mimo_social.core.config import AgentConfig
from mimo_social.envs import free_play_v0
from mimo_social.senses.acuity import (CUTOFF_MODULATION, AcuityBlur, acuity_at, acuity_blur,
                                       acuity_table, blur_acts_from_height, nyquist_cpd,
                                       pixels_per_degree)
from mimo_social.senses.vision import VisionConfig, eye_images, vision_system
from mimo_social.util.checks import ConfigError


def grating(cpd, height, width, axis, amplitude=100.0, mean=128.0):
    """A sine grating of ``cpd`` cycles per degree (on the line of sight of a 60 degree eye)
    varying along ``axis`` (1: across, 0: down), as uint8 RGB."""
    f = cpd / pixels_per_degree(height)                      # cycles per pixel
    n = width if axis == 1 else height
    wave = mean + amplitude * np.sin(2 * np.pi * f * np.arange(n) + 0.3)
    plane = np.tile(wave, (height, 1)) if axis == 1 else np.tile(wave[:, None], (1, width))
    return np.repeat(np.rint(plane)[..., None], 3, axis=2).astype(np.uint8), f


def contrast(img, f, axis, amplitude=100.0):
    """The grating's amplitude left in ``img`` (least squares on sin and cos of its frequency,
    away from the borders), as a fraction of ``amplitude``."""
    gray = img.astype(float).mean(axis=2)
    profile = gray.mean(axis=0 if axis == 1 else 1)
    n = len(profile)
    keep = slice(n // 8, n - n // 8)
    x = np.arange(n)[keep]
    basis = np.stack([np.sin(2 * np.pi * f * x), np.cos(2 * np.pi * f * x), np.ones_like(x)], 1)
    coef, *_ = np.linalg.lstsq(basis, profile[keep], rcond=None)
    return math.hypot(coef[0], coef[1]) / amplitude


def test_acuity_table_follows_the_cited_norms_and_is_off_from_24_months_and_for_adults():
    table = dict(acuity_table())
    assert table[0.5] == 0.66 and table[6] == 7.44 and table[18] == 12.39 and table[24] == 14.64
    assert acuity_at(0) == 0.66 and acuity_at(6) == pytest.approx(7.44)
    assert acuity_at(1.0) == pytest.approx(2 ** np.interp(1.0, [0.5, 2], np.log2([0.66, 2.02])))
    assert acuity_at(24) is None and acuity_at(30) is None and acuity_at(None) is None
    assert AgentConfig(body="adult").age is None


@pytest.mark.parametrize("cutoff,height,width", [(2.02, 512, 384), (0.66, 256, 256),
                                                 (3.89, 1024, 160)])
@pytest.mark.parametrize("axis", [0, 1])
def test_gratings_below_the_cutoff_pass_and_above_it_are_cut(cutoff, height, width, axis):
    blur = AcuityBlur(cutoff, height, width)
    assert not blur.identity
    measured = {}
    for k in (0.5, 1.0, 1.5):
        img, f = grating(k * cutoff, height, width, axis)
        out = blur(img)
        assert out.dtype == np.uint8 and out.shape == img.shape
        assert contrast(img, f, axis) > 0.99        # the grating as drawn
        measured[k] = contrast(out, f, axis)
    assert measured[0.5] >= 0.5                     # law: 0.1 ** (1/4) = 0.56
    assert measured[1.0] == pytest.approx(CUTOFF_MODULATION, abs=0.02)
    assert measured[1.5] <= 0.02                    # law: 0.1 ** 2.25 = 0.006


def test_no_blur_at_or_above_nyquist_and_none_when_off():
    img = np.random.default_rng(0).integers(0, 256, (128, 128, 3), dtype=np.uint8)
    assert nyquist_cpd(128) == pytest.approx(0.9674, abs=1e-4)
    top = AcuityBlur(nyquist_cpd(128), 128, 128)
    assert top.identity and top(img) is img
    assert acuity_blur(12.39, 128, 128) is None     # 18 months at 128 px: nothing to cut
    assert acuity_blur(None, 128, 128) is None
    assert blur_acts_from_height(0.66) == 88 and acuity_blur(0.66, 87, 87) is None
    assert acuity_blur(0.66, 88, 88) is not None


def test_bad_acuity_values_are_refused_naming_field_value_and_what_is_allowed():
    assert VisionConfig().acuity is None
    assert VisionConfig(acuity=3).acuity == 3.0 and VisionConfig(acuity="age").acuity == "age"
    for bad in ("young", 0.0, 500, True, float("nan"), [1.0]):
        with pytest.raises(ConfigError, match=r"acuity=.*not allowed; allowed: None \(off\), "
                                              r"'age'.*cycles per degree from 0.1 to 100"):
            VisionConfig(acuity=bad)
    with pytest.raises(ConfigError, match="agent infant_0: vision: acuity='young'"):
        free_play_v0.parallel_env(n_agents=1, vision={"acuity": "young"})


def high_band_power(img, cpd):
    """The power of the image's grey levels at spatial frequencies above ``cpd`` (cycles per
    degree on the line of sight)."""
    gray = img.astype(float).mean(axis=2)
    window = np.outer(np.hanning(gray.shape[0]), np.hanning(gray.shape[1]))  # no wrap edges
    spec = np.abs(np.fft.fft2((gray - gray.mean()) * window)) ** 2
    fy = np.fft.fftfreq(gray.shape[0])[:, None]
    fx = np.fft.fftfreq(gray.shape[1])[None, :]
    radial = np.hypot(fx, fy) * pixels_per_degree(gray.shape[0])
    return spec[radial > cpd].sum()


@pytest.fixture(scope="module")
def two_envs():
    """Free play with a newborn and an 18-month-old, 128-pixel eyes, acuity from age and off."""
    envs = {}
    for acuity in ("age", None):
        env = free_play_v0.parallel_env(
            n_agents=2, vision={"width": 128, "height": 128, "depth": True, "acuity": acuity},
            per_agent=[{"age_months": 0}, {"age_months": 18}])
        env.reset(seed=0)
        envs[acuity] = env
    yield envs
    for env in envs.values():
        env.close()


def test_the_young_eye_sees_less_fine_detail_and_18_months_at_128_px_is_untouched(two_envs):
    on, off = two_envs["age"], two_envs[None]
    assert vision_system(on).cutoffs == {0: 0.66, 1: 12.39}
    assert vision_system(off).cutoffs == {0: None, 1: None}
    obs_on, obs_off = ({a: o for a, o in env.step(  # a step: the images observations get
        {a: {"motors": np.zeros(env.action_space(a)["motors"].shape, np.float32),
             "expression": 0} for a in env.agents})[0].items()} for env in (on, off))
    young, old = on.agents
    for eye in ("eye_left", "eye_right"):
        sharp, blurred = obs_off[young][eye], obs_on[young][eye]
        assert np.array_equal(eye_images(on, young)[eye], blurred)   # what eye_images sees
        assert high_band_power(sharp, 0.66) > 0
        assert high_band_power(blurred, 0.66) < 0.01 * high_band_power(sharp, 0.66)
        assert abs(blurred.astype(float).mean() - sharp.astype(float).mean()) < 1.0
        # the 18-month-old's cut-off is above 128 px's Nyquist: its images bit for bit
        assert np.array_equal(obs_on[old][eye], obs_off[old][eye])
    copy = pickle.loads(pickle.dumps(vision_system(on)))      # the blur travels with the env
    assert copy.cutoffs == {0: 0.66, 1: 12.39} and copy.blurs[1] is None
    assert np.array_equal(copy.blurs[0](obs_off[young]["eye_left"]), obs_on[young]["eye_left"])
    for agent in (young, old):  # depth stays sharp
        for eye in ("depth_left", "depth_right"):
            assert np.array_equal(obs_on[agent][eye], obs_off[agent][eye])
