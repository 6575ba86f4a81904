"""``mimo-social paradigm`` / ``train.paradigms``: the paradigms' own summaries for the
scripted, random, zero and trained learners, side by side (tiny episodes: short phases, few
steps)."""

from __future__ import annotations

import json

import pytest

from mimo_social import cli
from mimo_social.envs.catalog import entry
from mimo_social.tasks.still_face import measures as still_face_measures
from mimo_social.tasks.still_face.controller import StillFaceInfantController
from mimo_social.train.paradigms import run_paradigm, side_by_side
from mimo_social.train.tasks import TrainInputError

SHORT_SF = {"task_options": {"phases_s": [0.5, 0.5, 0.5]}}
TINY_SF = {"task_options": {"phases_s": [0.1, 0.1, 0.1]},
           "per_agent": [{"vision": {"width": 16, "height": 16}}, {}]}


def _col(result, k):
    return result["learners"][k]["summary"]


def test_still_face_scripted_shows_the_pattern_zero_shows_nothing():
    res = run_paradigm("still_face", ["scripted", "zero", "random"], episodes=2, seed=0,
                       env_kwargs=SHORT_SF)
    scripted, zero = _col(res, 0)["phases"], _col(res, 1)["phases"]
    assert scripted["interaction"]["smile"][0] > 0.9 > 0.1 > scripted["still"]["smile"][0]
    assert scripted["reunion"]["smile"][0] > 0.9
    assert scripted["still"]["self_touch"][0] > scripted["interaction"]["self_touch"][0]
    assert all(v[0] == 0.0 for phase in zero.values() for v in phase.values())
    table = side_by_side(res)
    assert "| still: smile | 0.00 +- 0.00 | 0.00 +- 0.00 |" in table
    assert "scripted (StillFaceInfantController)" in table
    # the paradigm's effect (the task's measures.effects, on the same episodes), per learner
    scripted, zero, random = (res["learners"][k]["effects"] for k in range(3))
    assert set(scripted) == set(still_face_measures.EFFECTS)
    # measured: smile drop 1.00, recovery 1.00; gaze drop 0.52; self-touch rise 0.44
    assert scripted["smile_still_drop"][0] > 0.9 and scripted["smile_reunion_recovery"][0] > 0.9
    assert scripted["gaze_still_drop"][0] > 0.3 and scripted["self_touch_still_rise"][0] > 0.3
    assert all(v == (0.0, 0.0) for v in zero.values())
    assert all(abs(m) < 0.3 for m, _ in random.values())      # measured within 0.00-0.22
    assert "| smile_still_drop | +1.000 +- 0.000 | +0.000 +- 0.000 |" in table
    # the summary is measures.run's, on the same episodes
    env = entry("still_face").scripted_env(**SHORT_SF)
    try:
        again = still_face_measures.run(StillFaceInfantController(), 2, 0, env)
    finally:
        env.close()
    assert again == _col(res, 0)


def test_contingency_per_condition_and_imitation_per_action():
    res = run_paradigm("contingency", ["scripted", "zero"], episodes=1, seed=0,
                       env_kwargs={"max_steps": 600})
    for k in (0, 1):
        assert list(_col(res, k)) == ["live", "replay", "non_contingent"]
    assert _col(res, 0)["live"]["smiling_fraction"][0] > 0.1      # measured 0.12
    assert _col(res, 1)["live"]["smiling_fraction"][0] == 0.0
    table = side_by_side(res)
    assert "| replay: contingency_index |" in table
    scripted, zero = (res["learners"][k]["effects"] for k in (0, 1))
    assert list(scripted) == ["live_minus_replay", "live_minus_non_contingent"]
    assert scripted["live_minus_non_contingent"]["smiling_fraction"][0] > 0.05   # measured 0.10
    assert all(v == (0.0, 0.0) for d in zero.values() for v in d.values())
    assert "| live minus non contingent: smiling_fraction | +0.103 +- 0.000 |" in table

    res = run_paradigm("imitation", ["scripted", "zero"], episodes=2, seed=0)
    scripted, zero = _col(res, 0), _col(res, 1)
    assert scripted["all"]["success"] == 1.0 and zero["all"]["success"] == 0.0
    assert zero["all"]["responses"]["none"] == 2
    assert "| all: success | 100 % of 2 | 0 % of 2 |" in side_by_side(res)
    assert "imitation: no paradigm effect" in side_by_side(res)
    assert "effects" not in res["learners"][0]


def test_a_trained_run_is_a_learner_with_its_env_settings(tmp_path, capsys):
    run = tmp_path / "sf"
    assert cli.main(["train", "--task", "still_face", "--mode", "scripted", "--algo", "ppo",
                     "--steps", "64", "--out", str(run), "--algo-kwargs",
                     '{"n_steps": 32, "batch_size": 32, "n_epochs": 1}', "--env-kwargs",
                     json.dumps(TINY_SF), "--eval-episodes", "1", "--eval-every", "64",
                     "--checkpoint-every", "0", "--no-progress"]) == 0
    capsys.readouterr()
    out = tmp_path / "sf.json"
    assert cli.main(["paradigm", "still_face", "--learner", "random", str(run), "--episodes",
                     "1", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "| measure | random | sf (PPO) |" in text and "| reunion: gaze |" in text
    data = json.loads(out.read_text())
    assert data["env_kwargs"] == TINY_SF            # the run's settings, for every learner
    assert [r["spec"] for r in data["learners"]] == ["random", str(run)]
    assert "| effect | random | sf (PPO) |" in text and "| gaze_reunion_recovery |" in text
    effect = data["learners"][1]["effects"]       # the trained policy's still-face effect
    assert set(effect) == set(still_face_measures.EFFECTS)
    assert all(len(v) == 2 and -1.0 <= v[0] <= 1.0 for v in effect.values())
    # sampled actions (as in training), seeded per episode: the same twice
    a, b = (run_paradigm("still_face", [str(run)], episodes=2, seed=3, deterministic=False)
            for _ in range(2))
    assert a["learners"][0]["learner"] == "sf (PPO, sampled)"
    assert a["learners"] == b["learners"]
    # eye size differs from the run's: refused, naming both shapes
    with pytest.raises(TrainInputError, match="observes"):
        run_paradigm("still_face", [str(run)], episodes=1, env_kwargs=SHORT_SF)
    # a run of another task: exit code 2, one line naming the learner and both tasks
    assert cli.main(["paradigm", "imitation", "--learner", str(run)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "'still_face', not 'imitation'" in err


def test_bad_library_arguments_are_refused():
    with pytest.raises(TrainInputError, match="allowed: contingency, still_face, imitation"):
        run_paradigm("mirror", ["zero"])
    with pytest.raises(TrainInputError, match="positive integer"):
        run_paradigm("still_face", ["zero"], episodes=0)
    with pytest.raises(FileNotFoundError, match="allowed: scripted, random, zero"):
        run_paradigm("still_face", ["nowhere"])
