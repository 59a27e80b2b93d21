"""Figures the documentation states are kept true by a record or by nothing at all.

A count of tests changes with every commit, so no page states one. The start-up times
``docs/getting-started.md`` quotes are those of ``benchmarks/results/startup.json``, with the
machine and the load average of that record: rerunning ``benchmarks/bench_startup.py`` makes
this test fail until the page says what the new record says.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def _prose(page: Path) -> str:
    return " ".join(page.read_text(encoding="utf-8").split())


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_page_states_a_count_of_tests(page):
    found = re.findall(r"\b\d[\d,]*\s+(?:\w+\s+)?tests\b", _prose(page))
    assert not found, f"{page.relative_to(ROOT)} states {found}: such a count goes stale"


def test_getting_started_quotes_the_startup_record():
    record = json.loads((ROOT / "benchmarks" / "results" / "startup.json").read_text())
    first = record["readme_first_command"]
    sat = record["commands"]["satellite"]
    loads = [record["started_loadavg"], record["finished_loadavg"]]
    loads += [s["loadavg_before"] for s in first["steps"].values()]
    text = _prose(ROOT / "docs" / "getting-started.md")
    cpu = " ".join(record["machine"]["cpu"].replace("(R)", "").split()[:2])  # Intel Xeon
    expected = [
        f"{record['machine']['cores']}-core {cpu}",
        f"load average of {min(loads):.1f} to {max(loads):.1f}",
        f"the whole command took {first['total_s']:.1f} s",
        f"{first['steps']['pip_install']['wall_s']:.1f} s of it `pip install`",
        f"{first['steps']['run_satellite']['wall_s']:.1f} s the satellite",
        f"the satellite's first run took {sat['cold_without_archive']['wall_s']:.1f} s",
        "`benchmarks/results/startup.json`",
    ]
    missing = [e for e in expected if e not in text]
    assert not missing, f"getting-started.md does not say what the record says: {missing}"
