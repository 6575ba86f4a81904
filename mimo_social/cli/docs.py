"""``mimo-social docs [--check] [--out docs/tasks.md] [--config-out docs/reference/config.md]``.

Writes the generated pages of the docs: the task page, :func:`mimo_social.envs.task_docs.render`
(the catalogue's overview and one section per task, built from the docstring table of its module
in ``mimo_social/tasks/``), and the configuration reference,
:func:`mimo_social.envs.config_docs.render` (every setting of the config dataclasses, with its
comment and what its check allows). ``--check`` writes nothing and exits 1 when a file differs
(or a table lacks a required row, or a setting has no comment).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..envs import config_docs, task_docs
from ._args import output_file, write_file

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "docs", help="write docs/tasks.md and docs/reference/config.md from their sources",
        description="Render docs/tasks.md from the catalogue and the docstring table of each "
                    "task module (mimo_social/tasks/*.py), the one source of the task docs, "
                    "and docs/reference/config.md from the config dataclasses.")
    parser.add_argument("--out", default="docs/tasks.md", metavar="FILE", type=output_file,
                        help="the task page to write or check (default: docs/tasks.md)")
    parser.add_argument("--config-out", default="docs/reference/config.md", metavar="FILE",
                        type=output_file, help="the configuration reference to write or check "
                                               "(default: docs/reference/config.md)")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 when a file differs from the generated text")
    parser.set_defaults(func=run)
    return parser


def _pages(args) -> list[tuple[Path, str, str, list[str]]]:
    """(file, text, what it is generated from, what its source lacks) for each page asked for;
    ``config_out`` None (or absent): the task page only."""
    incomplete = [f"{d.source}: the docstring table lacks the row(s) {', '.join(d.missing)}"
                  for d in task_docs.task_docs() if d.missing]
    pages = [(Path(args.out), task_docs.render(), "the task docstrings", incomplete)]
    config_out = getattr(args, "config_out", None)
    if config_out:
        lacking = [f"{name}: no comment in its config class (the reference shows the comment "
                   f"above a field and the one after it)" for name in config_docs.missing()]
        pages.append((Path(config_out), config_docs.render(), "the config dataclasses",
                      lacking))
    return pages


def run(args) -> int:
    status = 0
    for out, text, source, lacking in _pages(args):
        for line in lacking:
            print(line, file=sys.stderr)
        status |= bool(lacking)
        if args.check:
            current = out.read_text() if out.is_file() else None
            if current != text:
                why = "is missing" if current is None else f"differs from {source}"
                print(f"{out} {why}: run `mimo-social docs`", file=sys.stderr)
                status = 1
            elif not lacking:
                print(f"{out} is up to date")
            continue
        write_file(out, text)
        print(f"wrote {out} ({len(text.splitlines())} lines)")
    return int(status)
