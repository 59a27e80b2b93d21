"""A contractor network over intervals, boxes and tubes, contracted to a fixed point.

Domains are mutable: tubes are contracted in place by their contractors, intervals and boxes
have their bound arrays overwritten. The network applies every contractor in the order they were
added, once per iteration, until no domain's total width decreases by more than ``rel_eps``
(relative) in an iteration and no infinite bound became finite, or ``max_iter`` iterations
ran, or a domain became empty. The rule is per domain: a small box (a landmark, a measurement
time) that still shrinks keeps the network going even beside a long tube that no longer does.
"""

from __future__ import annotations

import time
from collections.abc import Sequence as Seq
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from .._progress import Progress
from ..ctc import Contractor
from ..interval import Interval
from .tube import Tube

__all__ = ["ContractorNetwork", "NetworkReport"]

Domain = Tube | Interval


class TubeContractor(Protocol):
    def contract(self, *domains: Any) -> Any: ...


@dataclass(repr=False)
class NetworkReport:
    """What a call to :meth:`ContractorNetwork.contract` did.

    ``contraction[k]`` is the largest relative decrease, over the domains, of a domain's total
    finite width in iteration ``k`` (for a tube: the widths of its slices times their durations
    plus its gates' widths; for an interval or box: its widths), ``newly_bounded[k]`` the
    number of bounds that stopped being infinite.
    """

    iterations: int = 0
    contraction: list[float] = field(default_factory=list)
    newly_bounded: list[int] = field(default_factory=list)
    empty: bool = False
    converged: bool = False
    time_s: float = 0.0

    def __repr__(self) -> str:
        last = f"{self.contraction[-1]:.3g}" if self.contraction else "none"
        return (f"NetworkReport(iterations={self.iterations}, converged={self.converged}, "
                f"empty={self.empty}, last_contraction={last}, time_s={self.time_s:.3g})")


class ContractorNetwork:
    """Contractors with their domains, propagated to a fixed point.

    Examples
    --------
    >>> from boundest import Interval
    >>> from boundest.tube import CtcDeriv
    >>> x = Tube.constant(0, 1, 10, Interval.entire())
    >>> x.gates[0] = Interval(0, 0)
    >>> v = Tube.constant(0, 1, 10, Interval(-1, 1))
    >>> cn = ContractorNetwork()
    >>> cn.add(CtcDeriv(), [x, v])
    >>> cn.contract().iterations
    2
    """

    def __init__(self) -> None:
        self._items: list[tuple[Any, list[Domain]]] = []

    def add(self, ctc: TubeContractor | Contractor, domains: Seq[Domain]) -> None:
        """Add a contractor over ``domains``: a tube contractor (``CtcDeriv``, ``CtcEval``,
        ``CtcSlices`` or any object whose ``contract(*domains)`` contracts them in place), or a
        box ``Contractor`` over one ``Interval`` box (its result is written back in place)."""
        domains = list(domains)
        for d in domains:
            if not isinstance(d, (Tube, Interval)):
                raise ValueError(f"network domains are tubes or intervals, got {d!r}")
        if isinstance(ctc, Contractor) and (len(domains) != 1 or isinstance(domains[0], Tube)):
            raise ValueError("a box Contractor takes exactly one Interval box as its domain")
        if not (isinstance(ctc, Contractor) or callable(getattr(ctc, "contract", None))):
            raise ValueError(f"not a contractor: {ctc!r}")
        self._items.append((ctc, domains))

    @property
    def domains(self) -> list[Domain]:
        seen: dict[int, Domain] = {}
        for _, doms in self._items:
            for d in doms:
                seen.setdefault(id(d), d)
        return list(seen.values())

    def _widths(self) -> list[np.ndarray]:
        """Widths of each domain: slices (times their durations) and gates of a tube, the
        bounds of an interval; a measure for the stopping rule only (rounded to nearest; NaN
        for empty sets)."""
        parts = []
        with np.errstate(invalid="ignore"):
            for d in self.domains:
                if isinstance(d, Tube):
                    w = (d.slices.hi - d.slices.lo).reshape(d.n_slices, -1)
                    parts.append(np.concatenate([(w * np.diff(d.t)[:, None]).ravel(),
                                                 (d.gates.hi - d.gates.lo).ravel()]))
                else:
                    parts.append(np.atleast_1d(d.hi - d.lo).ravel())
        return parts

    def contract_once(self) -> bool:
        """Apply every contractor once; ``False`` as soon as a domain is empty."""
        for ctc, doms in self._items:
            if isinstance(ctc, Contractor):
                box = doms[0]
                out = ctc(box)
                box.lo[...], box.hi[...] = out.lo, out.hi
            else:
                ctc.contract(*doms)
            if any(d.is_empty() if isinstance(d, Tube) else bool(np.isnan(d.lo).any())
                   for d in doms):
                return False
        return True

    def contract(self, rel_eps: float = 1e-4, max_iter: int = 100,
                 progress: bool | None = None) -> NetworkReport:
        """Propagate to a fixed point.

        Parameters
        ----------
        rel_eps : float
            Stop when an iteration decreases the total finite width by less than this fraction
            and bounds no infinite bound.
        max_iter : int
            Stop after this many iterations.
        progress : bool, optional
            Show a progress bar (on a terminal only): ``None`` shows it only for runs longer
            than 2 s.
        """
        if not 0.0 <= rel_eps < 1.0 or max_iter < 1:
            raise ValueError(f"need 0 <= rel_eps < 1 and max_iter >= 1, got {rel_eps}, "
                             f"{max_iter}")
        report = NetworkReport()
        start = time.perf_counter()
        before = self._widths()
        # no total: the number of iterations to the fixed point is not known in advance (the
        # cap is not a forecast); the bar counts iterations and shows the last contraction
        with Progress(progress, desc="contractor network") as bar:
            while report.iterations < max_iter:
                ok = self.contract_once()
                report.iterations += 1
                bar.update(1)
                if not ok:
                    bar.stop("empty: the constraints are inconsistent")
                    report.empty = True
                    report.contraction.append(1.0)
                    report.newly_bounded.append(0)
                    break
                after = self._widths()
                # widths only shrink: what was finite stays finite (or becomes NaN: empty)
                ratio, bounded = 0.0, 0
                for wb, wa in zip(before, after, strict=True):
                    fin_b = np.isfinite(wb)
                    vb = float(np.sum(wb, where=fin_b))
                    va = float(np.sum(wa, where=fin_b))
                    if vb > 0:
                        ratio = max(ratio, (vb - va) / vb)
                    bounded += int(np.count_nonzero(np.isfinite(wa))) - int(np.count_nonzero(fin_b))
                report.contraction.append(ratio)
                report.newly_bounded.append(bounded)
                bar.set_postfix(contraction=f"{ratio:.2e}", stop_below=f"{rel_eps:.0e}")
                before = after
                if ratio < rel_eps and bounded == 0:
                    report.converged = True
                    bar.stop("converged")
                    break
            else:
                bar.stop(f"max_iter={max_iter} reached")
        report.time_s = time.perf_counter() - start
        return report
