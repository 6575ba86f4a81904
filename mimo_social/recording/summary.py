"""What a Rerun recording of mimo_social holds, read back from the ``.rrd`` file.

:func:`summarize` reads the file with Rerun's own reader (``rerun.chunk.RrdReader``) and returns
the agents, the simulated duration, the number of steps and of pose rows, the entity paths grouped
by agent and kind, the eye images and skin points per agent, the expression log rows and the
contact events between agents; :func:`format_summary` puts that as text for people. Files of a
run that was killed (no footer, perhaps a last frame cut off mid-write: :mod:`.torn`) are read
up to their last whole flush.
"""

from __future__ import annotations

import re
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

from .columns import SIM_TIME, STEP
from .contacts import CONTACTS_PATH
from .torn import readable_copy

__all__ = ["format_summary", "read_batches", "summarize"]

_TRANSLATION = "Transform3D:translation"
_AGENT_GROUPS = ("world", "agents")


def _read_chunks(path: Path):
    """(stores, chunks, complete, torn bytes): a file killed mid-write is read up to its last
    whole frame (:mod:`.torn`)."""
    from rerun.chunk import RrdReader

    with readable_copy(path) as (readable, torn), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")   # a file of a crashed run has no footer: say so
        reader = RrdReader(readable)
        stores = reader.recordings()
        chunks = reader.stream().to_chunks()
    complete = torn == 0 and not any("footer" in str(w.message) for w in caught)
    return stores, chunks, complete, torn


def read_batches(path: str | Path) -> dict:
    """Entity path -> the Arrow record batches of its chunks (static ones included), read with
    Rerun's own reader: the raw rows, for checks and analyses beyond :func:`summarize`. A file
    of a run still open or killed (no footer, a torn last frame) reads up to its last whole
    flush."""
    _, chunks, _, _ = _read_chunks(Path(path))
    out: dict = defaultdict(list)
    for chunk in chunks:
        out[chunk.entity_path].append(chunk.to_record_batch())
    return dict(out)


def _non_null(batch, name: str) -> np.ndarray:
    column = batch.column(name)
    return ~np.asarray(column.is_null().to_numpy(zero_copy_only=False), dtype=bool)


def summarize(path: str | Path) -> dict:
    """What a recording holds (see the module docstring); read with ``RrdReader``."""
    path = Path(path)
    stores, chunks, complete, torn = _read_chunks(path)
    entities: set[str] = set()
    steps: set[int] = set()
    t_min, t_max = None, None
    pose_rows: dict[str, int] = defaultdict(int)       # body entity -> rows with a translation
    eye_images: dict[str, dict[str, int]] = defaultdict(lambda: {"left": 0, "right": 0})
    skin_rows: dict[str, int] = defaultdict(int)       # agent -> rows with at least one point
    skin_points: dict[str, int] = defaultdict(int)
    contacts: list[tuple[int, str]] = []
    expression_changes: dict[str, int] = defaultdict(int)
    for chunk in chunks:
        e = chunk.entity_path
        if e.startswith("/__"):                         # Rerun's own properties
            continue
        entities.add(e)
        if chunk.is_static:
            continue
        batch = chunk.to_record_batch()
        names = batch.schema.names
        if STEP in names:
            steps.update(batch.column(STEP).to_numpy(zero_copy_only=False).tolist())
        if SIM_TIME in names:
            t = batch.column(SIM_TIME).cast("int64").to_numpy(zero_copy_only=False)
            if len(t):
                t_min = int(t.min()) if t_min is None else min(t_min, int(t.min()))
                t_max = int(t.max()) if t_max is None else max(t_max, int(t.max()))
        parts = e.strip("/").split("/")
        if _TRANSLATION in names:
            pose_rows[e] += int(_non_null(batch, _TRANSLATION).sum())
        if len(parts) == 4 and parts[0] == "agents" and parts[2] == "eyes":
            for name in ("EncodedImage:blob", "Image:buffer"):
                if name in names and parts[3] in ("left", "right"):
                    eye_images[parts[1]][parts[3]] += int(_non_null(batch, name).sum())
        if len(parts) == 3 and parts[0] == "world" and parts[2] == "skin" \
                and "Points3D:positions" in names:
            lengths = batch.column("Points3D:positions").value_lengths().fill_null(0)
            lengths = lengths.to_numpy(zero_copy_only=False)
            skin_rows[parts[1]] += int(np.count_nonzero(lengths))
            skin_points[parts[1]] += int(lengths.sum())
        if e == CONTACTS_PATH and "TextLog:text" in names:
            step_col = (batch.column(STEP).to_pylist() if STEP in names
                        else [None] * batch.num_rows)
            for s, texts in zip(step_col, batch.column("TextLog:text").to_pylist()):
                for text in texts or []:
                    contacts.append((s, text))
        if len(parts) == 3 and parts[0] == "agents" and parts[2] == "expression" \
                and "TextLog:text" in names:
            expression_changes[parts[1]] += int(_non_null(batch, "TextLog:text").sum())
    agents = sorted({p.strip("/").split("/")[1] for p in entities
                     if p.strip("/").split("/")[0] in _AGENT_GROUPS
                     and len(p.strip("/").split("/")) > 1
                     and p.strip("/").split("/")[1] not in ("scene", "props")},
                    key=_agent_order)
    groups: dict[str, list[str]] = defaultdict(list)
    for p in sorted(entities, key=_natural):
        parts = p.strip("/").split("/")
        depth = 2 if parts[0] in _AGENT_GROUPS + ("events", "scalars") and len(parts) > 1 else 1
        key = "/" + "/".join(parts[:depth])
        rest = "/".join(parts[depth:])
        groups[key].append(rest)
    rows_per_body = sorted(set(pose_rows.values()))
    contacts.sort(key=lambda c: (-1 if c[0] is None else c[0]))
    return {
        "path": str(path), "bytes": path.stat().st_size, "complete": complete,
        "torn_bytes": torn,
        "recordings": [{"application_id": s.application_id, "recording_id": s.recording_id}
                       for s in stores],
        "agents": agents,
        "sim_time_s": (t_min / 1e9, t_max / 1e9) if t_min is not None else None,
        "duration_s": (t_max - t_min) / 1e9 if t_min is not None else 0.0,
        "steps": len(steps),
        "step_range": (min(steps), max(steps)) if steps else None,
        "pose_bodies": len(pose_rows),
        "pose_rows": max(pose_rows.values()) if pose_rows else 0,
        "pose_rows_per_body": rows_per_body,
        "entities": sorted(entities, key=_natural),
        "entity_groups": dict(groups),
        "eye_images": {a: dict(eye_images[a]) for a in agents if a in eye_images},
        "skin_rows": {a: skin_rows.get(a, 0) for a in agents},
        "skin_points": {a: skin_points.get(a, 0) for a in agents},
        "expression_changes": {a: expression_changes.get(a, 0) for a in agents},
        "contact_events": contacts,
    }


def _natural(s: str):
    """Sort key that puts infant_2 before infant_10."""
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", s)]


def _agent_order(name: str):
    """Sort key of agent names: infants (``infant_<i>``) before adult caregivers
    (``caregiver_<i>``), each by number, as the tasks place them."""
    kinds = ("infant_", "caregiver_")
    kind = next((k for k, p in enumerate(kinds) if name.startswith(p)), len(kinds))
    return (kind, _natural(name))


def format_summary(s: dict, max_contacts: int = 10) -> str:
    """The summary as text, for people."""
    lines = [f"{s['path']} ({s['bytes'] / 1e6:.2f} MB)"]
    if not s["complete"]:
        lines.append("complete: no (no footer: the recording was not closed, e.g. the run was "
                     "killed; everything flushed before is here)")
    if s.get("torn_bytes"):
        lines.append(f"torn: the last {s['torn_bytes']} bytes are a frame cut off mid-write "
                     f"(left out; `mimo-social replay FILE --salvage` writes the whole part)")
    for r in s["recordings"]:
        lines.append(f"recording: {r['application_id']} ({r['recording_id']})")
    lines.append(f"agents: {len(s['agents'])} ({', '.join(s['agents']) or 'none'})")
    if s["sim_time_s"] is not None:
        t0, t1 = s["sim_time_s"]
        lines.append(f"simulated duration: {s['duration_s']:.3f} s "
                     f"(sim_time {t0:.3f} .. {t1:.3f} s)")
    else:
        lines.append("simulated duration: 0 s (no timed data)")
    if s["step_range"] is not None:
        lines.append(f"steps: {s['steps']} (step {s['step_range'][0]} .. {s['step_range'][1]})")
    else:
        lines.append("steps: 0")
    per_body = s["pose_rows_per_body"]
    same = "every body" if len(per_body) <= 1 else f"per body {per_body[0]} .. {per_body[-1]}"
    lines.append(f"pose rows: {s['pose_rows']} ({same}; {s['pose_bodies']} bodies)")
    eyes = {a: n for a, n in s["eye_images"].items() if n["left"] or n["right"]}
    lines.append("eye images: " + (", ".join(f"{a} {n['left']} left + {n['right']} right"
                                             for a, n in eyes.items()) if eyes else "none"))
    skin = {a: n for a, n in s["skin_rows"].items() if n}
    lines.append("skin points: " + (", ".join(f"{a} {n} rows, {s['skin_points'][a]} points"
                                              for a, n in skin.items()) if skin else "none"))
    changes = s["expression_changes"]
    if any(changes.values()):
        lines.append("expression log rows: " + ", ".join(f"{a} {n}" for a, n in changes.items()))
    contacts = s["contact_events"]
    lines.append(f"contact events between agents: {len(contacts)}")
    for step, text in contacts[:max_contacts]:
        lines.append(f"  step {step}: {text}")
    if len(contacts) > max_contacts:
        lines.append(f"  ... {len(contacts) - max_contacts} more")
    lines.append(f"entities: {len(s['entities'])}")
    for group, members in s["entity_groups"].items():
        named = [m for m in members if m]
        if not named:
            lines.append(f"  {group}")
            continue
        tops = sorted({m.split("/")[0] for m in named}, key=_natural)
        shown = ", ".join(tops[:30]) + (f", ... ({len(tops) - 30} more)" if len(tops) > 30 else "")
        lines.append(f"  {group}/ ({len(members)}): {shown}")
    return "\n".join(lines)
