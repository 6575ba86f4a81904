"""Argument types of the ``mimo-social`` subcommands: each checks its value when the command line
is read, so a bad value is a usage error (``mimo-social CMD: error: argument --opt: ...``, exit
code 2) before anything is built, run or written.

Numbers: ``positive_int``, ``non_negative_int``, ``int_range(lo, hi)``, ``seed`` (an integer
from 0 to 2**32 - 1, what NumPy, PyTorch and SB3 all take), ``positive_float`` and
``float_above(lo)`` (finite: ``inf`` and ``nan`` are refused). Paths: ``input_file``,
``input_dir`` (must exist), ``output_file``, ``output_dir`` (may not exist yet: the nearest
existing folder above must be a writable folder, not a file); they give the text back.
``json_object`` and
``env_kwargs``: a JSON object; the latter's keys must be settings an env takes.
"""

from __future__ import annotations

import argparse
import errno
import json
import math
import os
from pathlib import Path

__all__ = ["positive_int", "non_negative_int", "int_range", "seed", "positive_float",
           "non_negative_float",
           "float_above", "input_file", "input_dir", "output_file", "output_dir", "json_object",
           "env_kwargs", "comma_choices", "write_file", "draw_to",
           "SEED_MAX"]

SEED_MAX = 2**32 - 1
Bad = argparse.ArgumentTypeError


def _int(text: str, allowed: str) -> int:
    try:
        return int(text)
    except (TypeError, ValueError):
        raise Bad(f"{text!r} is not an integer; allowed: {allowed}") from None


def int_range(lo: int, hi: int | None = None, allowed: str | None = None):
    """An integer from ``lo`` to ``hi`` (no upper bound when None)."""
    allowed = allowed or (f"an integer >= {lo}" if hi is None else f"an integer from {lo} to {hi}")

    def parse(text: str) -> int:
        value = _int(text, allowed)
        if value < lo or (hi is not None and value > hi):
            raise Bad(f"{value} not allowed; allowed: {allowed}")
        return value

    parse.__name__ = "integer"
    return parse


positive_int = int_range(1, allowed="a positive integer")
non_negative_int = int_range(0, allowed="an integer >= 0")
seed = int_range(0, SEED_MAX, allowed=f"an integer from 0 to {SEED_MAX}")


def float_above(lo: float):
    """A finite number greater than ``lo``."""
    allowed = f"a finite number > {lo:g}"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except (TypeError, ValueError):
            raise Bad(f"{text!r} is not a number; allowed: {allowed}") from None
        if not math.isfinite(value) or value <= lo:
            raise Bad(f"{text} not allowed; allowed: {allowed}")
        return value

    parse.__name__ = "number"
    return parse


positive_float = float_above(0.0)


def non_negative_float(text: str) -> float:
    """A finite number >= 0."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise Bad(f"{text!r} is not a number; allowed: a finite number >= 0") from None
    if not math.isfinite(value) or value < 0:
        raise Bad(f"{text} not allowed; allowed: a finite number >= 0")
    return value


def comma_choices(choices, what: str = "value", as_text: bool = False):
    """Comma-separated names, each one of ``choices`` (no empties, no repeats): a list, or the
    text itself with ``as_text``."""
    def parse(text: str):
        names = [n.strip() for n in text.split(",")]
        bad = [n for n in names if n not in choices]
        if bad or not names or len(set(names)) != len(names):
            why = (f"unknown {what} {', '.join(map(repr, bad))}" if bad
                   else "a name is repeated")
            raise Bad(f"{text!r}: {why}; allowed: comma-separated, from "
                      f"{', '.join(map(str, choices))}")
        return text if as_text else names

    parse.__name__ = "list"
    return parse


def input_file(text: str) -> str:
    path = Path(text)
    if not path.exists():
        raise Bad(f"{text}: no such file")
    if not path.is_file():
        raise Bad(f"{text}: not a file")
    if not os.access(path, os.R_OK):
        raise Bad(f"{text}: not readable")
    return text


def input_dir(text: str) -> str:
    path = Path(text)
    if not path.exists():
        raise Bad(f"{text}: no such folder")
    if not path.is_dir():
        raise Bad(f"{text}: not a folder")
    return text


def _writable_parent(path: Path, text: str) -> None:
    """The nearest existing folder above ``path`` must be a writable folder (the commands make
    the missing ones)."""
    above = path.absolute().parent
    while not above.exists():
        if above.is_symlink():
            raise Bad(f"{text}: {above} is a broken link")
        above = above.parent
    if not above.is_dir():
        raise Bad(f"{text}: {above} is a file, not a folder")
    if not os.access(above, os.W_OK | os.X_OK):
        raise Bad(f"{text}: the folder {above} is not writable")


def output_file(text: str) -> str:
    """A file to write: not a folder; writable if it exists; else its folder can be made."""
    if not text:
        raise Bad("an empty path; allowed: a file to write")
    path = Path(text)
    if path.is_dir():
        raise Bad(f"{text}: is a folder; allowed: a file to write")
    if path.exists():
        if not os.access(path, os.W_OK):
            raise Bad(f"{text}: not writable")
        return text
    _writable_parent(path, text)
    return text


def output_dir(text: str) -> str:
    """A folder to write into: an existing writable folder, or one that can be made."""
    if not text:
        raise Bad("an empty path; allowed: a folder to write into")
    path = Path(text)
    if path.exists():
        if not path.is_dir():
            raise Bad(f"{text}: is a file; allowed: a folder to write into")
        if not os.access(path, os.W_OK | os.X_OK):
            raise Bad(f"{text}: the folder is not writable")
        return text
    _writable_parent(path, text)
    return text


def json_object(text: str) -> dict:
    try:
        value = json.loads(text)
    except json.JSONDecodeError as e:
        raise Bad(f"not JSON: {e}") from None
    if not isinstance(value, dict):
        raise Bad("expected a JSON object, e.g. '{\"max_steps\": 200}'")
    return value


def env_setting_names() -> list[str]:
    """What ``parallel_env(**kwargs)`` of a task takes: the env's own keywords (``n_agents``,
    ``task_options``, ``max_cycles``, ...) and the agents' settings (given to all)."""
    from ..core.factory import ENV_KEYWORDS, agent_settings

    return sorted({*ENV_KEYWORDS, *agent_settings()})


def env_kwargs(text: str) -> dict:
    """A JSON object of env settings; unknown keys are refused here (values are checked by the
    env when it is made, with errors naming the agent and the setting)."""
    value = json_object(text)
    allowed = env_setting_names()
    unknown = sorted(k for k in value if k not in allowed)
    if unknown:
        raise Bad(f"unknown env setting(s) {', '.join(map(repr, unknown))}; allowed: "
                  f"{', '.join(allowed)}")
    return value


def write_file(path, data: str | bytes) -> str:
    """Write ``data`` to ``path`` (its folder made); an OSError that names the file (a full
    disk is an error here even where the file is only flushed on close)."""
    path = Path(path)
    try:
        if path.parent != Path("."):
            path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "w" if isinstance(data, str) else "wb") as f:
            f.write(data)
    except OSError as e:
        raise OSError(e.errno, f"cannot write: {e.strerror or e}", str(path)) from e
    return str(path)


def draw_to(path, draw) -> str:
    """Call ``draw(tmp)`` to make a file in a temporary folder, then :func:`write_file` its bytes
    to ``path``: a plotting library that ignores write errors (matplotlib's ``savefig`` into a
    full disk says nothing) cannot leave a missing or cut file unreported."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="mimo-social-") as tmp:
        made = Path(tmp) / ("out" + (Path(path).suffix or ".png"))  # (matplotlib adds .png)
        draw(made)
        if not made.is_file() or made.stat().st_size == 0:
            raise OSError(errno.EIO, "nothing was drawn", str(path))
        return write_file(path, made.read_bytes())
