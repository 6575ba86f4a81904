"""Contact events between agents are full readable lines: who touches whom with which body parts,
the force, and the start and end of each contact (read back from the .rrd with Rerun's reader
and with recording/summary.py)."""

import re
import warnings

import mujoco
import numpy as np
import pyarrow as pa
import pytest
from rerun.chunk import RrdReader

from mimo_social.envs import high_five_v0
from mimo_social.recording import CONTACTS_PATH, Recorder, summarize
from mimo_social.recording.contacts import ContactLog

START = re.compile(r"^(infant_\d+) (\S+) touches (infant_\d+) (\S+) \((\d+\.\d\d) N\)$")
END = re.compile(r"^(infant_\d+) (\S+) stops touching (infant_\d+) (\S+) after (\d+\.\d\d) s "
                 r"\(peak (\d+\.\d\d) N\)( \((episode reset|end of recording)\))?$")


def contact_rows(path) -> list[tuple[int, float, str]]:
    """(step, sim_time in s, text) of every contact event, in time order."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chunks = RrdReader(path).stream().to_chunks()
    out = []
    for c in chunks:
        if c.entity_path != CONTACTS_PATH or c.is_static:
            continue
        b = c.to_record_batch()
        times = b.column("sim_time").cast(pa.int64()).to_pylist()
        for s, t, texts in zip(b.column("step").to_pylist(), times,
                               b.column("TextLog:text").to_pylist()):
            out += [(s, t / 1e9, text) for text in texts]
    return sorted(out, key=lambda r: r[:2])


def pair_forces(env) -> dict[tuple[str, str], float]:
    """Summed normal force per pair of body parts of two agents, with a plain loop."""
    m, d, w = env.world.model, env.world.data, env.world
    out, f = {}, np.zeros(6)
    for k in range(d.ncon):
        c = d.contact[k]
        g = (int(c.geom1), int(c.geom2))
        a = [int(w.geom_agent[x]) for x in g]
        if min(a) < 0 or a[0] == a[1] or c.dist > 0:
            continue
        ends = sorted((a[i], m.body(int(m.geom_bodyid[g[i]])).name) for i in range(2))
        key = tuple(f"infant_{x} {name.split('/', 1)[1]}" for x, name in ends)
        mujoco.mj_contactForce(m, d, k, f)
        out[key] = out.get(key, 0.0) + abs(f[0])
    return out


@pytest.fixture(scope="module")
def episodes(tmp_path_factory):
    """High five, infants 0.3 m apart, right arms swung forward until the hands meet; in the
    second of three episodes in one recording back again, so that they part; the forces between
    the parts seen here at every step."""
    env = high_five_v0.parallel_env(task_options={"end_on_touch": False, "distance": 0.3})
    path = tmp_path_factory.mktemp("contacts") / "contacts.rrd"
    forward = np.zeros(8, np.float32)
    forward[:2] = -1.0
    seen, times, resets = {}, {}, set()
    step, offset = -1, 0.0
    with Recorder(env, path) as rec:
        for ep in range(3):
            obs, _ = env.reset(seed=ep)
            rec.log_reset(obs)
            step += 1
            resets.add(step)
            seen[step] = pair_forces(env)
            times[step] = env.world.data.time + offset
            for k in range(130 if ep == 1 else 90):     # the second time back at 0.9 s
                u = -forward if k >= 90 else forward
                actions = {a: {"motors": u, "expression": 0} for a in env.agents}
                obs, rewards, *_ = env.step(actions)
                rec.log_step(actions, rewards, obs)
                step += 1
                seen[step] = pair_forces(env)
                times[step] = env.world.data.time + offset
            offset = times[step] + env.dt    # the recorder's sim_time goes on across resets
    body_names = {env.world.model.body(b).name for b in range(env.world.model.nbody)}
    env.close()
    return {"path": path, "rec": rec, "seen": seen, "bodies": body_names, "last_step": step,
            "times": times, "gap": rec._contacts.gap_s, "resets": resets}


def expected_events(seen: dict, times: dict, gap: float,
                    resets=()) -> list[tuple[int, tuple, str]]:
    """(step, pair, "start" | "end") by the rule: a pair starts when seen and not on; it ends at
    the first step ``gap`` seconds after the last step it was seen (ends at a reset or at the
    close are left out)."""
    out, last = [], {}
    for step in sorted(seen):
        if step in resets:
            last = {}
        for pair in sorted(p for p in last if p not in seen[step]):
            if times[step] - last[pair] >= gap - 1e-9:
                out.append((step, pair, "end"))
                del last[pair]
        for pair in sorted(seen[step]):
            if pair not in last:
                out.append((step, pair, "start"))
            last[pair] = times[step]
    return out


def test_every_contact_is_one_full_line_with_its_start_force_and_end(episodes):
    events = contact_rows(episodes["path"])
    seen, bodies = episodes["seen"], episodes["bodies"]
    times = episodes["times"]
    assert episodes["rec"].contact_events == len(events) >= 4
    open_at: dict[tuple[str, str], tuple[int, float]] = {}
    got = []
    for step, t, text in events:
        start, end = START.match(text), END.match(text)
        assert start or end, f"not a full contact line: {text!r}"
        m = start or end
        pair = (f"{m[1]} {m[2]}", f"{m[3]} {m[4]}")
        for agent, part in ((m[1], m[2]), (m[3], m[4])):   # real body parts, named in full
            assert f"{agent}/{part}" in bodies
        assert m[1] != m[3]
        if start:
            assert pair not in open_at and pair in seen[step]
            assert float(m[5]) == pytest.approx(seen[step][pair], abs=0.006)
            open_at[pair] = (step, t)
        else:
            first_step, t0 = open_at.pop(pair)
            stop = step if m[7] else step - 1        # ended by a reset / close: on until then
            touching = [s for s in range(first_step, stop + 1) if pair in seen[s]]
            assert float(m[5]) == pytest.approx(times[touching[-1]] - t0, abs=0.006)  # duration
            peak = max(seen[s][pair] for s in touching)
            assert float(m[6]) == pytest.approx(peak, abs=0.006) and peak > 0
            if not m[7]:   # parted: apart for the whole gap before the line
                assert all(pair not in seen[s] for s in range(touching[-1] + 1, step + 1))
        if not (end and end[7]):
            got.append((step, pair, "start" if start else "end"))
    assert not open_at                                # every start has its end
    # the events follow the gap rule exactly (ends by reset / close aside)
    assert sorted(got) == sorted(expected_events(seen, times, episodes["gap"], episodes["resets"]))
    whys = [re.search(r"\((episode reset|end of recording)\)$", x) for _, _, x in events]
    assert {w[1] if w else "parted" for w in whys} == {"parted", "episode reset",
                                                       "end of recording"}
    assert events[-1][0] == episodes["last_step"]


def test_a_touch_that_comes_back_within_the_gap_is_the_same_touch():
    """Hands resting on each other chatter (contact made and lost every few physics steps): with
    no gap each blink is an event; the gap (0.1 s) merges blinks shorter than it."""
    env = high_five_v0.parallel_env(task_options={"end_on_touch": False, "distance": 0.3})
    env.reset(seed=0)
    forward = np.zeros(8, np.float32)
    forward[:2] = -1.0
    apart = env.world.data.qpos.copy()
    for _ in range(200):
        env.step({a: {"motors": forward, "expression": 0} for a in env.agents})
        if pair_forces(env):
            break
    touching = env.world.data.qpos.copy()
    assert pair_forces(env), "the hands never met"
    # touch 5 steps, apart 3 (0.03 s), touch 5, apart 20 (0.2 s), touch 3
    pattern = [1] * 5 + [0] * 3 + [1] * 5 + [0] * 20 + [1] * 3
    runs = {}
    for gap in (0.0, 0.1):
        log = ContactLog(env.world, env.agents, gap_s=gap)
        d = env.world.data
        out = []
        for k, on in enumerate(pattern):
            d.qpos[:] = touching if on else apart
            mujoco.mj_forward(env.world.model, d)
            log.note(d, out, round(k * 0.01, 6), k)
        runs[gap] = out
    env.close()

    starts0 = sorted({s for _, s, x in runs[0.0] if START.match(x)})
    starts1 = sorted({s for _, s, x in runs[0.1] if START.match(x)})
    ends1 = sorted({s for _, s, x in runs[0.1] if END.match(x)})
    assert starts0 == [0, 8, 33]          # every blink starts again without a gap
    assert starts1 == [0, 33]             # the 0.03 s blink is merged, the 0.2 s one is not
    assert ends1 == [22]                  # 0.1 s after the last touch (step 12)
    assert all(re.search(r"after 0\.12 s", x) for _, s, x in runs[0.1] if END.match(x))


def test_summary_gives_the_same_full_lines(episodes):
    events = contact_rows(episodes["path"])
    listed = summarize(episodes["path"])["contact_events"]
    assert listed == [(s, text) for s, _, text in events]
    assert any(" touches " in text and text.endswith(" N)") for _, text in listed)
