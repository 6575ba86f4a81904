"""``mimo-social compare``: the Fig. 8 figure (steps and wall time), per-algorithm budgets and
keyword arguments, and ``--jobs`` (runs in parallel processes, the same files as one by one)."""

import csv
import json

import matplotlib.collections
import matplotlib.figure
import numpy as np
import pytest
import torch

from mimo_social import cli
from mimo_social.train import TrainInputError, compare, plot_compare, read_progress, write_progress
from mimo_social.train.comparison import parse_steps_per_algo

torch.set_num_threads(1)

TINY = dict(eval_every=64, eval_episodes=1, checkpoint_every=0, progress=False,
            env_kwargs={"max_steps": 30})
TINY_PPO = {"n_steps": 64, "batch_size": 32, "n_epochs": 1}
TINY_SAC = {"learning_starts": 32, "batch_size": 16}


def _fake_run(out, algo, seed, steps, wall_per_step, success=True):
    """A run directory with a config.json and a progress.csv, no training."""
    run = out / f"{algo}_seed{seed}"
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps({"task": "reach", "algo": algo, "seed": seed}))
    rows = [{"timesteps": t, "wall_time_s": float(t * wall_per_step),
             "eval_return_mean": float(np.log1p(t) + seed), "eval_return_std": 0.1,
             "eval_length_mean": 30.0,
             "eval_success_rate": float(min(1.0, t / steps)) if success else float("nan"),
             "train_return_mean": 0.0, "train_episodes": 1}
            for t in range(steps // 4, steps + 1, steps // 4)]
    write_progress(run / "progress.csv", rows)


@pytest.fixture
def figures(monkeypatch):
    """The figures plot_compare saves (their axes are read after the call)."""
    saved = []
    original = matplotlib.figure.Figure.savefig

    def savefig(self, *args, **kwargs):
        saved.append(self)
        return original(self, *args, **kwargs)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", savefig)
    return saved


def test_the_figure_has_steps_and_wall_time_side_by_side(tmp_path, figures):
    for seed in (0, 1):
        _fake_run(tmp_path, "ppo", seed, 400, 0.01)
        _fake_run(tmp_path, "sac", seed, 200, 0.2)          # fewer steps, slower per step
    png = plot_compare(tmp_path)
    assert png.read_bytes()[:4] == b"\x89PNG"
    (fig,) = figures
    axes = np.array(fig.axes).reshape(2, 2)                  # return, success x steps, wall
    assert [ax.get_xlabel() for ax in axes[0]] == ["environment steps", "wall time (s)"]
    assert [ax.get_ylabel() for ax in axes[:, 0]] == ["episode return", "success (%)"]
    for ax in axes.ravel():
        colors = {matplotlib.colors.to_hex(line.get_color()) for line in ax.get_lines()}
        assert colors == {matplotlib.colors.to_hex("tab:red"), matplotlib.colors.to_hex("tab:blue")}
        assert len(ax.get_lines()) == 2 * (2 + 1)          # a thin line per seed and the mean
    # the wall-time panel ends where the slowest run ends (SAC: 200 steps x 0.2 s)
    wall = axes[0, 1]
    sac_x = max(line.get_xdata().max() for line in wall.get_lines()
                if matplotlib.colors.to_hex(line.get_color()) == matplotlib.colors.to_hex("tab:blue"))
    assert sac_x == pytest.approx(40.0)
    with open(tmp_path / "compare.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {(r["algo"], r["seed"]) for r in rows} == {(a, s) for a in ("ppo", "sac")
                                                      for s in ("0", "1")}
    assert "wall_time_s" in rows[0]


def _drawn_points(ax, color):
    """The (x, y) points of ``color`` a reader sees: those of lines of two points or more, and
    single points that carry a marker."""
    seen = set()
    for line in ax.get_lines():
        if matplotlib.colors.to_hex(line.get_color()) != matplotlib.colors.to_hex(color):
            continue
        xy = [(float(x), float(y)) for x, y in zip(line.get_xdata(), line.get_ydata())
              if np.isfinite(x) and np.isfinite(y)]
        if len(xy) >= 2 or line.get_marker() not in ("None", "", " ", None):
            seen.update((round(x, 6), round(y, 6)) for x, y in xy)
    return seen


def test_runs_evaluated_once_are_drawn_in_compare_png(tmp_path, figures):
    """SAC's short runs have one evaluation each (at different wall times): each is a point on
    both panels, the mean a point with its min-max bar, not only a name in the legend."""
    _fake_run(tmp_path, "ppo", 0, 400, 0.01)
    for seed, wall in ((0, 456.9), (1, 578.3)):
        run = tmp_path / f"sac_seed{seed}"
        run.mkdir()
        (run / "config.json").write_text(json.dumps({"task": "reach", "algo": "sac",
                                                     "seed": seed}))
        write_progress(run / "progress.csv", [
            {"timesteps": 5000, "wall_time_s": wall, "eval_return_mean": -50.0 - 30 * seed,
             "eval_return_std": 0.0, "eval_length_mean": 88.0, "eval_success_rate": 0.0,
             "eval_return_mean_stochastic": -70.0, "train_return_mean": -65.0,
             "train_episodes": 70}])
    plot_compare(tmp_path)
    (fig,) = figures
    steps, wall = fig.axes[0], fig.axes[1]               # the return over steps and wall time
    assert "SAC (2 seeds), mean action" in [t.get_text() for t in steps.get_legend().texts]
    assert {(5000.0, -50.0), (5000.0, -80.0), (5000.0, -65.0)} <= _drawn_points(steps,
                                                                                 "tab:blue")
    minutes = {(round(w / 60, 6), r) for w, r in ((456.9, -50.0), (578.3, -80.0))}
    assert minutes <= _drawn_points(wall, "tab:blue")
    bars = [c for c in steps.collections if isinstance(c, matplotlib.collections.LineCollection)
            and matplotlib.colors.to_hex(c.get_edgecolor()[0]) == matplotlib.colors.to_hex(
                "tab:blue")]
    assert [[tuple(map(float, p)) for p in seg] for seg in bars[0].get_segments()] == [
        [(5000.0, -80.0), (5000.0, -50.0)]]
    with open(tmp_path / "compare.csv", newline="") as f:
        assert sum(r["algo"] == "sac" for r in csv.DictReader(f)) == 2


def test_without_success_or_wall_times_the_figure_has_fewer_panels(tmp_path, figures):
    _fake_run(tmp_path, "ppo", 0, 400, 1.0, success=False)
    plot_compare(tmp_path)
    axes = figures[-1].axes
    assert [ax.get_xlabel() for ax in axes] == ["environment steps", "wall time (min)"]
    p = read_progress(tmp_path / "ppo_seed0" / "progress.csv")
    p["wall_time_s"][:] = np.nan
    rows = [{k: float(v[i]) for k, v in p.items()} for i in range(len(p["timesteps"]))]
    write_progress(tmp_path / "ppo_seed0" / "progress.csv", rows)
    plot_compare(tmp_path)
    assert [ax.get_xlabel() for ax in figures[-1].axes] == ["environment steps"]


def test_each_algorithm_gets_its_own_steps_and_keyword_arguments(tmp_path, capsys):
    compare("reach", ["ppo", "sac"], seeds=1, steps={"ppo": 128, "sac": 64}, out=tmp_path,
            algo_kwargs={"ppo": TINY_PPO, "sac": TINY_SAC}, **TINY)
    configs = {a: json.loads((tmp_path / f"{a}_seed0" / "config.json").read_text())
               for a in ("ppo", "sac")}
    assert configs["ppo"]["steps"] == 128 and configs["sac"]["steps"] == 64
    # the given keys over the shipped hyperparameters, each with its provenance
    for a, given in (("ppo", TINY_PPO), ("sac", TINY_SAC)):
        used = configs[a]["algo_kwargs"]
        assert {k: used[k] for k in given} == given
        assert all(configs[a]["algo_kwargs_provenance"][k] == "command line" for k in given)
        # (or set for n_envs > 1 envs, e.g. SAC's gradient_steps -1: the provenance says so)
        assert all(v.startswith("shipped:") or "for n_envs=" in v for k, v in
                   configs[a]["algo_kwargs_provenance"].items() if k not in given
                   and not k.startswith("policy_kwargs"))
    assert configs["sac"]["algo_kwargs"]["buffer_size"] == 64     # capped at the run's steps
    assert read_progress(tmp_path / "sac_seed0" / "progress.csv")["timesteps"][-1] == 64
    # the command line: --steps-per-algo over --steps, per-algorithm --algo-kwargs
    (tmp_path / "compare.png").unlink()
    assert cli.main(["compare", "--task", "reach", "--algos", "ppo,sac", "--steps-per-algo",
                     "ppo=128,sac=64", "--out", str(tmp_path), "--plot-only"]) == 0
    assert (tmp_path / "compare.png").exists()


def test_bad_budgets_and_keyword_arguments_say_what_is_allowed(tmp_path, capsys):
    assert parse_steps_per_algo("ppo=100000, sac=20000") == {"ppo": 100000, "sac": 20000}
    for bad in ("ppo", "ppo=x", "a2c=5", "sac=0", ","):
        with pytest.raises(TrainInputError, match="e.g. ppo=100000,sac=20000"):
            parse_steps_per_algo(bad)
    with pytest.raises(TrainInputError, match="no value for sac"):
        compare("reach", ["ppo", "sac"], steps={"ppo": 10}, out=tmp_path)
    with pytest.raises(TrainInputError, match="one object per algorithm"):
        compare("reach", ["ppo"], steps=10, out=tmp_path,
                algo_kwargs={"ppo": TINY_PPO, "batch_size": 8})
    with pytest.raises(TrainInputError, match="jobs=0"):
        compare("reach", ["ppo"], steps=10, out=tmp_path, jobs=0)
    base = ["compare", "--task", "reach", "--algos", "ppo,sac", "--out", str(tmp_path)]
    assert cli.main([*base, "--steps-per-algo", "ppo=100"]) == 2
    assert "no step budget for sac" in capsys.readouterr().err
    assert cli.main([*base, "--steps", "10", "--steps-per-algo", "ppo=1,sac=x"]) == 2
    assert cli.main(["compare", "--task", "reach", "--algos", "ppo", "--steps-per-algo",
                     "sac=10", "--out", str(tmp_path)]) == 2
    assert "does not compare" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())                      # nothing written


def _files(run):
    """A run's files, with progress.csv less its wall times."""
    out = {}
    for f in sorted(run.rglob("*")):
        if f.suffix in (".csv", ".json"):
            text = f.read_text()
            if f.name == "progress.csv":
                p = read_progress(f)
                p.pop("wall_time_s")
                text = {k: list(v) for k, v in p.items()}
            elif f.name == "config.json":
                text = json.loads(text)
                text.pop("wall_time_s")
            out[str(f.relative_to(run))] = text
    return out


def _params(run):
    from stable_baselines3 import PPO
    return PPO.load(str(run / "model.zip"), device="cpu").policy.state_dict()


@pytest.mark.slow   # 14-25 s on 2 shared cores (two spawned processes start torch)
def test_jobs_run_in_parallel_processes_and_write_the_same_runs(tmp_path):
    kw = dict(algo_kwargs=TINY_PPO, **TINY)
    compare("reach", ["ppo"], seeds=2, steps=128, out=tmp_path / "one", jobs=1, **kw)
    compare("reach", ["ppo"], seeds=2, steps=128, out=tmp_path / "two", jobs=2, **kw)
    names = lambda d: sorted(str(p.relative_to(d)) for p in d.rglob("*"))
    assert names(tmp_path / "one") == names(tmp_path / "two")
    for seed in (0, 1):
        one, two = tmp_path / "one" / f"ppo_seed{seed}", tmp_path / "two" / f"ppo_seed{seed}"
        assert _files(one) == _files(two)
        a, b = _params(one), _params(two)
        assert all(torch.equal(a[k], b[k]) for k in a)
