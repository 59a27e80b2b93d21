"""The q-relaxed intersection of contractors (robust contraction with at most q outliers)."""

from __future__ import annotations

from collections.abc import Sequence as Seq

import numpy as np

from ..interval import Interval, intersect
from ..interval.relaxed import Method, _check_q, qinter_boxes
from .base import Contractor, _dimension, _empty_rows

__all__ = ["CtcQInter"]


class CtcQInter(Contractor):
    """Contract to the hull of the points that satisfy all the constraints but at most ``q``.

    Each contractor ``C_i`` is applied to the box ``X``; the result is the q-relaxed
    intersection of the ``N`` contracted boxes (``boundest.qinter_boxes``), intersected with
    ``X``. A point of ``X`` that satisfies at least ``N - q`` constraints lies in at least
    ``N - q`` of the ``C_i(X)`` (a contractor loses no solution), so it is kept: the contractor
    is sound for the set of points with at most ``q`` failed constraints (Jaulin's robust
    set-membership estimation with at most ``q`` outliers).

    Parameters
    ----------
    contractors : sequence of Contractor
        The ``N`` constraints, all of the same dimension.
    q : int
        The number of constraints allowed to **fail** (outliers), ``q >= 0``: ``q = 0`` is the
        plain intersection ``C_1 & ... & C_N`` done in parallel, ``q = N - 1`` the union
        ``C_1 | ... | C_N``. ``q >= N`` is accepted and means no contraction (every point
        satisfies at least ``N - q <= 0`` constraints). A contractor that empties a box counts
        as one of the ``q`` failures for that box.
    method : {"auto", "exact", "projection"}
        How the contracted boxes are combined (see ``qinter_boxes``): ``"exact"`` (the hull of
        the intersections of every ``N - q`` of them, ``C(N, q)`` subsets), ``"projection"``
        (the q-relaxed intersection of each component separately, cheaper and coarser) or
        ``"auto"`` (exact while ``C(N, q)`` is small). Both are sound.

    Notes
    -----
    **Convention for q.** boundest's ``q`` is the number of constraints that may fail, as in
    Jaulin's papers and in **Codac 2**, whose ``codac2::CtcQInter(q, ctcs)`` documents "q is the
    maximum number of constraints that may be violated" (``codac2_CtcQInter.h``; ``q`` comes
    first there, and Codac 2 requires ``q <= N``). **Codac 1** (its Python ``CtcQInter(list, q)``
    and ``CtcQInterProjF``, inherited from pyIbex/IBEX) documents ``q`` as "the number of
    contractors which have to intersect the result", i.e. the number that must *hold*. So
    ``CtcQInter(ctcs, q)`` here is ``codac2.CtcQInter(q, ctcs)`` and Codac 1's
    ``CtcQInter(ctcs, len(ctcs) - q)``.

    **Pavings.** For ``sivia``, ``CtcQInter(outer, q)`` contracts the set (``ctc_out``). Its
    complement, "at least ``q + 1`` constraints fail", is the q-relaxed intersection of the
    complements with ``N - q - 1`` failures allowed: ``ctc_in = CtcQInter(inner, N - q - 1)``
    where ``inner[i]`` contracts the complement of constraint ``i`` (e.g. the pairs returned by
    ``boundest.paving.separators``).

    The batch ``(..., n)`` is contracted at once: one call per contractor on the whole batch
    and one vectorised q-intersection, no loop over boxes.

    Examples
    --------
    >>> from boundest.ctc import CtcFwdBwd
    >>> from boundest.expr import Var
    >>> x = Var("x")
    >>> ctcs = [CtcFwdBwd([x.in_(Interval(a, b))], ["x"]) for a, b in [(0, 2), (1, 3), (8, 9)]]
    >>> CtcQInter(ctcs, 1)(Interval([-10], [10]))
    Interval([[1.0, 2.0]])
    """

    def __init__(self, contractors: Seq[Contractor], q: int, method: Method = "auto") -> None:
        ctcs = tuple(contractors)
        if not ctcs:
            raise ValueError("CtcQInter needs at least one contractor")
        if not all(isinstance(c, Contractor) for c in ctcs):
            raise TypeError("CtcQInter needs Contractor objects")
        if method not in ("auto", "exact", "projection"):
            raise ValueError(f"method must be 'auto', 'exact' or 'projection', got {method!r}")
        self.ctcs = ctcs
        self.q = _check_q(q)
        self.method: Method = method
        self.n = _dimension(ctcs)

    def contract(self, x: Interval) -> Interval:
        if x.ndim == 0:
            raise ValueError("CtcQInter contracts boxes (..., n), got a scalar interval")
        if self.q >= len(self.ctcs):
            return x.copy()
        parts = [_empty_rows(intersect(x, c.contract(x))) for c in self.ctcs]
        stacked = Interval.trusted(np.stack([p.lo for p in parts], axis=-2),
                                np.stack([p.hi for p in parts], axis=-2))
        return _empty_rows(intersect(x, qinter_boxes(stacked, self.q, self.method)))
