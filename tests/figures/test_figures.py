"""The figures for people (``mimo-social figure NAME OUT.png``): every one listed, the hand of
the skin figure drawn from the geoms the skin covers, labelled pictures written."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from PIL import Image

from mimo_social import figures
from mimo_social.cli import main

XML = """<mujoco><worldbody><body pos="0.1 0.2 0.3" euler="0 0 90">
  <geom name="box" type="box" size="0.03 0.01 0.02"/>
  <geom name="sphere" type="sphere" size="0.02" pos="0 0 0.1"/>
  <geom name="capsule" type="capsule" size="0.01 0.03" pos="0 0 0.2"/>
  <geom name="cylinder" type="cylinder" size="0.01 0.02" pos="0 0 0.3"/>
  <freejoint/></body></worldbody></mujoco>"""


def test_the_figures_of_the_docs_are_listed():
    assert {"skin-hand-ball", "eyes-partner-gaze", "eyes-expressions",
            "bodies-three-sizes"} <= set(figures.FIGURES)


def test_a_geom_is_drawn_as_its_surface_where_it_is():
    m = mujoco.MjModel.from_xml_string(XML)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    for name, extent in (("box", (0.01, 0.03, 0.02)), ("sphere", (0.02,) * 3),
                         ("capsule", (0.01, 0.01, 0.04)), ("cylinder", (0.01, 0.01, 0.02))):
        g = m.geom(name).id
        tris = figures.geom_triangles(m, d, g)
        assert tris.ndim == 3 and tris.shape[1:] == (3, 3) and len(tris) >= 12, name
        rel = tris.reshape(-1, 3) - d.geom_xpos[g]
        # turned 90 degrees about z: the box's long side lies along the world's y
        assert np.allclose(np.abs(rel).max(0), extent, atol=1e-9), (name, np.abs(rel).max(0))


@pytest.mark.parametrize("name", ["eyes-expressions"])
def test_a_figure_is_written(name, tmp_path, capsys):
    out = tmp_path / f"{name}.png"
    assert main(["figure", name, str(out)]) == 0
    assert str(out) in capsys.readouterr().out
    img = np.asarray(Image.open(out).convert("RGB"))
    assert img.shape[0] > 200 and img.shape[1] > 1000
    assert (img.min(axis=2) < 60).mean() > 0.005          # dark text and lines, not blank


@pytest.mark.parametrize("left, up", [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0)])
def test_the_partners_eyes_turn_together(left, up):
    """The gaze figure's turn moves both eyes the same way (a horizontal eye motor at +1 turns
    its eye outward, so one sign for both eyes made them diverge or converge)."""
    from mimo_social.envs import joint_attention_v0

    env = joint_attention_v0.parallel_env()
    env.reset(seed=0)
    learner, partner = env.agents
    still = np.zeros(env.action_space(partner).shape, np.float32)
    turn = figures.eye_turn(len(still), left, up)
    for _ in range(40):
        env.step({learner: still, partner: turn})
    w = env.world
    head = w.data.site_xmat[w.agents[1].head_site].reshape(3, 3)
    for side in ("right", "left"):
        gaze = w.data.xmat[w.model.body(f"{w.names[1]}/{side}_eye").id].reshape(3, 3)[:, 0]
        assert gaze @ head[:, 1] == pytest.approx(0.7 * left, abs=0.1), side    # to its left
        assert gaze @ head[:, 2] == pytest.approx(0.5 * up, abs=0.1), side      # up
    env.close()
