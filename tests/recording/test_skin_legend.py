"""Skin points in a recording are coloured AND sized by the magnitude of their force (log scale),
and a legend (colour bar with labelled dots, and a text) says what colour and size mean in newtons;
checked by reading the .rrd back with Rerun's reader."""


import numpy as np
import pytest

from mimo_social.envs import free_play_v0
from mimo_social.recording import (
    SKIN_FORCE_RANGE,
    SKIN_LEGEND_PATH,
    SKIN_LEGEND_TEXT_PATH,
    SKIN_RADIUS_RANGE,
    Recorder,
    force_colors,
    force_radii,
    read_batches,
)

N_STEPS = 12


def column(data, path, name) -> list:
    """Every non-null value of component column ``name`` at ``path``, in file order."""
    return [v for b in data.get(path, []) if name in b.schema.names
            for v in b.column(name).to_pylist() if v is not None]


def rgb(color) -> tuple[int, int, int]:
    return tuple((int(color) >> s) & 0xFF for s in (24, 16, 8))


@pytest.fixture(scope="module")
def touch_file(tmp_path_factory):
    """Two standing infants with touch, arms waving: the soles and hands feel many forces."""
    env = free_play_v0.parallel_env(n_agents=2, touch=True)
    path = tmp_path_factory.mktemp("skin") / "skin.rrd"
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=0)
    with Recorder(env, path) as rec:
        rec.log_reset(obs)
        for _ in range(N_STEPS):
            actions = {a: {"motors": rng.uniform(-0.3, 0.3, 44).astype(np.float32),
                           "expression": 0} for a in env.agents}
            obs, rewards, *_ = env.step(actions)
            rec.log_step(actions, rewards, obs)
    system = env.system("touch")
    forces = {a: np.array([np.linalg.norm(v["forces"][k]) for v in system.view(a).values()
                           for k in np.flatnonzero(v["normal_force"])])
              for a in env.possible_agents}
    env.close()
    return {"data": read_batches(path), "forces": forces, "rec": rec}


def test_force_radii_grow_on_a_log_scale():
    lo, hi = SKIN_FORCE_RANGE
    r = force_radii(np.array([0.0, lo, np.sqrt(lo * hi), hi, 10 * hi]))
    np.testing.assert_allclose(r, [SKIN_RADIUS_RANGE[0], SKIN_RADIUS_RANGE[0],
                                   np.mean(SKIN_RADIUS_RANGE), SKIN_RADIUS_RANGE[1],
                                   SKIN_RADIUS_RANGE[1]], rtol=1e-6)
    assert r.dtype == np.float32
    assert SKIN_RADIUS_RANGE[1] >= 3 * SKIN_RADIUS_RANGE[0]     # no longer 4 mm specks


def test_every_skin_point_is_sized_and_coloured_by_its_force(touch_file):
    data = touch_file["data"]
    for agent, forces in touch_file["forces"].items():
        path = f"/world/{agent}/skin"
        radii, colors = column(data, path, "Points3D:radii"), column(data, path, "Points3D:colors")
        positions = column(data, path, "Points3D:positions")
        assert len(radii) == len(colors) == len(positions) == N_STEPS + 1   # a list per row
        for r, c, p in zip(radii, colors, positions):
            assert len(r) == len(c) == len(p)
        # the last row: exactly the forces the touch system holds now
        assert sorted(radii[-1]) == sorted(force_radii(forces).tolist())
        assert sorted(colors[-1]) == sorted(force_colors(forces).tolist())
        # bigger force, bigger dot, darker colour: radius and colour tell the same force
        r, c = np.array(radii[-1]), np.array(colors[-1])
        order = np.argsort(r, kind="stable")
        green = np.array([rgb(x)[1] for x in c[order]])
        assert np.all(np.diff(green) <= 0)
        assert len(set(np.round(r, 6))) > 3 and r.min() >= SKIN_RADIUS_RANGE[0] - 1e-9


def test_legend_colour_bar_dots_and_text(touch_file):
    data = touch_file["data"]
    assert touch_file["rec"]._skin.legend_paths == [SKIN_LEGEND_PATH, SKIN_LEGEND_TEXT_PATH]
    fmt = column(data, f"{SKIN_LEGEND_PATH}/bar", "Image:format")[0][0]
    buf = bytes(column(data, f"{SKIN_LEGEND_PATH}/bar", "Image:buffer")[0][0])
    bar = np.frombuffer(buf, np.uint8).reshape(fmt["height"], fmt["width"], 3)
    assert bar.shape[0] > 4 * bar.shape[1]                      # a vertical bar
    lo, hi = SKIN_FORCE_RANGE
    assert tuple(bar[0, 0]) == rgb(force_colors(hi))            # strongest on top
    assert tuple(bar[-1, 0]) == rgb(force_colors(lo))
    ticks = f"{SKIN_LEGEND_PATH}/ticks"
    labels = f"{SKIN_LEGEND_PATH}/labels"
    assert column(data, labels, "Points2D:labels")[0] == ["0.01 N", "0.1 N", "1 N", "10 N"]
    label_xy = np.array(column(data, labels, "Points2D:positions")[0])
    tick_xy = np.array(column(data, ticks, "Points2D:positions")[0])
    np.testing.assert_allclose(label_xy[:, 0], tick_xy[:, 0])
    assert np.all(label_xy[:, 1] > tick_xy[:, 1])                  # each under its dot
    forces = np.array([0.01, 0.1, 1.0, 10.0])
    assert column(data, ticks, "Points2D:colors")[0] == force_colors(forces).tolist()
    radii = column(data, ticks, "Points2D:radii")[0]
    assert np.all(np.diff(radii) > 0)
    np.testing.assert_allclose(np.array(radii) / radii[-1], force_radii(forces) / force_radii(hi),
                               rtol=1e-6)                       # sized like the skin points
    for (_, y), color in zip(column(data, ticks, "Points2D:positions")[0], force_colors(forces)):
        assert np.abs(bar[int(round(y)), 0].astype(int) - rgb(color)).max() <= 8   # beside its colour
    text = column(data, SKIN_LEGEND_TEXT_PATH, "TextDocument:text")[0][0]
    media = column(data, SKIN_LEGEND_TEXT_PATH, "TextDocument:media_type")[0][0]
    assert media == "text/markdown"
    assert "coloured and sized" in text and "- **10 N**: dark red, 10 mm" in text
    assert "- **0.01 N**: yellow, 2.5 mm" in text


def test_no_legend_without_touch(tmp_path):
    env = free_play_v0.parallel_env(n_agents=1)
    obs, _ = env.reset(seed=0)
    with Recorder(env, tmp_path / "plain.rrd") as rec:
        rec.log_reset(obs)
    env.close()
    assert not [p for p in read_batches(tmp_path / "plain.rrd") if p.startswith("/legend")]
