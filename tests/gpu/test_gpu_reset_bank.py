"""Resets from a bank of kept starts (``BatchedTaskEnv(reset_bank=K)``), on Warp's CPU device:
while fewer than K episodes have started the worlds' episodes are those of a CPU reset per
finished world (every observation, the drawn target included), after that the starts repeat
with period K; a new seed makes the bank anew; bad values and the bench's option."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social import cli  # noqa: E402
from mimo_social.envs import selfbody_v0  # noqa: E402
from mimo_social.gpu import BatchedTaskEnv, GymVectorEnv  # noqa: E402

N = 2


def _tenv(bank, seed=3):
    # two-step episodes: every other step resets every world; the target drawn per episode
    return BatchedTaskEnv(selfbody_v0.parallel_env(max_steps=2), N, device="cpu", seed=seed,
                          reset_bank=bank)


def _run(tenv, steps):
    """Zero actions for ``steps`` steps: per step the observations (numpy) and the seeds."""
    obs, _ = tenv.reset()
    zero = {"infant_0": np.zeros((N, tenv.n_controls("infant_0")), np.float32)}
    out = [({k: v.numpy().copy() for k, v in obs["infant_0"].items()},
            [tenv.seed_of(w) for w in range(N)])]
    for _ in range(steps):
        obs, *_ = tenv.step(zero)
        out.append(({k: v.numpy().copy() for k, v in obs["infant_0"].items()},
                    [tenv.seed_of(w) for w in range(N)]))
    return out


@pytest.fixture(scope="module")
def host():
    return _run(_tenv(None), 6)


def test_a_bank_as_large_as_the_episodes_started_gives_the_host_resets(host):
    """8 kept starts, 2 worlds, 4 episodes each (8 in all): every observation of every step
    equals the host resets' (each episode's state and target from its seed's CPU reset)."""
    banked = _run(_tenv(8), 6)
    targets = set()
    for (o_h, s_h), (o_b, s_b) in zip(host, banked):
        assert s_h == s_b
        for k in o_h:
            np.testing.assert_array_equal(o_b[k], o_h[k], err_msg=k)
        targets.update(np.argmax(o_h["target"], axis=1).tolist())
    assert len(targets) > 2          # the episodes draw different targets: the rows differ


def test_after_k_episodes_the_kept_starts_repeat():
    """3 kept starts: the seeds cycle through seed .. seed + 2 (episode n of all: n mod 3) and
    each episode's first observation is that of the kept start it names."""
    tenv = _tenv(3)
    steps = _run(tenv, 6)
    firsts = steps[::2]                    # episodes start at steps 0, 2, 4, 6
    seeds = [s for _, s in firsts]
    assert seeds == [[3, 4], [5, 3], [4, 5], [3, 4]]
    by_seed = {}
    for o, s in firsts:
        for w in range(N):
            row = np.concatenate([o[k][w] for k in sorted(o)])
            if s[w] in by_seed:
                np.testing.assert_array_equal(row, by_seed[s[w]])
            by_seed[s[w]] = row
    assert set(by_seed) == {3, 4, 5}
    assert not np.array_equal(by_seed[3], by_seed[4])


def test_a_new_seed_makes_the_bank_anew(host):
    """reset(seed=) keeps the bank's size and makes its starts from the new seed."""
    tenv = _tenv(4, seed=50)
    obs, _ = tenv.reset(seed=3)
    assert tenv.bank.first_seed == 3 and [tenv.seed_of(w) for w in range(N)] == [3, 4]
    for k, v in obs["infant_0"].items():
        np.testing.assert_array_equal(v.numpy(), host[0][0][k], err_msg=k)


@pytest.mark.parametrize("bad", [0, -2, 2.5, "8", True])
def test_a_bad_bank_size_is_refused_by_name(bad):
    with pytest.raises((ValueError, TypeError), match="reset_bank"):
        _tenv(bad)


def test_the_vector_env_passes_the_bank_on():
    v = GymVectorEnv(selfbody_v0.parallel_env(max_steps=2), N, device="cpu", seed=7,
                     reset_bank=5)
    assert v.tenv.bank.size == 5 and v.tenv.bank.first_seed == 7


def test_the_bench_times_a_reset_from_the_bank(tmp_path, capsys):
    path = tmp_path / "gpu.json"
    argv = ["bench", "gpu", "--worlds", "2", "--steps", "1", "--warmup", "0", "--device",
            "cpu", "--with-task", "--reset-bank", "4", "--json", str(path)]
    assert cli.main(argv) == 0
    printed = capsys.readouterr().out
    assert "a bank of 4 starts" in printed and "reset ms/world" in printed
    row = json.loads(path.read_text())["results"][0]
    assert row["reset_bank"] == 4 and row["reset_ms_per_world"] > 0.0
    alone = [a for a in argv[:-2] if a != "--with-task"]
    assert cli.main(alone) == 2                                        # without --with-task
    assert "needs --with-task" in capsys.readouterr().err
