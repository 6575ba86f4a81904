"""A user scalar that fails names itself, and the recording stays whole: the rows before the
failure are in the file and the recorder closes cleanly (a failing scalar used to leave a row
half written, and the close then failed with an Arrow length error that hid the cause)."""

from __future__ import annotations

import pytest

from mimo_social.envs import free_play_v0
from mimo_social.recording import Recorder, summarize


def test_a_failing_scalar_names_itself_and_the_file_stays_readable(tmp_path):
    env = free_play_v0.parallel_env(n_agents=2)
    calls = {"n": 0}

    def flaky(_env):
        calls["n"] += 1
        if calls["n"] > 5:
            raise KeyError("gone")
        return 1.0

    path = tmp_path / "flaky.rrd"
    env.reset(seed=0)
    with pytest.raises(RuntimeError, match=r"Recorder scalar 'flaky'.*KeyError"):
        with Recorder(env, path, scalars={"flaky": flaky}) as rec:
            rec.log_reset()
            for _ in range(20):
                actions = {a: env.action_space(a).sample() for a in env.agents}
                _, rewards, *_ = env.step(actions)
                rec.log_step(actions, rewards)
    env.close()
    assert rec.rows == 5             # the reset row and four steps, every one whole
    summary = summarize(path)        # the file closed cleanly and reads back
    assert "/scalars/flaky" in summary["entities"] and summary["steps"] >= 5
