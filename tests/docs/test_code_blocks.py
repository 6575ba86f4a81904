"""Every code block of the documentation site runs (the pages of the nav in mkdocs.yml).

A page's blocks run in page order in one Python process, in one namespace (like a tutorial):
each ```python block is executed, each ```bash block runs in bash (``-euo pipefail``), all in a
fresh folder that has the repository's ``scripts``, ``docs``, ``examples`` and ``.venv-rllib``
linked in, with the repository on ``PYTHONPATH``. A block that is not run says so, visibly, in
an HTML comment on the line above it, with its reason:

* ``<!-- not run: trains for 30 min -->``: never run here;
* ``<!-- slow: trains a policy for 2 min -->``: run only by the slow test of its page
  (``python3 -m pytest -m slow tests/docs``), with every other block of the page.

Blocks of other languages (``text``, ``toml``, ``json`` ...) are not code and are not run; a
fence without a language is an error, so no command is skipped by being unlabelled.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
#: languages whose blocks run
RUN = {"python": "python", "py": "python", "bash": "bash", "sh": "bash", "shell": "bash"}
#: languages that are not code to run: file contents, output, diagrams
NOT_CODE = {"text", "toml", "json", "yaml", "csv", "markdown", "console-output", "output"}
MARKER = re.compile(r"^\s*<!--\s*(not run|slow)\s*:\s*(.*?)\s*-->\s*$")
FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([\w+-]*)\s*(.*)$")
#: what a block may use from the repository, linked into the folder the blocks run in
LINKED = ("scripts", "docs", "examples", ".venv-rllib")


@dataclass(frozen=True)
class Block:
    """One fenced block: its ``page``, 1-based ``line`` of the opening fence, ``language``,
    ``code`` (dedented to the fence) and ``marker`` ("not run", "slow" or "") with ``reason``."""

    page: str
    line: int
    language: str
    code: str
    marker: str = ""
    reason: str = ""

    @property
    def kind(self) -> str:
        return RUN.get(self.language, "")

    @property
    def where(self) -> str:
        return f"docs/{self.page}:{self.line}"


def nav_pages() -> list[str]:
    """The Markdown files of the site's nav, in nav order (paths relative to docs/)."""
    nav = yaml.safe_load((ROOT / "mkdocs.yml").read_text())["nav"]
    out = []

    def walk(item):
        if isinstance(item, str):
            out.append(item)
        elif isinstance(item, list):
            for x in item:
                walk(x)
        elif isinstance(item, dict):
            for x in item.values():
                walk(x)
    walk(nav)
    return [p for p in out if p.endswith(".md")]


def parse_blocks(text: str, page: str) -> list[Block]:
    """The fenced blocks of a Markdown page; a ValueError for a fence without a language, an
    unknown language, an unclosed fence or a marker without a reason."""
    lines = text.splitlines()
    blocks, k = [], 0
    while k < len(lines):
        m = FENCE.match(lines[k])
        if not m:
            k += 1
            continue
        indent, fence, language = len(m.group(1)), m.group(2), m.group(3).lower()
        if not language:
            raise ValueError(f"docs/{page}:{k + 1}: a code block without a language: give it "
                             f"one of {sorted(RUN)} (run by this test) or {sorted(NOT_CODE)}")
        if language not in RUN and language not in NOT_CODE:
            raise ValueError(f"docs/{page}:{k + 1}: language {language!r}; allowed: "
                             f"{sorted(RUN)} (run) or {sorted(NOT_CODE)} (not code)")
        end = k + 1
        while end < len(lines) and not (lines[end].strip().startswith(fence[0] * len(fence))
                                         and lines[end].strip().strip(fence[0]) == ""):
            end += 1
        if end == len(lines):
            raise ValueError(f"docs/{page}:{k + 1}: the code block is never closed")
        code = "\n".join(x[indent:] if x[:indent].strip() == "" else x for x in lines[k + 1:end])
        above = next((lines[j] for j in range(k - 1, -1, -1) if lines[j].strip()), "")
        mark = MARKER.match(above)
        marker, reason = (mark.group(1), mark.group(2)) if mark else ("", "")
        if mark and not reason:
            raise ValueError(f"docs/{page}:{k + 1}: '<!-- {marker}: -->' without a reason")
        blocks.append(Block(page, k + 1, language, code + "\n", marker, reason))
        k = end + 1
    return blocks


def page_blocks(page: str) -> list[Block]:
    return parse_blocks((DOCS / page).read_text(), page)


#: runs a page's blocks in order: Python in one namespace, bash in a subprocess
RUNNER = """\
import json, subprocess, sys, time, traceback
namespace = {"__name__": "__main__"}
start = time.perf_counter()
for block in json.load(open(sys.argv[1])):
    print(f"--- {block['where']} ({block['kind']}) at {time.perf_counter() - start:.1f} s",
          flush=True)
    if block["kind"] == "python":
        try:
            exec(compile(block["code"], block["where"], "exec"), namespace)
        except BaseException:
            traceback.print_exc()
            print(f"FAILED: the python block at {block['where']}", flush=True)
            sys.exit(1)
    else:
        done = subprocess.run(["bash", "-euo", "pipefail", "-c", block["code"]])
        if done.returncode:
            print(f"FAILED: the bash block at {block['where']} exited {done.returncode}",
                  flush=True)
            sys.exit(1)
print(f"--- done at {time.perf_counter() - start:.1f} s", flush=True)
"""


def run_blocks(blocks: list[Block], folder: Path) -> subprocess.CompletedProcess:
    """Run ``blocks`` in order in ``folder`` (a fresh one); the process's result."""
    for name in LINKED:
        if (ROOT / name).exists():
            (folder / name).symlink_to(ROOT / name)
    spec = folder / ".blocks.json"
    spec.write_text(json.dumps([{"where": b.where, "kind": b.kind, "code": b.code}
                                for b in blocks]))
    (folder / ".run_blocks.py").write_text(RUNNER)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]),
        MPLBACKEND="Agg")
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    return subprocess.run([sys.executable, ".run_blocks.py", str(spec)], cwd=folder, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


PAGES = nav_pages()


def _pages_with(markers: tuple[str, ...]) -> list[str]:
    """The pages with a code block marked with one of ``markers`` ("": unmarked)."""
    out = []
    for page in PAGES:
        try:
            if any(b.kind and b.marker in markers for b in page_blocks(page)):
                out.append(page)
        except ValueError:   # the parse test names the block
            pass
    return out


def test_the_nav_lists_existing_pages_and_every_page_parses():
    assert PAGES and len(PAGES) == len(set(PAGES))
    missing = [p for p in PAGES if not (DOCS / p).is_file()]
    assert not missing, f"pages in mkdocs.yml's nav that are not in docs/: {missing}"
    for page in PAGES:
        for block in page_blocks(page):   # a ValueError names the block
            assert block.kind or not block.marker, f"{block.where}: a marker on a non-code block"


def test_tutorials_run_their_code():
    """The tutorials and the getting-started page show code that runs (the Ray tutorial's
    in the slow test), not only commands."""
    for page in [p for p in PAGES if p.startswith("tutorials/")] + ["getting_started.md"]:
        run = [b for b in page_blocks(page) if b.kind and b.marker != "not run"]
        assert run, f"docs/{page}: no block of it runs"


def _check_run(page: str, tmp_path: Path, slow: bool):
    blocks = page_blocks(page)
    runnable = [b for b in blocks if b.kind and (b.marker == "" or (slow and b.marker == "slow"))]
    if not runnable:
        pytest.skip(f"docs/{page}: no code block to run "
                    + ("" if slow else "(slow ones run with -m slow)"))
    if slow:
        needs = [n for n in LINKED if any(n + "/" in b.code for b in runnable)
                 and not (ROOT / n).exists()]
        if needs:
            pytest.skip(f"docs/{page}: needs {needs} (e.g. bash scripts/setup_rllib.sh)")
    done = run_blocks(runnable, tmp_path)
    assert done.returncode == 0, (f"docs/{page}: a code block failed\n"
                                  + done.stdout[-6000:])


@pytest.mark.parametrize("page", _pages_with(("",)))
def test_code_blocks_run(page, tmp_path):
    _check_run(page, tmp_path, slow=False)


@pytest.mark.slow
@pytest.mark.parametrize("page", _pages_with(("slow",)))
def test_code_blocks_run_with_the_slow_ones(page, tmp_path):
    _check_run(page, tmp_path, slow=True)


def test_the_parser_refuses_what_would_be_skipped_silently(tmp_path):
    good = ("text\n\n<!-- not run: trains for hours -->\n```bash\nmimo-social train\n```\n\n"
            "  ```python\n  x = 1\n  ```\n\n<!-- slow: two minutes -->\n\n```sh\necho\n```\n"
            "```text\nout\n```\n")
    blocks = parse_blocks(good, "p.md")
    assert [(b.line, b.kind, b.marker, b.reason) for b in blocks] == [
        (4, "bash", "not run", "trains for hours"), (8, "python", "", ""),
        (14, "bash", "slow", "two minutes"), (17, "", "", "")]
    assert blocks[1].code == "x = 1\n"
    for bad, why in (("```\nmimo-social demo\n```\n", "without a language"),
                     ("```rust\nfn main() {}\n```\n", "language 'rust'"),
                     ("```python\nx = 1\n", "never closed"),
                     ("<!-- not run: -->\n```bash\nls\n```\n", "without a reason")):
        with pytest.raises(ValueError, match=why):
            parse_blocks(bad, "p.md")


def test_a_failing_block_fails_and_names_itself(tmp_path):
    blocks = [Block("p.md", 3, "python", "x = 41\n"), Block("p.md", 7, "bash", "echo ok\n"),
              Block("p.md", 9, "python", "assert x == 42, x\n")]
    done = run_blocks(blocks, tmp_path)
    assert done.returncode == 1 and "FAILED: the python block at docs/p.md:9" in done.stdout
    assert "AssertionError: 41" in done.stdout and "ok" in done.stdout
