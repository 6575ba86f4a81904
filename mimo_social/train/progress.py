"""What a run writes as it goes: ``progress.csv`` (one row per evaluation), ``config.json``.

``progress.csv`` has :data:`PROGRESS_FIELDS` and, for a multi-agent run, the per-agent columns
``eval_return_mean_<agent>`` and ``eval_success_rate_<agent>`` (the summary columns average them)
and the same of the stochastic policy, ``eval_return_mean_<agent>_stochastic`` and
``eval_success_rate_<agent>_stochastic``. The ``eval_*`` columns are the deterministic policy's
(the mean action), the ``eval_*_stochastic`` ones the sampled policy's, on the same episodes;
``eval_episodes`` is the episodes of each, ``eval_steps`` the env steps evaluated so far (both
policies, this row included). Runs written before the stochastic columns lack them.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Mapping

import numpy as np

__all__ = ["PROGRESS_FIELDS", "read_progress", "write_progress", "progress_agents",
           "agent_columns", "write_config", "json_default", "STOCHASTIC"]

PROGRESS_FIELDS = ("timesteps", "wall_time_s", "eval_return_mean", "eval_return_std",
                   "eval_length_mean", "eval_success_rate", "eval_return_mean_stochastic",
                   "eval_return_std_stochastic", "eval_length_mean_stochastic",
                   "eval_success_rate_stochastic", "eval_episodes", "eval_steps",
                   "train_return_mean", "train_episodes")

#: suffix of the stochastic policy's columns
STOCHASTIC = "_stochastic"


def json_default(value):
    """config.json: a class (e.g. a features extractor in policy_kwargs) by its dotted name."""
    if isinstance(value, type):
        return f"{value.__module__}.{value.__qualname__}"
    raise TypeError(f"not JSON serialisable: {value!r}")


def write_config(out: Path, config: Mapping) -> None:
    """``out/config.json`` (what ``eval`` reads)."""
    (Path(out) / "config.json").write_text(json.dumps(config, indent=2, default=json_default))


def write_progress(path: Path, rows) -> None:
    """``progress.csv``: :data:`PROGRESS_FIELDS` then any further columns of the rows (the
    per-agent ``eval_return_mean_<agent>`` / ``eval_success_rate_<agent>`` of multi-agent runs)."""
    fields = list(PROGRESS_FIELDS)
    if rows and "eval_steps" not in rows[0]:   # (rows of an older layout)
        fields = [f for f in fields if f in rows[0]]
    for row in rows[:1]:
        fields += [k for k in row if k not in fields]
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for row in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})


def read_progress(path: Path) -> dict[str, np.ndarray]:
    """Every column of a ``progress.csv`` as a float array (empty cells: NaN)."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        fields = list(reader.fieldnames or PROGRESS_FIELDS)
    return {k: np.array([float(r[k]) if r.get(k) not in ("", None) else np.nan for r in rows])
            for k in fields}


def progress_agents(p: Mapping[str, np.ndarray]) -> list[str]:
    """The agents with per-agent columns in a progress table (none for one-agent runs)."""
    prefix = "eval_return_mean_"
    return [k[len(prefix):] for k in p if k.startswith(prefix) and not k.endswith(STOCHASTIC)]


def agent_columns(res: dict, suffix: str = "") -> dict:
    """``eval_return_mean_<agent><suffix>`` and ``eval_success_rate_<agent><suffix>`` of an
    evaluation (``suffix="_stochastic"``: the sampled policy's)."""
    row = {}
    for a, r in res["agents"].items():
        row[f"eval_return_mean_{a}{suffix}"] = r["return_mean"]
        row[f"eval_success_rate_{a}{suffix}"] = r["success_rate"]
    return row

