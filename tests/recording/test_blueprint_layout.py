"""The default layout on a 1920x1080 page: large 3D view, each agent's eyes in its own panel at
>= 200 px, one time-series view per task plot, a wide contacts log, collapsed side panels.

Sizes are computed from the blueprint's container shares, with the viewer's chrome taken off
(top bar, compact time panel, a title bar per view, a tab bar per tab container)."""

from __future__ import annotations

import math

import pytest
import rerun.blueprint as rrb

from mimo_social.envs import free_play_v0, high_five_v0
from mimo_social.recording import Recorder

PAGE_W, PAGE_H = 1920, 1080
TOP_BAR, TIME_PANEL = 40, 70        # Rerun's top panel; the time panel, compact (generous)
TITLE, TAB_BAR = 24, 24


def layout(node, x=0.0, y=0.0, w=float(PAGE_W), h=float(PAGE_H - TOP_BAR - TIME_PANEL),
           in_tabs=False):
    """Every view with its rectangle (x, y, w, h) in px, and whether it sits in a tab."""
    kind = str(getattr(node, "kind", ""))
    contents = [c for c in (getattr(node, "contents", None) or []) if not isinstance(c, str)]
    if not kind or not contents and not hasattr(node, "column_shares"):
        yield node, (x, y, w, h - TITLE), in_tabs
        return
    n = len(contents)
    if "Tabs" in kind:
        for c in contents:
            yield from layout(c, x, y + TAB_BAR, w, h - TAB_BAR, True)
    elif "Horizontal" in kind:
        shares = list(node.column_shares or [1] * n)
        for c, s in zip(contents, shares):
            cw = w * s / sum(shares)
            yield from layout(c, x, y, cw, h, in_tabs)
            x += cw
    elif "Vertical" in kind:
        shares = list(node.row_shares or [1] * n)
        for c, s in zip(contents, shares):
            ch = h * s / sum(shares)
            yield from layout(c, x, y, w, ch, in_tabs)
            y += ch
    elif "Grid" in kind:
        cols = node.grid_columns or math.ceil(math.sqrt(n))
        rows = math.ceil(n / cols)
        for k, c in enumerate(contents):
            yield from layout(c, x + (k % cols) * w / cols, y + (k // cols) * h / rows,
                              w / cols, h / rows, in_tabs)
    else:
        raise AssertionError(f"unknown container {kind}")


def views_of(rec):
    bp = rec.blueprint()
    return bp, {getattr(v, "origin", None) if not isinstance(v, rrb.TimeSeriesView) else v.name:
                (v, rect, tabbed) for v, rect, tabbed in layout(bp.root_container)}


@pytest.fixture(scope="module")
def vision_envs():
    try:
        envs = {n: free_play_v0.parallel_env(n_agents=n, touch=True,
                                             vision={"width": 64, "height": 64})
                for n in (2, 3)}
        for e in envs.values():
            e.reset(seed=0)
    except Exception as exc:   # no GL here
        pytest.skip(f"vision unavailable: {exc}")
    yield envs
    for e in envs.values():
        e.close()


@pytest.mark.parametrize("n", [2, 3])
def test_each_agents_eyes_in_its_own_panel_at_200_px(vision_envs, n, tmp_path):
    env = vision_envs[n]
    with Recorder(env, tmp_path / "bp.rrd") as rec:
        bp, views = views_of(rec)
    for agent in env.possible_agents:
        eyes = [views[f"/agents/{agent}/eyes/{e}"] for e in ("left", "right")]
        (_, left, tab_l), (_, right, tab_r) = eyes
        for _, _, w, h in (left, right):
            assert min(w, h) >= 200, f"{agent}'s eye shows at {min(w, h):.0f} px"
        assert left[1] == right[1] and left[0] < right[0]          # side by side
        face = views[f"/agents/{agent}/face"][1]
        assert face[1] == left[1] and face[0] < left[0]            # the face beside them
        assert tab_l == tab_r == (n > 2)                           # a tab per agent beyond 2
    world = views["/world"][1]
    assert world[2] >= 0.5 * PAGE_W and world[3] >= 0.55 * PAGE_H  # the 3D view large
    assert str(bp.selection_panel.state) == "collapsed"
    assert str(bp.blueprint_panel.state) == "collapsed"


def test_contacts_log_wide_visible_and_showing_only_time_and_text(vision_envs, tmp_path):
    with Recorder(vision_envs[2], tmp_path / "bp.rrd") as rec:
        _, views = views_of(rec)
    view, (_, _, w, h), tabbed = views["/events/contacts"]
    assert isinstance(view, rrb.TextLogView) and not tabbed
    assert w >= 550 and h >= 150
    cols = view.properties["TextLogColumns"]
    shown = {c["kind"]: c["visible"] for c in cols.text_log_columns.pa_array.to_pylist()}
    assert shown == {1: False, 2: False, 3: True}   # entity path, level hidden; text shown
    times = {c["timeline"]: c["visible"] for c in cols.timeline_columns.pa_array.to_pylist()}
    assert times == {"sim_time": True, "step": False}


def test_one_view_per_task_plot_and_the_touch_totals(tmp_path):
    env = high_five_v0.parallel_env()
    env.reset(seed=0)
    with Recorder(env, tmp_path / "hf.rrd") as rec:
        _, views = views_of(rec)
    plots = env.task.plots()
    series = {k: v for k, v in views.items() if isinstance(v[0], rrb.TimeSeriesView)
              and k != "action norms"}
    assert list(series) == [p.title for p in plots] + ["touch totals (N)"]
    assert list(series["reward"][0].contents) == ["/agents/infant_0/reward"]   # shared: one
    assert list(series["hand_feels_partner (0/1)"][0].contents) == [
        "/plots/hand_feels_partner/infant_0", "/plots/hand_feels_partner/infant_1"]
    for _, (_, _, w, h), tabbed in series.values():
        assert not tabbed and w >= 250 and h >= 120
    assert not [k for k in views if "eyes" in str(k)]          # no vision: no eye panels
    legend = getattr(rec._skin, "legend_paths", ())
    if legend:                                                 # beside the 3D view
        world = views["/world"][1]
        key = views[legend[0]][1]
        assert key[0] >= world[0] + world[2] - 1 and key[1] == world[1]
    env.close()
