"""The one place boundest makes progress bars, so that they all follow two rules.

* A bar is drawn on a terminal only (tqdm's own rule, ``disable=None``): standard error sent to
  a log, a pipe or a captured stream gets no carriage-return lines, whatever ``show`` says;
  ``show=False`` draws none anywhere.
* A bar is left on screen when it closes, at its total, or with the reason it stopped (the loop
  converged, became empty, hit its cap, or an exception ended it); it is never cleared halfway
  (``leave=False`` showed "11 % 10/90" as the last frame of a finished run).
"""

from __future__ import annotations

from types import TracebackType
from typing import Any


class Progress:
    """A tqdm bar, as a context manager: ``with Progress(show, desc=...) as bar: bar.update()``.

    Parameters
    ----------
    show : bool or None
        False: no bar. True: a bar at once; None: a bar once the loop has run ``delay`` seconds
        (2 s by default, so that short calls stay quiet). Either way on a terminal only.
    desc, unit : str
        The bar's label and the unit of its counter.
    total : int, optional
        The number of updates the loop makes; None for an open-ended loop (a counter: a cap on
        the iterations is not a forecast of how many there will be).
    delay : float, optional
        Seconds before a ``show=None`` bar appears.
    """

    def __init__(self, show: bool | None, *, desc: str | None, total: int | None = None,
                 unit: str = "it", delay: float = 2.0, **kwargs: Any) -> None:
        self.total = total
        self.why: str | None = None
        self.bar: Any = None
        if show is not False:
            from tqdm.auto import tqdm  # here, not at import: boundest's import stays light

            self.bar = tqdm(total=total, desc=desc, unit=unit, disable=None, leave=True,
                            delay=0.0 if show else delay, **kwargs)
            if self.bar.disable:  # not a terminal
                self.bar = None

    @property
    def n(self) -> int:
        """Updates so far (0 when no bar is drawn)."""
        return 0 if self.bar is None else int(self.bar.n)

    def update(self, n: int = 1) -> None:
        """Advance the bar by ``n``."""
        if self.bar is not None:
            self.bar.update(n)

    def set_postfix(self, **kw: Any) -> None:
        """Show ``key=value`` pairs after the counter (e.g. the last contraction)."""
        if self.bar is not None:
            self.bar.set_postfix(**kw)

    def stop(self, why: str) -> None:
        """Say why the loop stopped; shown after the counter when the bar closes."""
        self.why = why

    def close(self, exc: BaseException | None = None) -> None:
        """Close the bar, leaving its last frame: the total, or why it stopped short."""
        if self.bar is None:
            return
        why = self.why
        if exc is not None:
            why = "interrupted" if isinstance(exc, KeyboardInterrupt) else \
                f"stopped by {type(exc).__name__}"
        elif why is None and self.total is not None and self.bar.n != self.total:
            why = f"stopped at {self.bar.n} of {self.total}"
        if why:
            self.bar.postfix = f"{self.bar.postfix}, {why}" if self.bar.postfix else why
        self.bar.close()
        self.bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close(exc)
