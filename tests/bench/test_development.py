"""``mimo-social bench development`` with tiny numbers: every body builds and is timed, every
compared env steps, and the table names each figure against its base."""

from __future__ import annotations

import json

from mimo_social import cli
from mimo_social.bench import development


def test_bench_development_times_every_body_and_variant(tmp_path, capsys):
    out = tmp_path / "dev.json"
    code = cli.main(["bench", "development", "--sim-seconds", "0.06", "--repeats", "1",
                     "--json", str(out)])
    assert code == 0
    results = json.loads(out.read_text())
    bodies = {(r["hands"], r["body"]) for r in results["build"]}
    assert bodies == {(h, label) for h in ("mitten", "five_fingers")
                      for label, _ in development.BUILD_BODIES}
    assert all(r["tables_ms"] > 0 and r["env_ms"] > 0 for r in results["build"])
    assert set(results["delays"]) == {"touch", "touch + delays", "touch + vision",
                                      "touch + vision + delays"}
    assert len(results["acuity"]) == 4 and all(v > 0 for v in results["acuity"].values())
    printed = capsys.readouterr().out
    assert "% vs touch) |" in printed and "vs 128x128 eyes, acuity off" in printed
    assert "| five_fingers | adult |" in printed
