"""``mimo-social bench sim``: measure real seconds per simulated second, by component (the
library: :mod:`mimo_social.bench`).

    mimo-social bench sim --json bench.json --update-benchmarks-md
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from .. import bench
from ._args import input_file, output_file, positive_float, seed, write_file

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "sim"
HELP = "real seconds per simulated second, by component (BENCHMARKS.md)"


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings, e.g.
    ``help``; none: not listed)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="Measure real seconds per simulated second (and env build time) for each "
                    "configuration, split by component. Default set: "
                    + ", ".join(bench.DEFAULT_CONFIGS) + "; also: "
                    + ", ".join(n for n in bench.CONFIGS if n not in bench.DEFAULT_CONFIGS) + ".")
    parser.add_argument("--json", default="bench.json", metavar="FILE", type=output_file,
                        help="where to write the results (default: bench.json)")
    parser.add_argument("--sim-seconds", type=positive_float, default=bench.DEFAULT_SIM_SECONDS,
                        metavar="S",
                        help=f"simulated seconds per configuration (default: "
                             f"{bench.DEFAULT_SIM_SECONDS:g}, one episode of the grid)")
    parser.add_argument("--only", default=None, metavar="NAME,...",
                        help="comma-separated configurations to run (default: the default set; "
                             "'all': every configuration)")
    parser.add_argument("--markdown", default=None, metavar="FILE", type=output_file,
                        help="write a Markdown report there (default: none)")
    parser.add_argument("--update-benchmarks-md", action="store_true",
                        help="write BENCHMARKS.md (and docs/benchmarks.png unless --plot is given)")
    parser.add_argument("--plot", default=None, metavar="FILE.png", type=output_file,
                        help="write stacked bar charts of the components there (and a second "
                             "one, tasks and scaling, beside it as <stem>_tasks_scaling.png)")
    parser.add_argument("--seed", type=seed, default=0, help="seed of the random actions")
    parser.add_argument("--no-recording", action="store_true",
                        help="do not record the runs (the recording component is then 0)")
    parser.add_argument("--from-json", default=None, metavar="FILE", type=input_file,
                        help="measure nothing: re-render --markdown/--plot from an earlier --json "
                             "output (its recorded command is kept)")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    parser.add_argument("--no-cold-start", action="store_true",
                        help="skip the fresh-process build measurements")
    parser.set_defaults(func=run)
    return parser


def _command(args, markdown, plot) -> str:
    parts = ["mimo-social bench sim", f"--json {args.json}",
             f"--sim-seconds {args.sim_seconds:g}"]
    if args.only:
        parts.append(f"--only {args.only}")
    if args.seed:
        parts.append(f"--seed {args.seed}")
    if getattr(args, "no_recording", False):
        parts.append("--no-recording")
    if args.no_cold_start:
        parts.append("--no-cold-start")
    if markdown:
        parts.append(f"--markdown {markdown}")
    if plot:
        parts.append(f"--plot {plot}")
    return " ".join(parts)


def run(args) -> int:
    try:
        names = bench.check_names(args.only)
    except ValueError as e:
        print(f"mimo-social bench {NAME}: error: {e}", file=sys.stderr)
        return 2
    markdown, plot = args.markdown, args.plot
    if args.update_benchmarks_md:
        markdown = markdown or "BENCHMARKS.md"
        plot = plot or "docs/benchmarks.png"
    if args.from_json:
        report = json.loads(Path(args.from_json).read_text())
    else:
        report = bench.run_benchmarks(names, args.sim_seconds, seed=args.seed,
                                progress=not args.no_progress,
                                measure_cold_start=not args.no_cold_start,
                                record=not getattr(args, "no_recording", False))
        report["settings"]["command"] = _command(args, markdown, plot)
        write_file(args.json, json.dumps(report, indent=2) + "\n")
    plots = bench.plot_report(report, plot) if plot else []
    if markdown:
        md = Path(markdown)
        rel = [os.path.relpath(Path(p).resolve(), md.resolve().parent) for p in plots]
        write_file(md, bench.markdown_report(report, report["settings"].get("command"), rel)
                   + "\n")
    print(bench.markdown_table(report))
    for s in report.get("skipped") or []:
        print(f"skipped: {s['name']}: {s['reason']}")
    for c in bench.target_checks(report):
        print(f"target: {c['target']}: {c['measured']} -> {'met' if c['met'] else 'NOT met'}")
    for v in bench.jacobian_verdict(report):
        print(f"jacobian, {v['n_agents']} agent(s): {v['winner']} "
              f"(dense faster by {v['dense_faster_by'] * 100:+.1f} % of physics in the median "
              f"chunk, in {v['dense_faster_in'] * 100:.0f} % of chunks; unstable "
              f"episodes dense {v['dense_unstable']}, sparse {v['sparse_unstable']})")
    written = [str(p) for p in (None if args.from_json else args.json, markdown, *plots) if p]
    print("wrote " + ", ".join(written))
    return 0
