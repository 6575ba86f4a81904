"""``mimo-social baselines``: random, zero, scripted and trained policies on the same seeded
episodes (reach, short episodes, a tiny trained run)."""

import dataclasses
import json
import math
import typing

import numpy as np
import pytest
import torch

import mimo_social.train.baselines as bl
from mimo_social import cli
from mimo_social.envs.catalog import entry
from mimo_social.partners.base import Partner, zero_action
from mimo_social.train import TrainInputError, train
from mimo_social.train.baselines import baselines, markdown_table

torch.set_num_threads(1)

SHORT = {"max_steps": 40}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs") / "reach_ppo_s0"
    train("reach", "ppo", 128, 0, out, eval_every=128, eval_episodes=1, checkpoint_every=0,
          progress=False, env_kwargs=SHORT,
          algo_kwargs={"n_steps": 64, "batch_size": 32, "n_epochs": 1})
    return out


def test_cli_prints_the_table_with_a_row_per_policy_and_writes_markdown_and_json(
        run, tmp_path, capsys):
    md, js = tmp_path / "b.md", tmp_path / "b.json"
    assert cli.main(["baselines", "reach", "--episodes", "2", "--seed", "4", "--run", str(run),
                     "--markdown", str(md), "--json", str(js), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "reach: 2 episodes per policy, seeds 4..5" in out
    assert "| policy | episodes | success | return | length | steps to success |" in out
    for row in ("| random | 2 |", "| zero | 2 |", "| scripted (ReachController) | 2 |",
                "| reach_ppo_s0 (PPO) | 2 |"):
        assert row in out, row
    assert md.read_text() in out
    res = json.loads(js.read_text())
    assert res["seeds"] == [4, 5] and res["env_kwargs"] == SHORT   # the run's env kwargs
    assert [p["policy"] for p in res["policies"]] == ["random", "zero",
                                                     "scripted (ReachController)",
                                                     "reach_ppo_s0 (PPO)"]
    for p in res["policies"]:
        assert p["episodes"] == 2 and len(p["returns"]) == 2
        assert all(n <= SHORT["max_steps"] for n in p["lengths"])
    trained = res["policies"][3]
    assert trained["kind"] == "trained" and trained["model"].endswith("model.zip")


def test_random_and_zero_rows_are_deterministic_under_the_seed(run):
    a = baselines("reach", 2, seed=3, runs=[run], progress=False)
    b = baselines("reach", 2, seed=3, runs=[run], progress=False)
    rows = lambda res: {p["kind"]: p["returns"] for p in res["policies"]}
    assert rows(a) == rows(b)
    c = baselines("reach", 2, seed=10, env_kwargs=SHORT, progress=False)
    assert rows(c)["random"] != rows(a)["random"]
    assert [p["kind"] for p in c["policies"]][:2] == ["random", "zero"]


class _Rest(Partner):
    """A stand-in controller: the zero action, counting its resets."""

    resets: typing.ClassVar[list] = []

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        type(self).resets.append((agent, int(rng.integers(1 << 30))))

    def act(self, env, agent, observation):
        assert agent in observation or isinstance(observation, dict)
        return zero_action(env.action_space(agent))


def test_the_catalogue_controller_drives_the_agent(monkeypatch):
    reach = dataclasses.replace(entry("reach"), controller=_Rest)
    monkeypatch.setattr(bl, "entry", lambda task: reach)
    _Rest.resets.clear()
    res = baselines("reach", 2, seed=0, env_kwargs=SHORT, progress=False)
    rows = {p["kind"]: p for p in res["policies"]}
    assert rows["scripted"]["policy"] == "scripted (_Rest)"
    assert rows["scripted"]["returns"] == rows["zero"]["returns"]   # it acts through the action
    assert [a for a, _ in _Rest.resets] == ["infant_0", "infant_0"]   # reset every episode
    assert not any("controller" in n for n in res["notes"])


def test_steps_to_success_average_the_successful_episodes():
    class P:
        name, kind = "p", "random"
    # (return, length, success at the end, first success step)
    res = bl._summary(P(), [(1.0, 10, True, 10), (0.0, 50, False, 20), (2.0, 30, True, 30),
                            (0.5, 50, False, None)])
    assert res["success_rate"] == 0.5 and res["successes"] == 2
    assert res["steps_to_success_mean"] == 20.0 and res["length_mean"] == 35.0
    none = bl._summary(P(), [(1.0, 10, None, None)])
    assert math.isnan(none["success_rate"]) and math.isnan(none["steps_to_success_mean"])
    table = markdown_table({"task": "t", "episodes": 1, "seeds": [0, 0], "dt": 0.01,
                            "max_steps": 10, "env_kwargs": {}, "notes": [],
                            "policies": [res, none]})
    assert "| p | 4 | 50% (2/4) | 0.875 +- 0.74 | 35 | 20 |" in table
    assert "| p | 1 | n/a | 1 +- 0 | 10 | - |" in table


def test_wrong_inputs_say_what_is_allowed(run, tmp_path, capsys):
    with pytest.raises(TrainInputError, match="trained on 'reach', not 'catch'"):
        baselines("catch", 1, runs=[run], progress=False)
    with pytest.raises(TrainInputError, match="free_play' not allowed"):
        baselines("free_play", 1, progress=False)
    with pytest.raises(TrainInputError, match="episodes=0"):
        baselines("reach", 0, progress=False)
    assert cli.main(["baselines", "reach", "--run", str(tmp_path / "nothing")]) == 2
    assert "config.json not found" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        cli.main(["baselines", "juggle"])


def test_a_social_task_runs_its_scripted_form():
    res = baselines("high_five", 1, env_kwargs={"max_steps": 20}, progress=False)
    assert [p["policy"] for p in res["policies"]][:2] == ["random", "zero"]
    assert all(np.isfinite(p["return_mean"]) for p in res["policies"])
