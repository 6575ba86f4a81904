"""Foveated eyes (issue 32): the warp magnifies the centre with its strength, keeps the whole
field of view, leaves the images of eyes without a fovea as they were, resamples depth the same
way, composes with the acuity blur, refuses bad values and pickles."""

import pickle

import numpy as np
import pytest

from mimo_social.envs import free_play_v0
from mimo_social.render import eye_renderer
from mimo_social.senses.acuity import AcuityBlur
from mimo_social.senses.fovea import (FoveaConfig, FovealWarp, check_fovea, profile_exponent,
                                      radial_profile, source_points)
from mimo_social.senses.vision import VisionConfig, vision_system
from mimo_social.util.checks import ConfigError

S = 32      # output side of the eyes in these tests


def make_env(size=S, **vision):
    env = free_play_v0.parallel_env(n_agents=2, vision={"width": size, "height": size, **vision})
    env.reset(seed=0)
    return env


def zero_actions(env):
    return {a: {"motors": np.zeros(env.action_space(a)["motors"].shape, np.float32),
                "expression": 0} for a in env.agents}


def first_obs(size=S, **vision):
    env = make_env(size, **vision)
    obs, _ = env.reset(seed=0)
    env.close()
    return obs


def test_profile_is_the_identity_at_strength_one_and_magnifies_the_centre_by_the_strength():
    rho = np.linspace(0.0, 1.0, 101)
    assert np.array_equal(radial_profile(rho, 1.0), rho)
    for strength in (1.5, 2.0, 4.0, 16.0):
        f = radial_profile(rho, strength)
        assert f[0] == 0.0 and f[-1] == pytest.approx(1.0)          # centre and border kept
        assert np.all(np.diff(f) > 0)                                # monotonic: nothing lost
        slope = radial_profile(1e-7, strength) / 1e-7
        assert 1.0 / slope == pytest.approx(strength, rel=1e-5)
    assert profile_exponent(1.0) == 0.0


def test_the_border_maps_onto_the_border_so_the_whole_field_of_view_is_kept():
    w, h = 48, 32
    edge = np.linspace(0.0, w, 25)
    for strength in (2.0, 8.0):
        sx, sy = source_points(edge, np.zeros_like(edge), w, h, strength)    # top edge
        assert np.allclose(sy, 0.0) and sx[0] == pytest.approx(0) and sx[-1] == pytest.approx(w)
        sx, sy = source_points(np.full(5, w), np.linspace(0, h, 5), w, h, strength)
        assert np.allclose(sx, w) and sy[0] == pytest.approx(0) and sy[-1] == pytest.approx(h)
        sx, sy = source_points(w / 2, h / 2, w, h, strength)
        assert (sx, sy) == (pytest.approx(w / 2), pytest.approx(h / 2))


def test_central_pixel_count_of_the_map_rises_with_the_strength():
    counts = [FovealWarp(check_fovea(s, 64, 64), 64, 64).pixels_within(0.25)
              for s in (1, 2, 4, 8)]
    assert counts[0] == 16 * 16                       # no magnification: a quarter per side
    assert all(a < b for a, b in zip(counts, counts[1:])), counts


def test_through_the_observation_the_partner_covers_more_pixels_the_stronger_the_fovea():
    """The partner stands in the middle of the view: with depth, the pixels nearer than 1.5 m
    (the partner; floor and sky are farther) count the output pixels given to the centre."""
    counts, seen = [], []
    for fovea in (None, 2, 4):
        obs = first_obs(48, depth=True, fovea=fovea)["infant_0"]
        near = obs["depth_left"] < 1.5
        counts.append(int(np.count_nonzero(near)))
        seen.append(obs["eye_left"][near].astype(float).mean(axis=0))
    assert counts[0] > 100
    assert counts[0] < counts[1] < counts[2], counts
    # the near pixels are the partner in every image (its colours, not the floor's)
    assert np.allclose(seen[0], seen[2], atol=40), seen


def test_strength_one_without_a_larger_render_equals_no_fovea_bit_for_bit():
    plain = first_obs(depth=True)
    ident = first_obs(depth=True, fovea={"strength": 1, "render_scale": 1})
    for agent in plain:
        for key in plain[agent]:
            assert np.array_equal(plain[agent][key], ident[agent][key]), (agent, key)


def test_fovea_off_gives_the_images_of_the_tile_renderer_unchanged():
    """Off (the default, and None) the observation is the renderer's tile itself, as before."""
    env = make_env(depth=True)
    obs, _ = env.reset(seed=0)
    off, _ = make_env(depth=True, fovea=None).reset(seed=0)
    m, d = env.world.model, env.world.data
    right, left = (int(c) for c in env.world.agents[0].eye_cameras)
    renderer = eye_renderer.TileRenderer([eye_renderer.Tile(S, S, True)] * 2, [[0, 1]])
    tiles = renderer.render(m, d, [(0, left), (1, right)])
    for t, eye in enumerate(("left", "right")):
        assert np.array_equal(obs["infant_0"][f"eye_{eye}"], tiles[t][0])
        assert np.array_equal(obs["infant_0"][f"depth_{eye}"], tiles[t][1])
        assert np.array_equal(off["infant_0"][f"eye_{eye}"], tiles[t][0])
    assert vision_system(env).foveas == {0: None, 1: None}
    renderer.close()
    env.close()


def test_spaces_keep_their_shapes():
    plain = free_play_v0.parallel_env(n_agents=1, vision={"width": 40, "height": 24,
                                                          "depth": True})
    fov = free_play_v0.parallel_env(n_agents=1, vision={"width": 40, "height": 24,
                                                        "depth": True, "fovea": 3})
    a, b = plain.observation_space("infant_0"), fov.observation_space("infant_0")
    for key in ("eye_left", "eye_right", "depth_left", "depth_right"):
        assert a[key] == b[key], key
    obs, _ = fov.reset(seed=1)
    assert obs["infant_0"]["eye_left"].shape == (24, 40, 3)
    assert obs["infant_0"]["depth_right"].shape == (24, 40)
    assert b.contains(obs["infant_0"])
    plain.close()
    fov.close()


@pytest.mark.parametrize("acuity", [None, 2.0])
def test_images_and_depth_are_the_warp_of_the_larger_render_blurred_first(acuity):
    """The fovea's images are the warp of the eye rendered k times larger (blurred there, in
    degrees, when acuity is on); its depth the render's depth at each pixel's centre."""
    k = 3
    fov = make_env(depth=True, fovea={"strength": 2.5, "render_scale": k}, acuity=acuity)
    big = make_env(S * k, depth=True)
    a, _ = fov.reset(seed=2)
    b, _ = big.reset(seed=2)
    warp = vision_system(fov).foveas[0]
    assert (warp.render_height, warp.render_width) == (S * k, S * k)
    for eye in ("left", "right"):
        rgb = b["infant_0"][f"eye_{eye}"]
        if acuity is not None:
            rgb = AcuityBlur(acuity, S * k, S * k)(rgb)
        assert np.array_equal(a["infant_0"][f"eye_{eye}"], warp.rgb(rgb)), eye
        depth = b["infant_0"][f"depth_{eye}"]
        assert np.array_equal(a["infant_0"][f"depth_{eye}"],
                              depth.reshape(-1)[warp.nearest]), eye
        # the centre pixel of the fovea shows what the centre of the plain eye shows
        c = S // 2
        assert a["infant_0"][f"depth_{eye}"][c, c] == pytest.approx(
            depth[c * k, c * k], rel=0.05)
    fov.close()
    big.close()


def test_settings_are_parsed():
    assert VisionConfig().fovea is None and VisionConfig(fovea=False).fovea is None
    assert VisionConfig(fovea=True).fovea == FoveaConfig(4.0, 4)
    assert VisionConfig(fovea=2.5).fovea == FoveaConfig(2.5, 3)
    assert VisionConfig(fovea={"strength": 3, "render_scale": 2}).fovea == FoveaConfig(3.0, 2)
    assert VisionConfig(fovea={"strength": 3, "render_scale": None}).fovea == FoveaConfig(3.0, 3)


@pytest.mark.parametrize("value,words", [
    (0.5, ["fovea strength=0.5", "from 1 to 16"]),
    (17, ["fovea strength=17", "from 1 to 16"]),
    (float("nan"), ["fovea strength=nan"]),
    ("strong", ["fovea='strong'", "None (off)", "a mapping"]),
    ([2], ["fovea=[2]", "allowed"]),
    ({"strength": 2, "render_scale": 0}, ["render_scale=0", "an integer from 1 to 8"]),
    ({"strength": 2, "render_scale": 1.5}, ["render_scale=1.5", "an integer from 1 to 8"]),
    ({"render_scale": 2}, ["has no 'strength'"]),
    ({"strength": 2, "sharpness": 1}, ["unknown setting(s) ['sharpness']", "render_scale"]),
])
def test_bad_values_are_refused_naming_the_field_the_value_and_what_is_allowed(value, words):
    with pytest.raises(ConfigError) as err:
        VisionConfig(fovea=value)
    text = str(err.value)
    assert text.startswith("vision: fovea")
    for w in words:
        assert w in text, (w, text)


def test_a_render_too_large_is_refused_and_env_errors_name_the_agent():
    with pytest.raises(ConfigError, match=r"renders 4096x8192 pixels; allowed: at most 4096"):
        VisionConfig(width=512, height=1024, fovea={"strength": 8, "render_scale": 8})
    with pytest.raises(ConfigError, match=r"fovea strength=0 not allowed"):
        free_play_v0.parallel_env(n_agents=1, vision={"width": 16, "height": 16, "fovea": 0})


def test_an_env_with_a_fovea_pickles_and_is_deterministic():
    env = make_env(depth=True, fovea=3)
    env.step(zero_actions(env))
    clone = pickle.loads(pickle.dumps(env))
    assert vision_system(clone).renderer is None
    warp = vision_system(env).foveas[0]
    assert len(pickle.dumps(warp)) < 1000          # its recipe, not its matrix
    assert vision_system(clone).foveas[0] is warp   # one per setting and size in a process
    a, *_ = env.step(zero_actions(env))
    b, *_ = clone.step(zero_actions(clone))
    again = make_env(depth=True, fovea=3)
    again.step(zero_actions(again))
    c, *_ = again.step(zero_actions(again))
    for agent in a:
        for key in a[agent]:
            assert np.array_equal(a[agent][key], b[agent][key]), (agent, key)
            assert np.array_equal(a[agent][key], c[agent][key]), (agent, key)
    for e in (env, clone, again):
        e.close()


def test_bench_vision_fovea_option_and_table():
    from mimo_social.bench import vision_cost
    from mimo_social.cli import build_parser

    args = build_parser().parse_args(["bench", "vision", "--fovea", "--sim-seconds", "2"])
    assert args.fovea and args.sim_seconds == 2.0
    names = list(vision_cost.FOVEA_CONFIGS)
    assert names[0] == "64x64, fovea off" and names[-1] == "128x128, fovea 4"
    rows = [{"config": names[0], "vision_ms_per_step": 0.5, "total_ms_per_step": 0.9,
             "total": 0.09},
            {"config": names[-1], "vision_ms_per_step": 8.0, "total_ms_per_step": 9.0,
             "total": 0.9}]
    text = vision_cost.format_fovea(rows)
    assert "| 64x64 | off | 0.50 | 0.90 | 0.090 |" in text
    assert "| 128x128 | 4; 512 px | 8.00 | 9.00 | 0.900 |" in text


def test_a_checked_setting_is_checked_again_where_it_is_reused():
    import dataclasses

    cfg = VisionConfig(width=64, height=64, fovea=8)
    assert VisionConfig(fovea=cfg.fovea).fovea == cfg.fovea
    assert VisionConfig(**dataclasses.asdict(cfg)) == cfg
    with pytest.raises(ConfigError, match="fovea render_scale=8 renders 512x8192"):
        dataclasses.replace(cfg, height=1024)
    with pytest.raises(ConfigError, match="fovea strength=100"):
        VisionConfig(fovea=FoveaConfig(100.0, 2))


def test_an_age_change_at_reset_keeps_the_blur_at_the_render_size_of_the_fovea():
    """An age change (reset option) rebuilds the acuity blur for the eye rendered k times
    larger, as a new env of that age builds it (it was once rebuilt for the observed size:
    at 96 px a 1-month-old's cut-off is above Nyquist, so the blur was dropped)."""
    vision = {"width": 96, "height": 96, "fovea": 3, "acuity": "age"}
    grown = free_play_v0.parallel_env(n_agents=1, vision=vision, per_agent=[{"age_months": 0}])
    grown.reset(seed=0)
    obs, _ = grown.reset(seed=0, options={"age_months": 1})
    born = free_play_v0.parallel_env(n_agents=1, vision=vision, per_agent=[{"age_months": 1}])
    ref, _ = born.reset(seed=0)
    blur, want = vision_system(grown).blurs[0], vision_system(born).blurs[0]
    assert blur is not None and (blur.height, blur.width) == (288, 288)
    assert blur.sigma_px == pytest.approx(want.sigma_px)
    for eye in ("eye_left", "eye_right"):
        assert np.array_equal(obs["infant_0"][eye], ref["infant_0"][eye])
    grown.close()
    born.close()
