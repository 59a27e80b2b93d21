"""Progress bars tell the truth: a bar with a total ends exactly at it; an open-ended loop shows
a counter and the current contraction, never an iteration cap as its total."""

from __future__ import annotations

import pytest

from boundest.estimation import discrete
from boundest.scenarios import jaulin2001 as jw


class _Bar:
    def __init__(self, total):
        self.total, self.n = total, 0

    def close(self):
        pass


@pytest.mark.parametrize(("domains", "eps"), [("boxes", 0.01), ("subpavings", 0.2)])
def test_the_estimators_bars_end_at_their_totals(monkeypatch, domains, eps):
    bars = []

    def fake(total, desc, show):
        bar = _Bar(total)
        bars.append((desc, bar))

        def tick():
            bar.n += 1
        return tick, bar

    monkeypatch.setattr(discrete, "_progress", fake)
    jw.solve(jw.load(None), domains=domains, eps=eps, progress=True)
    kw = dict(x0=jw.FRAME if domains == "subpavings" else None, domains=domains, eps=eps,
              progress=True)
    discrete.rcse(jw.system(), jw.load(None), **kw)
    discrete.ncse(jw.system(), jw.load(None), **kw)
    assert [d for d, _ in bars] == ["RCSE + NCSE", "RCSE", "NCSE"]
    for desc, bar in bars:
        assert bar.n == bar.total, (desc, bar.n, bar.total)


def test_propagation_counts_revisions_without_a_made_up_total(capsys):
    from boundest.csp import propagate
    from boundest.scenarios import satellite as sat

    res = propagate(sat.build_model(sat.load(None, k_max=200)), progress=True, chunk=5_000)
    err = capsys.readouterr().err
    assert res.consistent and "propagating" in err and "dirty=" in err
    # a counter ("48.1krev"), never "n/total |##  | 3%" with the revision budget as total
    assert "%" not in err and "|" not in err


def test_the_clock_network_shows_its_counter(capsys):
    from boundest.scenarios import drifting_clock as dc

    res = dc.solve(dt=0.1, progress=True)
    err = capsys.readouterr().err
    assert not res.empty and "contraction=" in err and "it" in err
