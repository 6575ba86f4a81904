"""The command line of issue 32: ``train --growth`` and ``eval --ages`` refuse bad values in one
line naming the value and what is allowed, before anything runs."""

from __future__ import annotations

import pytest

from mimo_social import cli


@pytest.mark.parametrize("spec, words", [
    ("forward:12-1", "the range written low-high"),
    ("grow:1-12", "kind 'grow' not allowed; allowed: forward, inverse, stochastic"),
    ("forward:1-34", "'34' not allowed; allowed: an age in months from 0 to 33"),
    ("stochastic:1-12:500", "a step span is for forward and inverse"),
])
def test_train_refuses_a_bad_growth_spec_naming_it(spec, words, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out",
                  str(tmp_path / "r"), "--growth", spec])
    assert exc.value.code == 2
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last.startswith("mimo-social train") and "--growth" in last and words in last
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("ages, words", [
    ("1,3,99", "--ages: '99' not allowed; allowed: ages in months from 0 to 33"),
    ("-1", "--ages: '-1' not allowed"),
    ("1,,x", "--ages: 'x' not allowed"),
    ("6,6", "--ages: '6' given twice; allowed: each age once"),
    (",", "--ages=[]; allowed: one or more ages in months 0-33"),
])
def test_eval_refuses_bad_ages_in_one_line_before_loading_anything(ages, words, tmp_path,
                                                                   capsys):
    assert cli.main(["eval", str(tmp_path), "--ages", ages]) == 2   # (no run there: not read)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("mimo-social eval: error: ") and words in err


def test_eval_ages_needs_a_run(tmp_path, capsys):
    assert cli.main(["eval", str(tmp_path), "--ages", "6"]) == 2
    assert "config.json not found" in capsys.readouterr().err
