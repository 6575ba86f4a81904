"""``mimo-social docs [--check] [--out docs/tasks.md]``: write the task docs from the task tables.

The page is :func:`mimo_social.envs.task_docs.render`: the catalogue's overview and one section
per task, built from the docstring table of its module in ``mimo_social/tasks/``. ``--check``
writes nothing and exits 1 when the file differs (or a table lacks a required row).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..envs import task_docs
from ._args import output_file, write_file

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "docs", help="write docs/tasks.md from the task modules' docstring tables",
        description="Render docs/tasks.md from the catalogue and the docstring table of each "
                    "task module (mimo_social/tasks/*.py), the one source of the task docs.")
    parser.add_argument("--out", default="docs/tasks.md", metavar="FILE", type=output_file,
                        help="the file to write or check (default: docs/tasks.md)")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 when FILE differs from the generated text")
    parser.set_defaults(func=run)
    return parser


def run(args) -> int:
    out = Path(args.out)
    incomplete = [(d.source, d.missing) for d in task_docs.task_docs() if d.missing]
    for source, missing in incomplete:
        print(f"{source}: the docstring table lacks the row(s) {', '.join(missing)}",
              file=sys.stderr)
    text = task_docs.render()
    if args.check:
        current = out.read_text() if out.is_file() else None
        if current != text:
            why = "is missing" if current is None else "differs from the task docstrings"
            print(f"{out} {why}: run `mimo-social docs --out {out}`", file=sys.stderr)
            return 1
        if incomplete:
            return 1
        print(f"{out} is up to date")
        return 0
    write_file(out, text)
    print(f"wrote {out} ({len(text.splitlines())} lines, {len(task_docs.task_docs())} tasks)")
    return 1 if incomplete else 0
