"""Bad arguments to every subcommand end in one line naming the option, exit code 2, no traceback,
before anything is built; errors while running (a full disk, a bad env setting) are one line,
exit code 1 (2 for a bad value), with the traceback only under --debug / MIMO_SOCIAL_DEBUG=1."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from mimo_social import cli

# (arguments, the option the message must name); {file}: an existing file, {dir}: a folder
BAD = [
    (["demo", "--seconds", "inf"], "--seconds"),
    (["demo", "--seconds", "nan"], "--seconds"),
    (["demo", "--seconds", "0"], "--seconds"),
    (["demo", "--seconds", "abc"], "--seconds"),
    (["demo", "--seed", "-1"], "--seed"),
    (["demo", "--seed", "1.5"], "--seed"),
    (["demo", "--seed", str(2**32)], "--seed"),
    (["demo", "--scene", "moon"], "--scene"),
    (["demo", "--record", "{file}/x.rrd"], "--record"),
    (["demo", "--record", "{dir}"], "--record"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--n-envs", "0"], "--n-envs"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "0", "--out", "{dir}/r"], "--steps"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--eval-every", "0"], "--eval-every"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--eval-episodes", "0"], "--eval-episodes"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--checkpoint-every", "-1"], "--checkpoint-every"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--n-cpus", "-1"], "--n-cpus"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--seed", "-1"], "--seed"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{file}"], "--out"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{file}/r"], "--out"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--env-kwargs", '{"foo": 1}'], "--env-kwargs"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--env-kwargs", "[1, 2]"], "--env-kwargs"),
    (["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "{dir}/r",
      "--algo-kwargs", "{bad json"], "--algo-kwargs"),
    (["eval", "{dir}", "--episodes", "0"], "--episodes"),
    (["eval", "{dir}", "--frame-every", "0"], "--frame-every"),
    (["eval", "{dir}", "--seed", "-1"], "--seed"),
    (["eval", "{dir}/nothing"], "dir"),
    (["eval", "{file}"], "dir"),
    (["eval", "{dir}", "--record", "{file}/x.rrd"], "--record"),
    (["eval", "{dir}", "--video", "{dir}"], "--video"),
    (["eval", "{dir}", "--frames", "{file}"], "--frames"),
    (["eval", "{dir}", "--env-kwargs", '{"bogus": 1}'], "--env-kwargs"),
    (["compare", "--task", "reach", "--seeds", "0", "--out", "{dir}/c"], "--seeds"),
    (["compare", "--task", "reach", "--jobs", "0", "--out", "{dir}/c"], "--jobs"),
    (["compare", "--task", "reach", "--steps", "-3", "--out", "{dir}/c"], "--steps"),
    (["compare", "--task", "reach", "--out", "{file}"], "--out"),
    (["baselines", "reach", "--episodes", "0"], "--episodes"),
    (["baselines", "reach", "--seed", "-1"], "--seed"),
    (["baselines", "reach", "--env-kwargs", '{"bogus": 1}'], "--env-kwargs"),
    (["baselines", "reach", "--markdown", "{file}/x.md"], "--markdown"),
    (["baselines", "reach", "--model", "worst"], "--model"),
    (["bench", "sim", "--sim-seconds", "inf"], "--sim-seconds"),
    (["bench", "sim", "--sim-seconds", "0"], "--sim-seconds"),
    (["bench", "sim", "--seed", "-1"], "--seed"),
    (["bench", "sim", "--json", "{file}/b.json"], "--json"),
    (["bench", "sim", "--from-json", "{dir}/nothing.json"], "--from-json"),
    (["bench", "sim", "--plot", "{dir}"], "--plot"),
    (["bench", "recording", "--sim-seconds", "0"], "--sim-seconds"),
    (["bench", "recording", "--only", "7"], "--only"),
    (["bench", "recording", "--only", "0,0"], "--only"),
    (["bench", "recording", "--folder", "{file}"], "--folder"),
    (["bench", "vision", "--backends", "vulkan"], "--backends"),
    (["bench", "vision", "--rounds", "0"], "--rounds"),
    (["bench", "vision", "--sim-seconds", "nan"], "--sim-seconds"),
    (["bench", "vision", "--json", "{file}/x.json"], "--json"),
    (["bench", "development", "--sim-seconds", "0"], "--sim-seconds"),
    (["bench", "development", "--sim-seconds", "nan"], "--sim-seconds"),
    (["bench", "development", "--repeats", "x"], "--repeats"),
    (["bench", "development", "--json", "{file}/x.json"], "--json"),
    (["bench", "engines", "--workers", "0", "--out", "{dir}/e"], "--workers"),
    (["bench", "engines", "--tasks", "moon", "--out", "{dir}/e"], "--tasks"),
    (["bench", "engines", "--out", "{file}"], "--out"),
    (["bench", "soak", "--steps", "-1"], "--steps"),
    (["bench", "soak", "--vision-size", "4"], "--vision-size"),
    (["bench", "soak", "--out", "{file}"], "--out"),
    (["soak", "--keep-recordings", "{file}/r"], "--keep-recordings"),
    (["calibrate", "fmax", "--iterations", "-1"], "--iterations"),
    (["calibrate", "fmax", "--steps", "3"], "--steps"),
    (["calibrate", "vmax", "--episodes", "0"], "--episodes"),
    (["calibrate", "vmax", "--seconds", "inf"], "--seconds"),
    (["calibrate", "vmax", "--seed", "-1"], "--seed"),
    (["calibrate", "speed", "--seconds", "0"], "--seconds"),
    (["compliance", "--seconds", "0.3"], "--seconds"),
    (["compliance", "--seconds", "inf"], "--seconds"),
    (["compliance", "--out", "{file}/c.png"], "--out"),
    (["figure", "skin-hand-ball", "{file}/x.png"], "OUT.png"),
    (["docs", "--out", "{file}/tasks.md"], "--out"),
    (["docs", "--out", "{dir}"], "--out"),
    (["docs", "--config-out", "{dir}"], "--config-out"),
    (["paradigm", "mirror"], "task"),
    (["paradigm", "still_face", "--episodes", "0"], "--episodes"),
    (["paradigm", "still_face", "--seed", "-1"], "--seed"),
    (["paradigm", "still_face", "--learner", "{dir}/nothing"], "--learner"),
    (["paradigm", "still_face", "--learner", "{file}"], "--learner"),
    (["paradigm", "still_face", "--env-kwargs", '{"bogus": 1}'], "--env-kwargs"),
    (["paradigm", "still_face", "--model", "worst"], "--model"),
    (["paradigm", "still_face", "--json", "{file}/x.json"], "--json"),
    (["recipe", "reach", "--jobs", "0", "--out", "{dir}/r"], "--jobs"),
    (["recipe", "reach", "--episodes", "0", "--out", "{dir}/r"], "--episodes"),
    (["recipe", "reach", "--out", "{file}/x"], "--out"),
    (["fig8", "--out", "{dir}/f", "--seeds", "0"], "--seeds"),
    (["fig8", "--out", "{dir}/f", "--tasks", "mirror"], "--tasks"),
    (["fig8", "--out", "{dir}/f", "--sac-steps", "-5"], "--sac-steps"),
]


@pytest.fixture
def places(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("x")
    return {"file": str(afile), "dir": str(tmp_path)}


def _fill(argv, places):
    return [a.replace("{file}", places["file"]).replace("{dir}", places["dir"]) for a in argv]


@pytest.mark.parametrize("argv, option", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_a_bad_argument_is_a_one_line_usage_error_naming_the_option(argv, option, places,
                                                                    capsys, monkeypatch):
    ran = []
    commands = (*cli.SUBCOMMANDS, *cli.bench.MEASUREMENTS.values())
    for module in commands:   # nothing may run: the parser refuses first
        monkeypatch.setattr(module, "run", lambda *a, **k: ran.append(a), raising=False)
    with pytest.raises(SystemExit) as exc:
        cli.main(_fill(argv, places))
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    last = err.strip().splitlines()[-1]
    command = " ".join(argv[:2] if argv[0] == "bench" else argv[:1])
    assert last.startswith(f"mimo-social {command}") and "error: argument" in last
    assert option in last
    assert not ran


def test_eval_refuses_zero_episodes_instead_of_printing_nan(places, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["eval", places["dir"], "--episodes", "0"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--episodes" in err and "positive integer" in err and "nan" not in err.lower()


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full here")
def test_a_full_disk_is_one_line_naming_the_file(capsys):
    assert cli.main(["docs", "--out", "/dev/full"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("mimo-social docs: error: /dev/full") and "No space left" in err
    with pytest.raises(OSError):                      # --debug: the traceback
        cli.main(["--debug", "docs", "--out", "/dev/full"])


def test_a_bad_env_setting_found_while_running_is_one_line_exit_2(capsys):
    assert cli.main(["baselines", "reach", "--episodes", "1", "--no-progress",
                     "--env-kwargs", '{"max_steps": -5}']) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("mimo-social baselines: error:") and "max_steps=-5" in err


def test_an_unexpected_error_is_one_line_and_debug_shows_it(monkeypatch, capsys):
    from mimo_social.cli import docs

    def broken(args):
        raise KeyError("boom")

    monkeypatch.setattr(docs, "run", broken)
    monkeypatch.setenv("MIMO_SOCIAL_DEBUG", "0")
    assert cli.main(["docs", "--check"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error" in err and "--debug" in err
    monkeypatch.setenv("MIMO_SOCIAL_DEBUG", "1")
    with pytest.raises(KeyError):
        cli.main(["docs", "--check"])


def test_the_installed_command_exits_2_without_a_traceback():
    done = subprocess.run([sys.executable, "-m", "mimo_social.cli", "demo", "--seconds", "inf"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert "mimo-social demo: error: argument --seconds: inf not allowed" in done.stderr
