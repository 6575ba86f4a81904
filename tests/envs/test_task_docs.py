"""docs/tasks.md is generated from the task modules' docstring tables (the one source)."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from mimo_social.cli import docs as docs_cli
from mimo_social.envs import task_docs
from mimo_social.envs.catalog import CATALOG

DOCS = Path(__file__).resolve().parents[2] / "docs" / "tasks.md"


def test_docs_tasks_md_is_generated():
    assert DOCS.is_file() and DOCS.read_text() == task_docs.render(), (
        "docs/tasks.md differs from the task docstring tables: run `mimo-social docs` "
        "(edit the tables in mimo_social/tasks/*/__init__.py, not docs/tasks.md)")


@pytest.mark.parametrize("entry", CATALOG, ids=lambda e: e.name)
def test_every_table_has_the_required_rows(entry):
    doc = task_docs.task_doc(entry)
    assert not doc.missing, f"{doc.source}: the docstring table lacks {list(doc.missing)}"
    for aspect in ("version history", "privileged cues", "baselines", "sources"):
        assert doc.row(aspect).strip(), f"{doc.source}: the {aspect!r} row is empty"
    assert doc.row("version history").startswith("v0"), doc.source
    assert "\n" not in doc.title and len(doc.title) < 100, f"{doc.source}: a one-line title"


def test_one_section_per_catalogue_entry_in_its_order():
    text = task_docs.render()
    places = [text.index(f"Task `{e.name}`: folder `mimo_social/tasks/{e.name}/`") for e in CATALOG]
    assert places == sorted(places)
    for e in CATALOG:
        assert f"`{e.module.__name__}`" in text and f"`{e.gym_id}`" in text


def test_overview_reads_the_task_classes():
    table = task_docs.overview_table()
    assert "| `mimo_social.envs.standup_v0` |" in table
    standup = next(line for line in table.splitlines() if "standup_v0" in line)
    assert "| 10 ms |" in standup and "500 steps (5 s)" in standup
    selfbody = next(line for line in table.splitlines() if "selfbody_v0" in line)
    assert "5 ms (`frame_skip=1`)" in selfbody and "500 steps (2.5 s)" in selfbody
    free_play = next(line for line in table.splitlines() if "free_play_v0" in line)
    assert "1-8 (default 2; Gymnasium id: 1)" in free_play


def test_parse_docstring():
    doc = ("Thing (paper Sec. X): a title.\n\nagents:\n    1\nreward (both):\n    a `|` b,\n"
           "    :class:`~a.b.Partner`\n\nA note\nover two lines.\n")
    title, rows, notes = task_docs.parse_docstring(doc, "here")
    assert title == "Thing (paper Sec. X): a title."
    assert rows == (("agents", "1"), ("reward (both)", "a `|` b, :class:`~a.b.Partner`"))
    assert notes == ("A note over two lines.",)
    assert task_docs._markdown(rows[1][1]) == "a `|` b, `Partner`"
    with pytest.raises(ValueError, match="no table"):
        task_docs.parse_docstring("Title only.", "here")
    with pytest.raises(ValueError, match="no table"):   # a key without an indented value
        task_docs.parse_docstring("Title.\n\nagents:\nnot indented\n", "here")
    with pytest.raises(ValueError, match="no docstring"):
        task_docs.parse_docstring(None, "here")


def test_cli_writes_and_checks(tmp_path, capsys):
    out = tmp_path / "tasks.md"
    check = argparse.Namespace(out=str(out), check=True)
    assert docs_cli.run(check) == 1                      # missing
    assert docs_cli.run(argparse.Namespace(out=str(out), check=False)) == 0
    assert out.read_text() == task_docs.render()
    assert docs_cli.run(check) == 0
    out.write_text(out.read_text() + "edited by hand\n")
    assert docs_cli.run(check) == 1
    assert "run `mimo-social docs" in capsys.readouterr().err


def test_each_task_section_lists_the_plots_its_replay_shows():
    from mimo_social.envs.task_docs import render, task_docs
    page = render()
    for d in task_docs():
        section = page.split(f"## {d.heading}\n", 1)[1].split("\n## ", 1)[0]
        row = next(line for line in section.splitlines() if line.startswith("| replay plots |"))
        names = [p.name for p in d.task_cls(d.task_cls.default_n_agents, None).plots()]
        assert all(f"`{n}`" in row for n in names), (d.entry.name, row)
    assert "`hand_distance` (m), one line" in page and "`gaze_error` (deg), per agent" in page


@pytest.mark.parametrize("entry", CATALOG, ids=lambda e: e.name)
def test_the_table_is_wrapped_within_100_columns(entry):
    package = task_docs.task_package(entry)
    long = [line for line in package.__doc__.splitlines() if len(line) > 100]
    assert not long, f"{package.__name__}: table lines over 100 columns: {long}"
