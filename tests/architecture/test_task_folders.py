"""One folder per task: a task's env, scripted solution and measures live together.

Each catalogue entry's Task class, scripted controller and measures come from its own folder,
``mimo_social/tasks/<name>/``; its ``<name>_v0`` module only re-exports that folder; no task
reaches into another task's folder; ``partners/`` holds only what several tasks reuse.
"""

from __future__ import annotations

import ast
import inspect

import pytest

from mimo_social.envs import task_docs
from mimo_social.envs.catalog import CATALOG

from test_layers import GRAPH, MODULES, PKG  # this folder is on the path (pytest rootdir-less tests)

TASKS = PKG / "tasks"
#: the modules of tasks/ that are not a task's folder: helpers several tasks share
SHARED = {"mimo_social.tasks", "mimo_social.tasks.common", "mimo_social.tasks.dyad",
          "mimo_social.tasks.facing_pair"}


def _folder(module: str) -> str | None:
    """The task folder a module belongs to (``mimo_social.tasks.reach.controller`` -> reach)."""
    parts = module.split(".")
    if module in SHARED or parts[:2] != ["mimo_social", "tasks"] or len(parts) < 3:
        return None
    return parts[2]


@pytest.mark.parametrize("entry", CATALOG, ids=lambda e: e.name)
def test_an_entry_comes_from_its_own_folder(entry):
    package = f"mimo_social.tasks.{entry.name}"
    assert task_docs.task_class(entry).__module__ == f"{package}.task"
    assert task_docs.task_package(entry).__name__ == package
    if entry.controller is not None:
        assert entry.controller.__module__ == f"{package}.controller"
    if entry.measures is not None:
        assert entry.measures.__name__ == f"{package}.measures"
        for name in ("run", "rows"):
            assert callable(getattr(entry.measures, name, None)), f"{package}.measures.{name}"
        assert isinstance(getattr(entry.measures, "UNIT", None), str)
    else:
        assert not (TASKS / entry.name / "measures.py").exists(), \
            f"{package}.measures exists but the catalogue entry does not name it"


def test_every_task_folder_is_in_the_catalogue():
    folders = {p.parent.name for p in TASKS.glob("*/task.py")}
    assert folders == {e.name for e in CATALOG}
    for e in CATALOG:
        has = (TASKS / e.name / "controller.py").exists()
        assert has == (e.controller is not None), e.name


@pytest.mark.parametrize("entry", CATALOG, ids=lambda e: e.name)
def test_the_versioned_module_is_a_shim(entry):
    """``<task>_v0.py``: two imports of its task's folder (PettingZoo's pattern), nothing else."""
    path = PKG / "envs" / f"{entry.module_name}.py"
    tree = ast.parse(path.read_text())
    assert len(tree.body) <= 2 and all(isinstance(n, ast.ImportFrom) for n in tree.body), path
    assert {(n.level, n.module) for n in tree.body} == {(2, f"tasks.{entry.name}")}, path
    assert entry.module.parallel_env is entry.module.__dict__["parallel_env"]
    assert inspect.getmodule(entry.module.parallel_env).__name__ \
        == f"mimo_social.tasks.{entry.name}.task"


def test_no_task_imports_another_tasks_folder():
    bad = []
    for module, imports in GRAPH.items():
        own = _folder(module)
        if own is None and module not in SHARED:
            continue
        for target, line in imports:
            other = _folder(target)
            if other is not None and other != own:
                bad.append(f"{module}:{line} imports {target}")
    assert not bad, "a task reaches into another task's folder:\n" + "\n".join(bad)


def _partner_users() -> dict[str, set[str]]:
    """Per module of partners/, the task folders that use it, directly or through another
    module of partners/ or a shared module of tasks/."""
    direct: dict[str, set[str]] = {m: set() for m in MODULES if m.startswith("mimo_social.partners")}

    def reached(module: str, seen: set[str]) -> set[str]:
        out = set()
        for target, _ in GRAPH.get(module, ()):
            if target in seen:
                continue
            seen.add(target)
            if target in direct:
                out.add(target)
            if target in direct or target in SHARED:
                out |= reached(target, seen)
        return out

    for module in MODULES:
        task = _folder(module)
        if task is None:
            continue
        for partner in reached(module, {module}):
            direct[partner].add(task)
    return direct


#: modules of partners/ kept there although one task uses them, each for its reason
REUSABLE = {
    # a caregiver that replays any recorded action stream (motors and face) of any agent: the
    # partner of a replay condition in a user's own paradigm, not contingency's alone
    "mimo_social.partners.replay",
}


def test_partners_hold_only_what_several_tasks_use():
    users = _partner_users()
    single = {m: sorted(t) for m, t in users.items()
              if len(t) == 1 and m not in REUSABLE}
    assert not single, (f"modules of partners/ that one task alone uses (move them into its "
                        f"folder): {single}")
    assert all(len(users[m]) >= 1 for m in REUSABLE), "REUSABLE names a module no task uses"
