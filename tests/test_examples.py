"""Every script of ``examples/`` runs to its end and says that its result holds its truth.

The examples are what a user copies to start a problem, so they must keep working on the core
install: each runs in a subprocess from an empty folder, with the extras of the ``test``
install (mpmath, SciPy, hypothesis, ...) hidden, and must exit with 0 after printing its final
``OK: ...`` line (each script asserts that its sets contain its simulated truth first).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from boundest.commands import SCENARIOS

from .core_install import HIDE_EXTRAS

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
SCRIPTS = sorted(p.name for p in EXAMPLES.glob("*.py"))
_RUN = HIDE_EXTRAS + """
import runpy
sys.argv = [sys.argv[1]]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


@pytest.mark.parametrize("script", SCRIPTS)  # 1-4 s each on the 2-core machine
def test_example_runs_and_keeps_its_truth(script, tmp_path):
    r = subprocess.run([sys.executable, "-c", _RUN, str(EXAMPLES / script)], cwd=tmp_path,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, f"{script} exited with {r.returncode}:\n{r.stdout}{r.stderr}"
    lines = r.stdout.strip().splitlines()
    assert lines and lines[-1].startswith("OK: "), f"{script} did not end with OK:\n{r.stdout}"


def test_one_example_per_scenario():
    # every scenario of `boundest run` (SCENARIOS: name -> module, help) has the script of its
    # module's name, so that a new scenario without an example fails here
    missing = sorted(f"{module}.py" for module, _ in SCENARIOS.values()
                     if f"{module}.py" not in SCRIPTS)
    assert not missing, f"examples/ has no script for the scenario(s) {missing}"


def test_the_readme_lists_every_example():
    readme = (EXAMPLES / "README.md").read_text()
    missing = [s for s in SCRIPTS if f"python examples/{s}" not in readme]
    assert not missing, f"examples/README.md does not say how to run {missing}"
