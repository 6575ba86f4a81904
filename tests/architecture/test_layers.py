"""The package's architecture, read from its import graph.

Layers import only downward (DESIGN.md): helpers -> body / expressions / render -> senses ->
core -> partners -> tasks -> envs -> tools (recording, then train / bench / experiments /
figures) -> cli. Also: no import cycle between modules, no string import, no argparse and no
``__main__`` block outside ``cli/``, no module over 600 lines nor a line over 120 characters,
no read of another object's private attribute (outside an allow-list of third-party privates),
and one folder per task (:mod:`tests.architecture.test_task_folders`).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[2] / "mimo_social"

#: the rank of each top-level unit of the package; a unit imports only from lower ranks
LAYERS = {
    "util": 0,
    "body": 1, "expressions": 1, "render": 1, "scenery": 1,
    "senses": 2,
    "core": 3,
    "partners": 4,
    "tasks": 5,
    "envs": 6,
    "recording": 7, "gpu": 7,
    "train": 8, "bench": 8, "experiments": 8, "figures": 8,
    "cli": 9,
}
#: modules outside the layers: the package root (chooses the GL backend, registers the ids) and
#: the alias kept for files saved before the layout (a saved SB3 model names
#: ``mimo_social.obs_norm.RunningNorm``)
OUTSIDE = {"mimo_social", "mimo_social.obs_norm"}
MAX_LINES = 600
#: characters in one line of a package module
MAX_COLUMNS = 120



def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PKG.rglob("*.py")):
        parts = path.relative_to(PKG.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _imports(name: str, path: Path) -> list[tuple[str, int]]:
    """Every mimo_social module this module imports (anywhere in the file), with line numbers."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names if a.name.startswith("mimo_social")]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if not mod.startswith("mimo_social"):
                continue
            for a in node.names:  # `from pkg import submodule` imports the submodule
                sub = f"{mod}.{a.name}"
                out.append((sub if sub in MODULES else mod, node.lineno))
    return out


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def _unit(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def test_every_unit_has_a_layer():
    units = {_unit(m) for m in MODULES if m not in OUTSIDE}
    assert units <= set(LAYERS), f"units without a layer: {sorted(units - set(LAYERS))}"


def test_imports_run_only_downward():
    bad = []
    for module, imports in GRAPH.items():
        if module in OUTSIDE:
            continue
        unit = _unit(module)
        for target, line in imports:
            tu = _unit(target)
            if target in OUTSIDE or tu is None:
                bad.append(f"{module}:{line} imports {target} (outside the layers)")
            elif tu != unit and LAYERS[tu] >= LAYERS[unit]:
                bad.append(f"{module}:{line} ({unit}, layer {LAYERS[unit]}) imports {target} "
                           f"({tu}, layer {LAYERS[tu]})")
    assert not bad, "imports that do not run downward:\n" + "\n".join(bad)


def test_no_import_cycle():
    """Tarjan's strongly connected components over module imports (function-level included)."""
    index, low, stack, on, cycles = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w, _ in GRAPH.get(v, ()):
            if w not in MODULES or w == v:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in MODULES:
        if v not in index:
            visit(v)
    assert not cycles, f"import cycles: {cycles}"


def _calls(path: Path):
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call):
            f = node.func
            yield node, (f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", ""))


def test_no_string_imports():
    bad = [f"{m}:{node.lineno}" for m, p in MODULES.items() for node, name in _calls(p)
           if name in ("import_module", "__import__")]
    assert not bad, f"string imports (hide the import graph): {bad}"


def test_argparse_and_main_blocks_live_in_cli():
    bad = []
    for module, path in MODULES.items():
        if _unit(module) == "cli":
            continue
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] + [getattr(node, "module", None) or ""]
                if "argparse" in names:
                    bad.append(f"{module}:{node.lineno} imports argparse")
            if isinstance(node, ast.If) and isinstance(node.test, ast.Compare) \
                    and getattr(node.test.left, "id", "") == "__name__":
                bad.append(f"{module}:{node.lineno} has a __main__ block")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_module_is_short(module):
    n = len(MODULES[module].read_text().splitlines())
    assert n <= MAX_LINES, f"{module} has {n} lines; at most {MAX_LINES}: split it by concern"


def test_tasks_and_partners_use_the_public_env_view():
    """Task hooks and partners read env.systems / env.controls / env.steps, never env._..."""
    bad = []
    for module, path in MODULES.items():
        if _unit(module) == "core" or module in OUTSIDE:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and node.attr.startswith("_") \
                    and not node.attr.startswith("__") and isinstance(node.value, ast.Name) \
                    and node.value.id in ("env", "par_env", "parallel", "penv", "base_env"):
                bad.append(f"{module}:{node.lineno} reads {node.value.id}.{node.attr}")
    assert not bad, "private env attributes read outside core:\n" + "\n".join(bad)


def test_tests_mirror_the_package():
    """Each folder of tests/ is a unit of the package, or one of the suites that span them."""
    tests = Path(__file__).resolve().parents[1]
    spanning = {"architecture", "conformance", "properties", "clients", "data", "docs",
                "__pycache__"}
    folders = {p.name for p in tests.iterdir() if p.is_dir()} - spanning
    assert folders <= set(LAYERS), f"test folders that are no unit: {sorted(folders - set(LAYERS))}"
    loose = sorted(p.name for p in tests.glob("test_*.py"))
    assert not loose, f"tests outside a unit's folder: {loose}"


def test_a_saved_model_still_finds_running_norm():
    from mimo_social.obs_norm import RunningNorm
    from mimo_social.train.obs_norm import RunningNorm as new

    assert RunningNorm is new


def test_no_line_is_too_long():
    bad = [f"{m}:{k} has {len(line)} characters" for m, path in MODULES.items()
           for k, line in enumerate(path.read_text().splitlines(), 1) if len(line) > MAX_COLUMNS]
    assert not bad, f"lines over {MAX_COLUMNS} characters (wrap them):\n" + "\n".join(bad)


#: the private attributes of third-party objects the package reads, each for a reason no public
#: API serves; (module, expression, attribute). Nothing of the package's own is here: a private
#: attribute of ours that another object needs becomes public instead.
THIRD_PARTY_PRIVATES = {
    # rerun-sdk: a stream made from the native handle that rr.memory/binary streams hand out,
    # and a blueprint sent to a stream that is not the global one (no public call takes one)
    ("mimo_social.recording.streams", "rr.RecordingStream", "_from_native"),
    ("mimo_social.recording.streams", "default_blueprint.to_blueprint()", "_log_to_stream"),
    # MuJoCo's GL module: the context current on this thread (to check it before drawing)
    ("mimo_social.render.eye_renderer", "mod", "_current_context"),
    # RLlib: the connector pipeline's observation filters (to read their running statistics)
    # and the env runner's env-to-module connector (to carry the filter state to evaluation)
    ("mimo_social.train.rllib.evaluation", "filt", "_filters"),
    ("mimo_social.train.rllib.runner", "er", "_env_to_module"),
    ("mimo_social.train.rllib.runner", "algorithm.env_runner", "_env_to_module"),
    # the standard library: a spawned run whose parent is gone ends its process at once (no
    # exit handlers: the pool worker's would wait on the dead parent); os._exit is the
    # documented call for a child process
    ("mimo_social.train.comparison", "os", "_exit"),
}


def _private_reads():
    """(module, line, expression, attribute) of each ``obj._name`` whose obj is not ``self``,
    ``cls`` or ``super()``, and each ``from x import _name`` of another module's private."""
    out = []
    for module, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and node.attr.startswith("_") \
                    and not (node.attr.startswith("__") and node.attr.endswith("__")):
                owner = ast.unparse(node.value)
                if owner not in ("self", "cls", "super()"):
                    out.append((module, node.lineno, owner, node.attr))
            elif isinstance(node, ast.ImportFrom):
                out += [(module, node.lineno, f"from {'.' * node.level}{node.module or ''}",
                         a.name) for a in node.names
                        if a.name.startswith("_") and not a.name.startswith("__")]
    return out


def test_no_read_of_another_objects_private_attribute():
    bad = [f"{m}:{line} reads {owner}.{attr}" for m, line, owner, attr in _private_reads()
           if (m, owner, attr) not in THIRD_PARTY_PRIVATES]
    assert not bad, ("private attributes read from outside their object (make them public, or "
                     "for a third-party object add them to THIRD_PARTY_PRIVATES with the "
                     "reason):\n" + "\n".join(bad))


def test_the_allow_list_names_only_reads_that_exist():
    found = {(m, owner, attr) for m, _, owner, attr in _private_reads()}
    assert THIRD_PARTY_PRIVATES <= found, sorted(THIRD_PARTY_PRIVATES - found)
