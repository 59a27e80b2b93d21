"""Every Python code block a reader sees in the README and in the documentation runs as pasted.

A ```` ```python ```` block is code to paste and run: it must import what it uses and define
what it names. Each block runs in a fresh ``__main__`` namespace, unless it belongs to a
markdown-exec ``session`` (a tutorial's page, whose blocks a reader pastes in order): then it
runs after the earlier shown blocks of the same session on its page, in their namespace, and
in no other. Blocks that markdown-exec runs without showing them (``exec`` with no
``source``: they draw the page's figures) are run by the documentation build, not here; a
reader never pastes them, so a shown block may not lean on them either. Shell commands,
listings and output use another fence language (``bash``, ``text``, ``json``, ``py`` for
Python that needs a machine outside this one, such as a Dask scheduler).

Each page runs in one subprocess (imports paid once per page) from an empty folder, with
Matplotlib on its non-interactive backend; the page whose code starts worker processes
(``distributed.md``) is marked slow.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([^\s`]*)(.*)$")
ATTR = re.compile(r'(\w+)="([^"]*)"')


def fenced_blocks(page: Path) -> list[tuple[int, str, dict[str, str], str]]:
    """``(line, language, attributes, code)`` of every fenced block of ``page``."""
    lines = page.read_text(encoding="utf-8").splitlines()
    out, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if m:
            indent, fence, lang, rest = m.groups()
            j = i + 1
            while j < len(lines) and not lines[j].strip().startswith(fence):
                j += 1
            assert j < len(lines), f"{page.name}:{i + 1}: unclosed code fence"
            code = "\n".join(ln[len(indent):] for ln in lines[i + 1:j])
            out.append((i + 1, lang, dict(ATTR.findall(rest)), code + "\n"))
            i = j
        i += 1
    return out


def shown_python(page: Path) -> list[tuple[int, str | None, str]]:
    """``(line, session, code)`` of the Python blocks a reader of ``page`` sees."""
    return [(line, attrs.get("session"), code) for line, lang, attrs, code in fenced_blocks(page)
            if lang == "python" and ("exec" not in attrs or "source" in attrs)]


_RUN = r"""
import io, json, sys, traceback, types, contextlib
blocks = json.loads(sys.stdin.read())
sessions, failures = {}, []
for line, session, code in blocks:
    if session is None or session not in sessions:
        module = types.ModuleType("__main__")
        module.__builtins__ = __builtins__
        if session is not None:
            sessions[session] = module
    else:
        module = sessions[session]
    sys.modules["__main__"] = module  # what pickle finds for a function the block defines
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            exec(compile(code, f"block at line {line}", "exec"), module.__dict__)
    except BaseException:
        failures.append([line, traceback.format_exc(limit=-4)])
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")
print("RESULT" + json.dumps(failures))
"""

#: pages whose code starts worker processes (like the suite's Dask tests: slow)
_SLOW = {"distributed.md"}
_PAGES_WITH_CODE = [pytest.param(p, marks=[pytest.mark.slow] if p.name in _SLOW else [])
                    for p in PAGES if shown_python(p)]


@pytest.mark.parametrize("page", _PAGES_WITH_CODE, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_shown_python_block_runs_as_pasted(page, tmp_path):  # 3-8 s a page, warm
    blocks = shown_python(page)
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=os.pathsep.join(
        [str(ROOT / "src")] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
                               if p]))
    r = subprocess.run([sys.executable, "-c", _RUN], input=json.dumps(blocks), cwd=tmp_path,
                       env=env, capture_output=True, text=True, timeout=600)
    result = [ln for ln in r.stdout.splitlines() if ln.startswith("RESULT")]
    assert r.returncode == 0 and result, f"{page.name}: the runner failed:\n{r.stderr[-3000:]}"
    failures = json.loads(result[-1][len("RESULT"):])
    assert not failures, "\n".join(f"{page.relative_to(ROOT)}:{line}: the block fails when "
                                   f"pasted:\n{tb}" for line, tb in failures)


def test_the_checker_sees_the_blocks_it_should():
    # the README and the first tutorial have Python blocks, and the tutorial's hidden set-up
    # block (it imports the docs' figure helper) is not among those a reader pastes
    assert len(shown_python(ROOT / "README.md")) >= 6
    first = shown_python(ROOT / "docs" / "tutorials" / "first-estimate.md")
    assert first and all("_helpers" not in code for _, _, code in first)
    assert {s for _, s, _ in first} >= {"first"}


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_fence_names_its_language(page):
    # an unnamed fence is neither run here nor highlighted: Python hidden in it would escape
    # this check
    bare = [line for line, lang, _, _ in fenced_blocks(page) if not lang]
    assert not bare, f"{page.relative_to(ROOT)}: fences without a language at lines {bare}"
