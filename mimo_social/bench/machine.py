"""The machine a benchmark ran on: CPU, cores, memory, versions, GL backend, load."""

from __future__ import annotations

import os
import platform

import numpy as np

__all__ = ["machine_info", "load_average"]


def _proc_field(path: str, key: str) -> str | None:
    try:
        with open(path) as f:
            for line in f:
                if line.split(":", 1)[0].strip() == key:
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def _gl_renderer() -> str | None:
    """GL_RENDERER of the process's GL context, if the eyes have made one (none is made here)."""
    try:
        from ..render import eye_renderer

        if not eye_renderer.has_gl_context():
            return None
        eye_renderer.shared_gl_context()
        from OpenGL.GL import GL_RENDERER, GL_VERSION, glGetString

        return f"{glGetString(GL_RENDERER).decode()}; OpenGL {glGetString(GL_VERSION).decode()}"
    except Exception:  # noqa: BLE001 - informative only
        return None


def machine_info() -> dict:
    """CPU, cores, memory, versions, platform and the GL backend in force."""
    import mujoco

    mem = _proc_field("/proc/meminfo", "MemTotal")
    try:
        usable = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        usable = os.cpu_count()
    mhz = _proc_field("/proc/cpuinfo", "cpu MHz")
    return {
        "cpu": _proc_field("/proc/cpuinfo", "model name") or platform.processor() or "unknown",
        "cpu_mhz": float(mhz) if mhz else None,
        "cores": os.cpu_count(),
        "usable_cores": usable,
        "memory_gb": round(int(mem.split()[0]) / 2**20, 1) if mem else None,
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "mujoco_gl": os.environ.get("MUJOCO_GL") or "unset",
        "gl_renderer": _gl_renderer(),
        "lp_num_threads": os.environ.get("LP_NUM_THREADS"),
    }


def load_average() -> list[float] | None:
    """The 1, 5 and 15-minute load averages, or None where the platform has none."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None
