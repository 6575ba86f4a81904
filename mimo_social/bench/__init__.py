"""The benchmark: real seconds per simulated second, split by component (``mimo-social bench
sim``).

:mod:`.configs` (what runs: :data:`CONFIGS`, one per catalogue env among them; targets and the
original MIMo's figures), :mod:`.runner` (the timed runs, :func:`run_benchmarks`),
:mod:`.builds` (build times in fresh processes), :mod:`.machine` (what it ran on),
:mod:`.report` (verdicts and the Markdown of BENCHMARKS.md), :mod:`.plots` (the charts).

From Python::

    from mimo_social import bench
    report = bench.run_benchmarks(["basic_1", "reach"], sim_seconds=2)
    print(bench.markdown_table(report))
"""

from .builds import cold_start, fresh_build, skin_cache_builds
from .configs import (CHUNK, COMPONENTS, CONFIGS, DEFAULT_CONFIGS, DEFAULT_SIM_SECONDS,
                      ENV_COMPONENTS, EPISODE_STEPS, MIMO_REFERENCE, TARGETS, WARMUP_STEPS,
                      BenchConfig, check_names, mimo_reference)
from .machine import machine_info
from .plots import plot_report
from .report import (build_table, jacobian_verdict, load_note, markdown_report, markdown_table,
                     mimo_comparison, noise_note, noise_pairs, scaling_table, target_checks,
                     where_time_goes)
from .runner import run_benchmarks

__all__ = [
    "CONFIGS", "DEFAULT_CONFIGS", "COMPONENTS", "ENV_COMPONENTS", "BenchConfig", "CHUNK",
    "WARMUP_STEPS", "EPISODE_STEPS", "DEFAULT_SIM_SECONDS", "MIMO_REFERENCE", "TARGETS",
    "check_names", "mimo_reference", "run_benchmarks", "cold_start", "fresh_build",
    "skin_cache_builds", "machine_info", "markdown_report", "markdown_table", "scaling_table",
    "build_table", "where_time_goes", "target_checks", "mimo_comparison", "jacobian_verdict",
    "noise_pairs", "noise_note", "load_note", "plot_report",
]
