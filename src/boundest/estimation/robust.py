"""A recursive set-membership observer robust to outliers (Jaulin's robust observer).

At step ``k`` the observer predicts its set, ``P_k = f(X_{k-1}, U_{k-1})``, contracts the
prediction with the new measurement, ``C_k = g_k^{-1}(Y_k) ∩ P_k``, and keeps in a sliding
window the images at time ``k`` of the last ``m`` such sets (each propagated by ``f`` with the
inputs since). Its set is the prediction intersected with the q-relaxed intersection of the
window, the points consistent with all but at most ``q`` of the last ``m`` measurements::

    X_k = P_k ∩ ⋂^{q}_{j = k-m+1..k} f^{k-j}(C_j)

**What the set guarantees.** If the true state is in ``X_{k-1}`` and at most ``q`` of the
window's measurements are outliers, the true state is in ``X_k`` (every inlier's set holds it).
By induction, ``x_k ∈ X_k`` whenever every window since the start (or the last restart) held at
most ``q`` outliers: that event, not the per-window binomial bound, is what the recursive set
is conditioned on. Its probability is at most the binomial bound ``P(at most q outliers in one
window)``, which :func:`window_probability` computes.

When more than ``q`` outliers hit a window the set may become empty: the step is reported and
the observer restarts from a given box with an empty window (its next sets depend only on the
measurements after the restart). It never keeps an empty set silently. A wrong but non-empty set
cannot be detected.

Everything is batched: a leading batch axis runs many independent missions at once (the same
inputs or one input box per mission), which is how a Monte Carlo check runs. This is the
observer for any model given as Python callables; the pool robot has a compiled one that also
smooths inside its window (:mod:`boundest.scenarios.pool_observer`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from math import comb
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..interval import Interval, qinter_boxes

__all__ = ["ObserverStep", "RobustObserver", "window_probability"]


def window_probability(m: int, q: int, p: float) -> float:
    """``P(at most q outliers among m measurements)`` for independent outliers of
    probability ``p``: ``sum_{i <= q} C(m, i) p^i (1 - p)^(m - i)`` (1 when ``q >= m``)."""
    if m < 0 or q < 0 or not 0.0 <= p <= 1.0:
        raise ValueError(f"need m >= 0, q >= 0 and 0 <= p <= 1, got m={m}, q={q}, p={p}")
    return float(sum(comb(m, i) * p**i * (1.0 - p) ** (m - i) for i in range(min(q, m) + 1)))


@dataclass
class ObserverStep:
    """The result of one update.

    Attributes
    ----------
    box : Interval, shape (..., n)
        The set ``X_k`` (after a restart: the restart box).
    rejected : ndarray of int, shape (...)
        Measurements of the window whose sets miss ``X_k`` (detected outliers).
    empty : ndarray of bool, shape (...)
        Whether ``X_k`` came out empty (more than ``q`` outliers, or a model error); those rows
        restarted.
    window : int
        Measurements in the window.
    """

    box: Interval
    rejected: NDArray[np.intp]
    empty: NDArray[np.bool_]
    window: int


class RobustObserver:
    """The recursive q-relaxed observer over boxes (see the module docstring).

    Parameters
    ----------
    predict : callable
        ``predict(X, u) -> Interval``: a sound image of boxes ``X`` of shape ``(..., w, n)`` or
        ``(..., n)`` by one step of the dynamics with the input ``u`` (broadcast against the
        leading axes).
    observe : callable
        ``observe(X, y) -> Interval``: ``X`` contracted with the measurement ``y`` (any object
        the callable understands), soundly.
    x0 : Interval, shape (..., n)
        The initial set (leading axes: a batch of independent missions).
    m, q : int
        Window length and the number of outliers allowed in it.
    restart : Interval, shape (n,), optional
        The set to restart from when ``X_k`` is empty (default: ``x0``).

    Examples
    --------
    A constant in [0, 10] measured three times, one outlier allowed: one measurement says
    nothing (it may be the outlier), two give their union, three the points in two of them.

    >>> obs = RobustObserver(lambda x, u: x + u, lambda x, y: x & y,
    ...                      Interval([0.0], [10.0]), m=3, q=1)
    >>> [obs.update(0.0, Interval([a], [a + 1.0])).box for a in (2.0, 8.0, 2.5)]
    [Interval([[0.0, 10.0]]), Interval([[2.0, 9.0]]), Interval([[2.5, 3.0]])]
    """

    def __init__(self, predict: Callable[[Interval, Any], Interval],
                 observe: Callable[[Interval, Any], Interval], x0: Interval, m: int, q: int,
                 restart: Interval | None = None) -> None:
        if m < 1 or q < 0:
            raise ValueError(f"need a window m >= 1 and q >= 0, got m={m}, q={q}")
        self.predict, self.observe, self.m, self.q = predict, observe, int(m), int(q)
        self.restart_box = x0 if restart is None else restart
        self.x = x0.copy()
        self.k = -1
        shape = (*x0.shape[:-1], 0, x0.shape[-1])
        self.hyp = Interval.empty(shape)

    def update(self, u: Any, y: Any) -> ObserverStep:
        """Advance to the next measurement ``y`` (``u``: the input applied since the previous
        one; ignored at the first update, whose prediction is ``x0``)."""
        if self.k >= 0:
            pred = self.predict(self.x, u)
            hyp = self.predict(self.hyp, _at_window(u)) if self.hyp.shape[-2] else self.hyp
        else:
            pred, hyp = self.x, self.hyp
        new = self.observe(pred, y)
        stack = Interval.trusted(np.concatenate([hyp.lo, new.lo[..., None, :]], axis=-2),
                              np.concatenate([hyp.hi, new.hi[..., None, :]], axis=-2))
        if stack.shape[-2] > self.m:
            stack = stack[..., 1:, :]
        x = pred & qinter_boxes(stack, self.q, method="projection")
        empty = np.isnan(x.lo).any(axis=-1)
        with np.errstate(invalid="ignore"):
            miss = ((stack.hi < x.lo[..., None, :]) | (stack.lo > x.hi[..., None, :])
                    | np.isnan(stack.lo)).any(axis=-1)
        rejected = np.where(empty, 0, miss.sum(axis=-1))
        if empty.any():  # restart those rows from the restart box, with a neutral window
            rb = np.broadcast_to(self.restart_box.lo, x.shape), np.broadcast_to(
                self.restart_box.hi, x.shape)
            x = Interval.trusted(np.where(empty[..., None], rb[0], x.lo),
                              np.where(empty[..., None], rb[1], x.hi))
            e = empty[..., None, None]
            stack = Interval.trusted(np.where(e, -np.inf, stack.lo), np.where(e, np.inf, stack.hi))
        self.x, self.hyp, self.k = x, stack, self.k + 1
        return ObserverStep(x, rejected, empty, stack.shape[-2])


def _at_window(u: Any) -> Any:
    """An input broadcast against ``(..., w, n)`` window boxes: a new axis before the last."""
    if isinstance(u, Interval) and u.ndim >= 1:
        return u[..., None, :]
    if isinstance(u, np.ndarray) and u.ndim >= 1:
        return u[..., None, :]
    return u
