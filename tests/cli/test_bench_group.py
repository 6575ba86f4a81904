"""``mimo-social bench MEASUREMENT`` (issue 27): the measuring commands under one group, each
with its own --help; the old names (``bench-vision``, ..., ``soak`` and ``bench --option`` for
``bench sim``) run the same function with the same arguments for one release, after one line
on stderr naming the new command; ``bench`` alone is a one-line usage error."""

from __future__ import annotations

import pytest

from mimo_social import cli
from mimo_social.cli import bench

NEW = ["sim", "floor", "vision", "recording", "development", "engines", "training", "soak",
       "ages", "gpu"]
#: old command line -> the same command under its new name (every argument has a default but
#: engines' --out)
OLD = {
    ("bench-vision", "--rounds", "2"): ("bench", "vision", "--rounds", "2"),
    ("bench-recording", "--only", "0"): ("bench", "recording", "--only", "0"),
    ("bench-development", "--repeats", "1"): ("bench", "development", "--repeats", "1"),
    ("bench-engines", "--out", "{tmp}/e", "--engines", "sb3"):
        ("bench", "engines", "--out", "{tmp}/e", "--engines", "sb3"),
    ("soak", "--steps", "10", "--out", "{tmp}/s"): ("bench", "soak", "--steps", "10", "--out",
                                                    "{tmp}/s"),
    ("bench", "--sim-seconds", "0.5", "--no-progress"):
        ("bench", "sim", "--sim-seconds", "0.5", "--no-progress"),
}


@pytest.fixture
def calls(monkeypatch):
    """Every measurement's ``run`` replaced by one that records its arguments (nothing runs)."""
    seen = []
    for name, module in bench.MEASUREMENTS.items():
        monkeypatch.setattr(module, "run", lambda args, name=name: seen.append((name, args)) or 0)
    return seen


def test_the_group_lists_the_measurements_in_order():
    assert list(bench.MEASUREMENTS) == NEW
    assert all(module.NAME == name for name, module in bench.MEASUREMENTS.items())


@pytest.mark.parametrize("name", NEW)
def test_each_measurement_has_its_help(name, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench", name, "--help"])
    assert e.value.code == 0
    out, err = capsys.readouterr()
    assert out.startswith(f"usage: mimo-social bench {name} [-h]") and err == ""


def test_the_group_help_names_each_measurement_and_the_old_names(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench", "--help"])
    assert e.value.code == 0
    out = " ".join(capsys.readouterr().out.split())
    for name, module in bench.MEASUREMENTS.items():
        assert f"{name} {' '.join(module.HELP.split())}" in out
    assert "bench-vision, bench-recording, bench-development, bench-engines and soak" in out


def test_the_old_names_are_not_listed_at_the_top(capsys):
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    out = capsys.readouterr().out
    # a command's line is indented 4 spaces; its help's continuation lines more
    listed = [line.split()[0] for line in out.splitlines()
              if line.startswith("    ") and not line.startswith("     ")]
    assert "bench" in listed and "demo" in listed
    assert not set(listed) & {*bench.OLD_NAMES, "check-viewer"}


@pytest.mark.parametrize("old, new", list(OLD.items()), ids=[" ".join(o[:2]) for o in OLD])
def test_an_old_name_runs_the_same_with_a_one_line_note(old, new, calls, tmp_path, capsys):
    fill = [a.replace("{tmp}", str(tmp_path)) for a in old]
    assert cli.main(fill) == 0
    err = capsys.readouterr().err
    word = "bench sim" if old[0] == "bench" else f"bench {bench.OLD_NAMES[old[0]]}"
    assert err.count("\n") == 1 and err.startswith(f"mimo-social: '{old[0]}' ")
    assert f"is now '{word}'" in err and "next release" in err
    assert cli.main([a.replace("{tmp}", str(tmp_path)) for a in new]) == 0
    assert capsys.readouterr().err == ""                        # the new name: no note
    (name_old, args_old), (name_new, args_new) = calls
    assert name_old == name_new == new[1]
    drop = ("command", "measurement")                           # which parser read them
    assert ({k: v for k, v in vars(args_old).items() if k not in drop}
            == {k: v for k, v in vars(args_new).items() if k not in drop})


def test_an_old_name_still_parses_without_main():
    args = cli.build_parser().parse_args(["bench-vision", "--backends", "egl", "--rounds", "2"])
    assert (args.backends, args.rounds, args.func) == ("egl", 2, bench.MEASUREMENTS["vision"].run)


def test_a_bad_argument_under_an_old_name_is_noted_then_refused(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench-vision", "--rounds", "0"])
    assert e.value.code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[0] == ("mimo-social: 'bench-vision' is now 'bench vision'; the old name goes in "
                        "the next release")
    assert lines[-1].startswith("mimo-social bench-vision: error: argument --rounds")


def test_bench_alone_is_a_one_line_usage_error_naming_the_measurements(calls, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench"])
    assert e.value.code == 2 and not calls
    err = capsys.readouterr().err
    assert err.startswith("usage: mimo-social bench ") and "Traceback" not in err
    last = err.strip().splitlines()[-1]
    assert last.startswith("mimo-social bench: error: give a measurement: sim, floor, vision, ")
    assert "mimo-social bench sim" in last


def test_an_unknown_measurement_is_a_usage_error(calls, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench", "speed"])
    assert e.value.code == 2 and not calls
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last.startswith("mimo-social bench: error: argument MEASUREMENT: invalid choice")


def test_an_error_while_running_names_the_measurement(monkeypatch, capsys):
    def broken(args):
        raise ValueError("a bad value")

    monkeypatch.setattr(bench.MEASUREMENTS["development"], "run", broken)
    assert cli.main(["bench", "development"]) == 2
    assert capsys.readouterr().err == "mimo-social bench development: error: a bad value\n"


@pytest.mark.parametrize("argv, want", [
    (["demo", "--seconds", "2"], ["demo", "--seconds", "2"]),
    (["--debug", "bench", "--json", "b.json"], ["--debug", "bench", "sim", "--json", "b.json"]),
    (["bench", "-h"], ["bench", "-h"]),
    (["bench"], ["bench"]),
    ([], []),
])
def test_old_form_rewrites_only_bench_with_an_option(argv, want, capsys):
    assert bench.old_form(argv) == want
    assert bool(capsys.readouterr().err) == (want != argv)
