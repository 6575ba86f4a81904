"""The task's plots in a recording (Task.plots -> /plots/...): every task's, read back from the
.rrd; values that follow the simulation; colours of the agents' clothes; the user's scalars."""

from __future__ import annotations


import numpy as np
import pytest
import rerun.blueprint as rrb

from mimo_social.core.task import Plot, Task
from mimo_social.core.world import CLOTHES_PALETTE
from mimo_social.envs import catalog, free_play_v0, high_five_v0
from mimo_social.tasks.high_five import HighFiveController
from mimo_social.recording import Recorder, read_batches
from mimo_social.recording.plots import SOUND_PLOT
from mimo_social.util.checks import ConfigError


def series(data, path: str) -> dict[int, float]:
    """step -> value of the Scalars at ``path`` (rows with a value)."""
    out = {}
    for batch in data.get(path, []):
        if "Scalars:scalars" not in batch.schema.names:
            continue
        for s, v in zip(batch.column("step").to_pylist(),
                        batch.column("Scalars:scalars").to_pylist()):
            if v is not None:
                out[s] = v[0]
    return dict(sorted(out.items()))


def static(data, path: str, component: str):
    found = [b.column(component).to_pylist()[0] for b in data.get(path, [])
             if component in b.schema.names and "step" not in b.schema.names]
    assert len(found) == 1, f"{path} {component}: {len(found)} static rows"
    return found[0]


def rgb(rgba) -> tuple[int, int, int]:
    return tuple(int(round(255 * c)) for c in rgba[:3])


def nodes(node):
    yield node
    for child in getattr(node, "contents", None) or []:
        if not isinstance(child, str):
            yield from nodes(child)


def plot_views(rec) -> dict[str, list[str]]:
    """Title -> series paths of the time-series views in the recorder's blueprint (the task's
    plots, in order; then touch totals and scalars if any; action norms excluded)."""
    return {n.name: list(n.contents) for n in nodes(rec.blueprint().root_container)
            if isinstance(n, rrb.TimeSeriesView) and n.name not in ("action norms",
                                                                     "touch totals (N)")}


def record(env, path, steps: int, policy=None, **kwargs):
    """Record ``steps`` env steps (``policy(obs) -> actions``; default random) from seed 0."""
    obs, _ = env.reset(seed=0)
    for a in env.possible_agents:
        env.action_space(a).seed(0)
    with Recorder(env, path, flush_every_s=0.2, **kwargs) as rec:
        rec.log_reset(obs)
        for _ in range(steps):
            if not env.agents:
                break
            actions = policy(obs) if policy else {a: env.action_space(a).sample()
                                                  for a in env.agents}
            obs, rewards, *_ = env.step(actions)
            rec.log_step(actions, rewards, obs)
    return rec


@pytest.mark.parametrize("name", catalog.names())
def test_every_task_logs_its_plots(name, tmp_path):
    env = catalog.entry(name).module.parallel_env()
    plots = env.task.plots()
    assert plots and all(isinstance(p, Plot) for p in plots)
    rec = record(env, tmp_path / f"{name}.rrd", 6, eyes=False)
    data = read_batches(tmp_path / f"{name}.rrd")
    n = len(env.possible_agents)
    views = plot_views(rec)
    voiced = tuple(i for i, c in enumerate(env.agent_configs) if c.voice)
    if voiced and SOUND_PLOT not in [p.name for p in plots]:     # the recorder's own plot
        plots = [*plots, Plot(SOUND_PLOT, "dB SPL at 1 m", lambda e: e.sounds[:, 1], True,
                              voiced)]
    assert list(views) == [p.title for p in plots]
    for p in plots:
        paths = views[p.title]
        if p.fn is None:
            assert all(s.startswith("/agents/") and s.endswith("/reward") for s in paths)
            continue
        agents = p.agents if p.agents is not None else range(n)
        expect = ([f"/plots/{p.name}/{env.possible_agents[i]}" for i in agents]
                  if p.per_agent else [f"/plots/{p.name}"])
        assert list(paths) == expect
        for s in paths:
            assert any("Scalars:scalars" in b.schema.names for b in data.get(s, [])), s
            values = series(data, s)            # (may be empty: e.g. no gaze target yet)
            assert 0 not in values, f"{s}: a value at reset"   # none before a step
            assert all(np.isfinite(v) for v in values.values())
    env.close()


def test_free_play_has_no_reward_plot_but_heights_and_distance(tmp_path):
    env = free_play_v0.parallel_env(n_agents=2)
    titles = [p.title for p in env.task.plots()]
    assert titles == ["head_height (m)", "nearest_infant (m)"]
    record(env, tmp_path / "fp.rrd", 120)
    data = read_batches(tmp_path / "fp.rrd")
    heights = series(data, "/plots/head_height/infant_0")
    d = env.world.data
    assert heights[max(heights)] == pytest.approx(d.site_xpos[env.world.agents[0].head_site, 2])
    assert max(heights.values()) - min(heights.values()) > 0.05    # random motors: it moves
    gap = series(data, "/plots/nearest_infant/infant_1")
    hips = d.xpos[[a.root_body for a in env.world.agents], :2]
    assert gap[max(gap)] == pytest.approx(np.linalg.norm(hips[0] - hips[1]))
    assert series(data, "/plots/nearest_infant/infant_0") == gap   # symmetric for two
    env.close()


def _scripted_high_five(tmp_path):
    env = high_five_v0.scripted_env(expressions=False)
    inner = env.unwrapped
    ctrl = HighFiveController()
    obs, _ = env.reset(seed=1000)
    ctrl.reset(inner, "infant_0", np.random.default_rng(1000))
    path = tmp_path / "hf.rrd"
    with Recorder(env, path, flush_every_s=0.2, eyes=False) as rec:
        rec.log_reset(obs)
        while env.agents:
            act = {"infant_0": ctrl.act(inner, "infant_0", obs["infant_0"])}
            obs, rewards, _, _, infos = env.step(act)
            rec.log_step(act, rewards, obs)
    assert infos["infant_0"]["is_success"]
    return env, rec, read_batches(path)


def test_high_five_hand_distance_falls_to_contact_at_success(tmp_path):
    env, rec, data = _scripted_high_five(tmp_path)
    dist = series(data, "/plots/hand_distance")      # palm centres (the reward's)
    gap = series(data, "/plots/hand_gap")             # hand surfaces
    success = series(data, "/plots/success")
    last = max(dist)
    assert list(success) == list(dist) == list(gap) == list(range(1, last + 1))
    assert success[last] == 1.0 and not any(v for s, v in success.items() if s < last)
    assert dist[1] > 0.2 and gap[1] == 0.1             # the hands start apart (gap: capped)
    assert dist[last] < 0.4 * dist[1]
    assert abs(gap[last]) < 0.01                       # touching at the high five
    assert all(g > 0.0 for s, g in gap.items() if s < last - 10)
    for agent in env.possible_agents:
        assert series(data, f"/plots/hand_feels_partner/{agent}")[last] == 1.0
    # the reward is shared: one line, named so, in a colour of no agent
    assert plot_views(rec)["reward"] == ["/agents/infant_0/reward"]
    assert static(data, "/agents/infant_0/reward", "SeriesLines:names") == ["reward (shared)"]
    env.close()


def test_series_colours_are_the_clothes_colours(tmp_path):
    own = (0.1, 0.8, 0.2, 1.0)
    env = free_play_v0.parallel_env(n_agents=3, touch=True, per_agent=[{}, {"clothes_rgba": own},
                                                                       {}])
    record(env, tmp_path / "c.rrd", 3, eyes=False)
    data = read_batches(tmp_path / "c.rrd")
    expect = [rgb(CLOTHES_PALETTE[0]), rgb(own), rgb(CLOTHES_PALETTE[2])]
    widths = [static(data, f"/plots/head_height/{a}", "SeriesLines:widths")[0]
              for a in env.possible_agents]
    assert widths[0] > widths[1] > widths[2] >= 2.0   # later lines drawn inside earlier ones
    for i, agent in enumerate(env.possible_agents):
        for path in (f"/plots/head_height/{agent}", f"/plots/nearest_infant/{agent}",
                     f"/agents/{agent}/action_norm", f"/agents/{agent}/touch_total"):
            colour = static(data, path, "SeriesLines:colors")
            assert len(colour) == 1
            c = int(colour[0])
            assert ((c >> 24) & 255, (c >> 16) & 255, (c >> 8) & 255) == expect[i], path
            assert static(data, path, "SeriesLines:names") == [agent]
    env.close()


def test_user_scalars_still_logged_beside_the_plots(tmp_path):
    env = free_play_v0.parallel_env(n_agents=2)
    rec = record(env, tmp_path / "s.rrd", 5, eyes=False,
                 scalars={"time/now": lambda e: float(e.world.data.time)})
    data = read_batches(tmp_path / "s.rrd")
    times = series(data, "/scalars/time/now")
    assert list(times) == list(range(6))
    assert times[5] == pytest.approx(5 * env.dt)
    assert len(series(data, "/plots/head_height/infant_0")) == 5
    assert rec.scalar_names == ["time/now"]
    env.close()


class _Custom(Task):
    name = "custom"

    def plots(self):
        return [Plot("x", "m", lambda env: (1.0, 2.0)), Plot("y", "", lambda env: 1 / 0,
                                                              per_agent=False)]


def test_a_failing_plot_names_the_task_and_the_plot(tmp_path):
    from mimo_social.core.env import MimoParallelEnv
    env = MimoParallelEnv(_Custom(2))
    obs, _ = env.reset(seed=0)
    with pytest.raises(RuntimeError, match="custom plot 'y'.*ZeroDivisionError"):
        with Recorder(env, tmp_path / "f.rrd") as rec:
            rec.log_reset(obs)                    # no plot values at reset
            # what env.step takes (the recorder checks it): motors and a face with expressions
            zero = {a: {"motors": np.zeros(env.action_space(a)["motors"].shape), "expression": 0}
                    if hasattr(env.action_space(a), "spaces")
                    else np.zeros(env.action_space(a).shape) for a in env.agents}
            rec.log_step(zero, None)
    env.close()


@pytest.mark.parametrize("kwargs, match", [
    ({"name": "a/b"}, "name='a/b'"),
    ({"name": ""}, "name=''"),
    ({"name": "x", "fn": None}, "fn=None"),
    ({"name": "x", "fn": 3}, "fn=3"),
    ({"name": "x", "fn": abs, "per_agent": False, "agents": (0,)}, "agents=\\(0,\\)"),
    ({"name": "x", "fn": abs, "agents": (-1,)}, "agents=\\(-1,\\)"),
])
def test_plot_errors_name_the_field_and_what_is_allowed(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        Plot(**kwargs)


#: plots that may stay constant in a scripted episode (the touch's distance exists only while
#: the hand touches a primitive other than the target: the scripted reach touches the target)
_STEADY = {"touch_distance"}


@pytest.mark.parametrize("entry", [e for e in catalog.CATALOG if e.controller is not None],
                         ids=lambda e: e.name)
def test_plots_follow_the_scripted_solution(entry, tmp_path):
    """The task's scripted controller as the learner, up to 600 steps: every plot's series
    changes, and a plot named success reaches 1."""
    env = entry.scripted_env()
    inner = env.unwrapped if hasattr(env, "unwrapped") else env
    ctrl = entry.controller()
    obs, _ = env.reset(seed=1000)
    ctrl.reset(inner, "infant_0", np.random.default_rng(1000))
    path = tmp_path / "run.rrd"
    with Recorder(env, path, eyes=False) as rec:
        rec.log_reset(obs)
        for _ in range(600):
            if not env.agents:
                break
            act = {"infant_0": ctrl.act(inner, "infant_0", obs["infant_0"])}
            obs, rewards, *_ = env.step(act)
            rec.log_step(act, rewards, obs)
    data = read_batches(path)
    assert set(rec.agents) == set(inner.possible_agents)       # the partner recorded too
    for plot in inner.task.plots():
        if plot.fn is None:
            assert series(data, "/agents/infant_0/reward")
            continue
        for path_ in plot_views(rec)[plot.title]:
            values = list(series(data, path_).values())
            if plot.name not in _STEADY:
                assert len(set(values)) >= 2, f"{path_}: {set(values)}"
            if plot.name == "success" and path_.endswith(("/success", "infant_0")):
                assert max(values) == 1.0, path_
    env.close()


def test_scripted_env_and_its_gym_form_record_the_partner_too(tmp_path):
    """A scripted env (ScriptedPartners lists only its learner) and its Gymnasium form record
    both agents: the partner's body, plots and skin are in the file."""
    entry = catalog.entry("high_five")
    for k, env in enumerate((entry.scripted_env(), entry.gym_env())):
        obs, _ = env.reset(seed=0)
        path = tmp_path / f"g{k}.rrd"
        with Recorder(env, path, eyes=False) as rec:
            rec.log_reset(obs)
            for _ in range(3):
                if k:
                    action = env.action_space.sample()
                    obs, reward, *_ = env.step(action)
                    rec.log_step(action, reward, obs)
                else:
                    action = {"infant_0": env.action_space("infant_0").sample()}
                    obs, reward, *_ = env.step(action)
                    rec.log_step(action, reward, obs)
        data = read_batches(path)
        assert rec.agents == ["infant_0", "infant_1"]
        assert len(series(data, "/agents/infant_0/reward")) == 3
        assert len(series(data, "/agents/infant_0/action_norm")) == 3
        assert len(series(data, "/plots/hand_feels_partner/infant_1")) == 3
        assert "/world/infant_1/skin" in data
        env.close()
