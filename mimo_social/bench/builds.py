"""Build times in fresh Python processes: the 2-infant cold start, and each configuration with
touch built with an empty skin cache (``MIMO_SOCIAL_CACHE``, the skin is computed) and again with
the cache that filled (the skin is read from disk)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from typing import Sequence

from .configs import CONFIGS, deep_copy

__all__ = ["cold_start", "fresh_build", "skin_cache_builds", "error_text"]


def error_text(e: BaseException) -> str:
    """An exception as one line of at most 400 characters."""
    text = f"{type(e).__name__}: {e}"
    return text if len(text) <= 400 else text[:397] + "..."


def cold_start(timeout: float = 300.0) -> dict:
    """Import and first 2-infant build in a fresh Python process (nothing cached)."""
    code = ("import time; t0 = time.perf_counter()\n"
            "from mimo_social.envs import free_play_v0\n"
            "t1 = time.perf_counter()\n"
            "env = free_play_v0.parallel_env(n_agents=2)\n"
            "t2 = time.perf_counter()\n"
            "print(t1 - t0, t2 - t1)\n")
    try:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=timeout, check=True)
        imp, build = (float(x) for x in out.stdout.split()[-2:])
        return {"import_s": imp, "build_2_agents_s": build}
    except (subprocess.SubprocessError, ValueError, OSError) as e:
        return {"error": f"{type(e).__name__}: {e}"}


# argv: the task name and the keyword arguments (JSON) of one configuration
_FRESH_BUILD = """\
import json, sys, time
t0 = time.perf_counter()
from mimo_social.envs.catalog import entry
t1 = time.perf_counter()
env = entry(sys.argv[1]).parallel_env(**json.loads(sys.argv[2]))
t2 = time.perf_counter()
env.reset(seed=0)
t3 = time.perf_counter()
skin = sorted({sk.from_cache or "built" for s in [env.systems.get("touch")] if s is not None
               for sk in s.skins if sk is not None})
print("JSON" + json.dumps({"import_s": t1 - t0, "build_s": t2 - t1, "first_reset_s": t3 - t2,
                          "skin": skin}))
env.close()
"""


def fresh_build(name: str, cache_dir: str | os.PathLike, timeout: float = 600.0) -> dict:
    """Build configuration ``name`` in a fresh Python process whose skin cache
    (``MIMO_SOCIAL_CACHE``) is ``cache_dir``: ``{"import_s", "build_s", "first_reset_s",
    "skin"}`` (the skin's source per agent: "built", "disk", "memory"), or ``{"error"}``."""
    cfg = CONFIGS[name]
    env = dict(os.environ, MIMO_SOCIAL_CACHE=str(cache_dir))
    argv = [sys.executable, "-c", _FRESH_BUILD, cfg.task, json.dumps(deep_copy(cfg.kwargs))]
    try:
        out = subprocess.run(argv, capture_output=True, text=True, timeout=timeout, env=env)
        lines = [ln for ln in out.stdout.splitlines() if ln.startswith("JSON")]
        if out.returncode or not lines:
            tail = (out.stderr or out.stdout).strip().splitlines()[-1:] or ["no output"]
            return {"error": f"exit {out.returncode}: {tail[0][:300]}"}
        return json.loads(lines[-1][4:])
    except (subprocess.SubprocessError, ValueError, OSError) as e:
        return {"error": error_text(e)}


def skin_cache_builds(names: Sequence[str], progress=None) -> dict:
    """For each configuration with touch: :func:`fresh_build` with a new empty skin cache
    (``cold``) and again with the cache that filled (``warm``)."""
    out = {}
    for name in names:
        if not CONFIGS[name].has_touch:
            continue
        if progress is not None:
            progress(name)
        with tempfile.TemporaryDirectory(prefix="mimo_bench_cache_") as d:
            cold = fresh_build(name, d)
            warm = fresh_build(name, d) if "error" not in cold else {"error": "cold build failed"}
        out[name] = {"cold": cold, "warm": warm}
    return out
