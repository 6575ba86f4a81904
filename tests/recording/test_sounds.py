"""The agents' sounds in a recording: a level series and a text event per change, read back
from the .rrd, and a tab of the default layout."""

from __future__ import annotations

import numpy as np
import rerun.blueprint as rrb

from mimo_social.envs import free_play_v0
from mimo_social.expressions.voice import level_db
from mimo_social.recording import Recorder, read_batches


def _column(data, path, component):
    out = {}
    for batch in data.get(path, []):
        if component in batch.schema.names and "step" in batch.schema.names:
            for s, v in zip(batch.column("step").to_pylist(), batch.column(component).to_pylist()):
                if v is not None:
                    out[s] = v[0]
    return dict(sorted(out.items()))


def test_sounds_are_logged_as_events_and_levels(tmp_path):
    env = free_play_v0.parallel_env(n_agents=2, voice=True, audition=True)
    obs, _ = env.reset(seed=0)
    # infant_0: a cry held 3 steps, then silence; infant_1: coos at step 2
    script = [(3, 0), (3, 1), (3, 1), (0, 1), (0, 0)]
    with Recorder(env, tmp_path / "s.rrd", flush_every_s=0.02, eyes=False) as rec:
        rec.log_reset(obs)
        for a0, a1 in script:
            acts = {a: {"motors": np.zeros(44, np.float32), "expression": 0, "voice": v,
                        "loudness": [1.0]} for a, v in zip(env.agents, (a0, a1))}
            obs, rewards, *_ = env.step(acts)
            rec.log_step(acts, rewards, obs)
    data = read_batches(tmp_path / "s.rrd")
    texts = _column(data, "/agents/infant_0/voice", "TextLog:text")
    cry = level_db(3, 1.0)
    assert list(texts.values()) == [f"cry {cry:.0f} dB", "silence"]
    assert list(_column(data, "/agents/infant_1/voice", "TextLog:text").values()) == [
        f"coo {level_db(1, 1.0):.0f} dB", "silence"]
    levels = _column(data, "/plots/sound_level/infant_0", "Scalars:scalars")
    assert list(levels.values()) == [cry, cry, cry, 0.0, 0.0]
    views = [n for n in _nodes(rec.blueprint().root_container)
             if isinstance(n, rrb.TextLogView) and n.name == "sounds"]
    assert len(views) == 1


def test_no_voice_no_sound_log(tmp_path):
    env = free_play_v0.parallel_env(n_agents=1)
    obs, _ = env.reset(seed=0)
    with Recorder(env, tmp_path / "n.rrd", eyes=False) as rec:
        rec.log_reset(obs)
    assert not any("voice" in p or "sound" in p for p in read_batches(tmp_path / "n.rrd"))


def _nodes(node):
    yield node
    for child in getattr(node, "contents", None) or []:
        if not isinstance(child, str):
            yield from _nodes(child)
