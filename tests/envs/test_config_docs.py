"""docs/reference/config.md is generated from the config dataclasses (the one source)."""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from mimo_social.cli import docs as docs_cli
from mimo_social.core.config import POSTURES, AgentConfig, PhysicsConfig
from mimo_social.envs import config_docs, task_docs
from mimo_social.senses import SENSES

PAGE = Path(__file__).resolve().parents[2] / "docs" / "reference" / "config.md"


def test_config_reference_is_generated():
    assert PAGE.is_file() and PAGE.read_text() == config_docs.render(), (
        "docs/reference/config.md differs from the config dataclasses: run `mimo-social docs` "
        "(edit the comments in mimo_social/core/config.py and mimo_social/senses/*.py)")


def test_every_setting_has_a_comment():
    assert config_docs.missing() == []
    assert "(no comment)" not in config_docs.render()


def test_every_field_and_sense_is_on_the_page():
    text = config_docs.render()
    for cls in [AgentConfig, PhysicsConfig] + [e.config for e in SENSES.values()]:
        assert f"`{cls.__name__}`" in text
        for field in dataclasses.fields(cls):
            assert f"| `{field.name}` |" in text, (cls.__name__, field.name)
    for name in ("n_agents", "task_options", "physics", "per_agent", "render_mode",
                 "max_steps", "render_size", "scene"):
        assert f"| `{name}` |" in text


def test_allowed_and_defaults_come_from_the_checks():
    posture = next(f for f in config_docs.field_docs(AgentConfig) if f.name == "posture")
    assert posture.allowed == str(list(POSTURES)) and posture.default == "`'standing'`"
    touch = next(f for f in config_docs.field_docs(AgentConfig) if f.name == "touch")
    assert touch.default == "`False` (off)" and "density" in touch.allowed
    timestep = next(f for f in config_docs.field_docs(PhysicsConfig) if f.name == "timestep")
    assert timestep.allowed.startswith("a number from 0.0001 to 0.006")
    assert timestep.default == f"`{PhysicsConfig.timestep!r}`"
    scene = next(f for f in config_docs.env_setting_docs() if f.name == "scene")
    assert scene.allowed == "['floor', 'playroom']" and scene.default == "`'floor'`"


@dataclasses.dataclass(frozen=True)
class _Example:
    # above,
    # over two lines
    a: int = 1   # and after
    b: str = "x"
    c: tuple[int, ...] = (1, 2)  # only after; a '#' in "quotes" stays

    def __post_init__(self):
        if not isinstance(self.a, int) or not isinstance(self.b, str) or \
                not isinstance(self.c, tuple):
            raise config_docs.ConfigError("bad; allowed: the right type")


def test_comments_above_and_after_a_field_are_its_text():
    docs = {f.name: f for f in config_docs.field_docs(_Example)}
    assert docs["a"].text == "above, over two lines and after"
    assert docs["b"].text == ""                       # undocumented: missing() would name it
    assert docs["c"].text == "only after; a '#' in \"quotes\" stays"
    assert docs["a"].allowed == "the right type" and docs["c"].type == "tuple[int, ...]"


def test_cli_writes_and_checks_both_pages(tmp_path, capsys):
    tasks, config = tmp_path / "tasks.md", tmp_path / "ref" / "config.md"

    def args(check):
        return argparse.Namespace(out=str(tasks), config_out=str(config), check=check)

    assert docs_cli.run(args(True)) == 1
    assert docs_cli.run(args(False)) == 0
    assert config.read_text() == config_docs.render()
    assert tasks.read_text() == task_docs.render()
    assert docs_cli.run(args(True)) == 0
    config.write_text(config.read_text().replace("| `scale` |", "| `size` |"))
    assert docs_cli.run(args(True)) == 1
    assert "config.md differs from the config dataclasses" in capsys.readouterr().err
