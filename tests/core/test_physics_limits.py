"""Every physics setting the config allows holds a body at the largest allowed strength under
bang-bang actions; settings beyond the measured limits are refused with a clear message."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from mimo_social.core.config import MIN_ITERATIONS, TIMESTEP_MAX, TOLERANCE_MAX, PhysicsConfig
from mimo_social.envs import free_play_v0
from mimo_social.util.checks import ConfigError

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "body"))
from test_hand_stability import RUNS, bang_bang  # noqa: E402  (the stability cases)

#: each setting at its limit alone, then all at their limits together for each solver
EDGES = {
    "timestep": {"timestep": TIMESTEP_MAX},
    "tolerance": {"tolerance": TOLERANCE_MAX},
    "newton iterations": {"iterations": MIN_ITERATIONS["newton"]},
    "cg iterations": {"solver": "cg", "iterations": MIN_ITERATIONS["cg"]},
    "pgs iterations": {"solver": "pgs", "iterations": MIN_ITERATIONS["pgs"]},
    "elliptic cone": {"cone": "elliptic"},
    "dense": {"jacobian": "dense"},
    "auto": {"jacobian": "auto"},
    **{f"all limits, {solver}": {"timestep": TIMESTEP_MAX, "tolerance": TOLERANCE_MAX,
                                 "solver": solver, "iterations": MIN_ITERATIONS[solver]}
       for solver in MIN_ITERATIONS},
}
#: the cases that diverged first as settings loosened (newborn with muscles; two touching)
BODIES = ("newborn, muscles, strength 3", "two sitting face to face, strength 3")


@pytest.mark.parametrize("body", BODIES)
@pytest.mark.parametrize("edge", list(EDGES))
def test_an_allowed_setting_runs_600_bang_bang_steps_without_a_divergence(edge, body):
    assert bang_bang(600, seed=0, physics=EDGES[edge], **RUNS[body]) == []


@pytest.mark.slow
@pytest.mark.parametrize("seed", (1, 2))
@pytest.mark.parametrize("body", list(RUNS))
@pytest.mark.parametrize("edge", list(EDGES) + ["frame_skip"])
def test_every_case_and_seed_at_every_limit(edge, body, seed):
    physics = {"frame_skip": 100} if edge == "frame_skip" else EDGES[edge]
    assert bang_bang(600, seed=seed, physics=physics, **RUNS[body]) == []


@pytest.mark.parametrize("physics, message", [
    ({"iterations": MIN_ITERATIONS["newton"] - 1},
     r"iterations=9 not allowed; allowed: an integer from 10 to 1000 \(with solver='newton'; "
     r"outside it a body at strength 3 diverged"),
    ({"solver": "cg", "iterations": 20}, r"iterations=20 .* from 32 to 1000 \(with solver='cg'"),
    ({"timestep": 0.01}, r"timestep=0.01 not allowed; allowed: a number from 0.0001 to 0.006"),
    ({"tolerance": 0.1}, r"tolerance=0.1 not allowed; allowed: a number from 0 to 0.001"),
])
def test_settings_that_cannot_hold_are_refused(physics, message):
    with pytest.raises(ConfigError, match=message):
        free_play_v0.parallel_env(physics=physics)
    with pytest.raises(ConfigError, match=message):
        PhysicsConfig(**physics)


def test_pgs_takes_a_single_iteration():
    assert PhysicsConfig(solver="pgs", iterations=1).iterations == 1
