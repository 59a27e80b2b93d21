"""Progress bars tell the truth: a bar with a total ends exactly at it; an open-ended loop shows
a counter and the current contraction, never an iteration cap as its total; a bar that stops
short says why; and bars are drawn on a terminal only, never into a log."""

from __future__ import annotations

import io
import sys

import pytest

from boundest.estimation import discrete
from boundest.scenarios import jaulin2001 as jw


class _Bar:
    def __init__(self, total):
        self.total, self.n = total, 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        pass

    def close(self):
        pass


class _Terminal(io.StringIO):
    """Standard error as a terminal."""

    def isatty(self) -> bool:
        return True


def _terminal(monkeypatch) -> _Terminal:
    """Standard error replaced by a terminal; ``.getvalue()`` is what was drawn. Called in the
    test's body: pytest sets its own capture stream again between a fixture and the test."""
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    return term


def _last_frame(text: str) -> str:
    """What stays on screen: the last carriage-return-separated frame."""
    frames = [f for f in text.split("\r") if f.strip()]
    assert frames, "no bar drawn"
    return frames[-1].strip()


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


def test_propagation_counts_revisions_without_a_made_up_total(monkeypatch):
    terminal = _terminal(monkeypatch)
    from boundest.csp import propagate
    from boundest.scenarios import satellite as sat

    res = propagate(sat.build_model(sat.load(None, k_max=200)), progress=True, chunk=5_000,
                    mode="hc4")
    err = terminal.getvalue()
    assert res.consistent and "propagating" in err and "dirty=" in err
    # a counter ("48.1krev"), never "n/total |##  | 3%" with the revision budget as total
    assert "%" not in err and "|" not in err
    # left on screen, with why it stopped
    assert _last_frame(err).endswith("fixed point]"), _last_frame(err)


def test_the_clock_network_shows_its_counter(monkeypatch):
    terminal = _terminal(monkeypatch)
    from boundest.scenarios import drifting_clock as dc

    res = dc.solve(dt=0.1, progress=True)
    err = terminal.getvalue()
    assert not res.empty and "contraction=" in err and "it" in err
    assert "converged" in _last_frame(err) or "max_iter" in _last_frame(err)


def test_no_bar_is_drawn_when_standard_error_is_not_a_terminal(capfd):
    """A log, a pipe or the docs build's captured stream gets no carriage-return lines, even
    with ``progress=True`` (tqdm's own rule)."""
    from boundest.csp import propagate
    from boundest.parallel import map_chunked
    from boundest.scenarios import drifting_clock as dc
    from boundest.scenarios import satellite as sat

    propagate(sat.build_model(sat.load(None, k_max=200)), progress=True, chunk=5_000,
                    mode="hc4")
    dc.solve(dt=0.1, progress=True)
    jw.solve(jw.load(None), domains="boxes", progress=True)
    map_chunked(abs, range(8), progress=True, desc="items")
    err = capfd.readouterr().err
    assert "\r" not in err and "it/s" not in err and "%" not in err, err


def test_a_bar_with_a_total_is_left_at_its_total(monkeypatch):
    """Not cleared halfway (a finished run whose last frame read "11 % 10/90")."""
    terminal = _terminal(monkeypatch)
    from boundest.parallel import map_chunked

    assert map_chunked(abs, range(-45, 45), progress=True, desc="items") == \
        [abs(v) for v in range(-45, 45)]
    jw.solve(jw.load(None), domains="boxes", progress=True)
    frames = [_last_frame(part) for part in terminal.getvalue().split("\n") if part.strip()]
    assert len(frames) == 2, frames
    assert frames[0].startswith("items: 100%") and "90/90" in frames[0], frames[0]
    assert frames[1].startswith("RCSE + NCSE: 100%"), frames[1]


def _fails_on_seven(v: int) -> int:
    if v == 7:
        raise ValueError("seven")
    return v


def test_a_bar_that_stops_short_says_why(monkeypatch):
    terminal = _terminal(monkeypatch)
    from boundest.parallel import TaskError, map_chunked

    with pytest.raises(TaskError):
        map_chunked(_fails_on_seven, range(10), chunk=1, progress=True, desc="items")
    last = _last_frame(terminal.getvalue())
    assert "7/10" in last and last.endswith("stopped by TaskError]"), last


def test_an_open_ended_bar_says_it_hit_its_cap(monkeypatch):
    terminal = _terminal(monkeypatch)
    from boundest.scenarios import drifting_clock as dc

    res = dc.solve(dt=0.1, max_iter=1, progress=True)
    last = _last_frame(terminal.getvalue())
    assert res.iterations == 1 and last.endswith("max_iter=1 reached]"), last
