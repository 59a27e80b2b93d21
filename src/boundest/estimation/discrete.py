"""Causal and non-causal set state estimation of Jaulin et al. 2001 (section 4): CSE, RCSE and NCSE.

The system is ``x_k = f_k(x_{k-1})``, ``y_k = g_k(x_k)``, ``k = 1..K``. Its SCSP (Jaulin et al. 2001
eq. 20) is a tree: the chain ``x_0 - x_1 - ... - x_K`` with a leaf ``y_k`` on each ``x_k``. The
estimators are FALL/CLIMB schedules on it (``boundest.csp.tree``), with the local operators of
``boundest.estimation.setops`` on one of two kinds of domains:

``domains="boxes"``       hull consistency by forward-backward contractors; fast; batched: the
                          measurements may carry leading batch dimensions ``(..., K, ny)`` (one
                          independent problem each, e.g. many simulated runs at once);
``domains="subpavings"``  the optimal set estimators of Jaulin et al. 2001 (up to the precision
``eps``).

Example (Jaulin et al. 2001 equation 21, three steps from x(0) = (0, 0), boxes):

>>> import boundest as bd
>>> sys = DiscreteSystem(lambda x: [3 * bd.sin(x[0] + x[1]), 3 * bd.cos(x[0] + x[1])],
...                      lambda x: [abs(x[0])], nx=2, ny=1)
>>> y = bd.Interval([[-0.1], [0.32], [1.58]], [[0.1], [0.52], [1.78]])
>>> est = ncse(sys, y, x0=bd.Interval([-0.5, -0.5], [0.5, 0.5]))
>>> bool(est.hull()[1].contains([0.0, 3.0]).all())  # x(1) = (3 sin 0, 3 cos 0)
True
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._progress import Progress
from ..csp.tree import Arc, TreeSCSP
from ..ctc.base import _empty_rows
from ..interval import Interval
from ..paving import Subpaving
from .maps import Map
from .setops import BoxSets, Domain, PavingSets

__all__ = ["ChainEstimate", "DiscreteSystem", "cse", "ncse", "rcse", "rcse_ncse"]

Fn = Callable[[Sequence[Any]], Any]


class DiscreteSystem:
    """``x_k = f_k(x_{k-1})``, ``y_k = g_k(x_k)`` with ``x`` in ``R^nx`` and ``y`` in ``R^ny``.

    Parameters
    ----------
    f, g : callable or sequence of callables
        ``f(x) -> [components of the next state]``, ``g(x) -> [components of the output]``,
        written with arithmetic and boundest's elementary functions (``boundest.sin``, ``abs``)
        so that they accept intervals and expressions alike. A sequence gives one function per
        step ``k = 1..K`` (time-varying system).
    nx, ny : int
        State and output dimensions.
    """

    def __init__(self, f: Fn | Sequence[Fn], g: Fn | Sequence[Fn], nx: int, ny: int) -> None:
        self.nx, self.ny = nx, ny
        self._f = self._maps(f, nx, nx, "f")
        self._g = self._maps(g, nx, ny, "g")

    @staticmethod
    def _maps(h: Fn | Sequence[Fn], n_in: int, n_out: int, name: str) -> Map | list[Map]:
        if callable(h):
            return Map(h, n_in, n_out, name)
        return [Map(hk, n_in, n_out, f"{name}_{k}") for k, hk in enumerate(h, start=1)]

    def _at(self, maps: Map | list[Map], k: int, K: int, name: str) -> Map:
        if isinstance(maps, Map):
            return maps
        if len(maps) != K:
            raise ValueError(f"{len(maps)} functions {name}_k given for K = {K} steps")
        return maps[k - 1]

    def f(self, k: int, K: int) -> Map:
        """The map of ``x_k = f_k(x_{k-1})``."""
        return self._at(self._f, k, K, "f")

    def g(self, k: int, K: int) -> Map:
        """The map of ``y_k = g_k(x_k)``."""
        return self._at(self._g, k, K, "g")


@dataclass
class ChainEstimate:
    """Domains of ``x_0..x_K`` and ``y_1..y_K`` after an estimator.

    ``x[k]`` is a box ``Interval (..., nx)`` or a ``Subpaving`` (or a box while unbounded);
    ``y[k - 1]`` the domain of ``y_k``. For RCSE, ``x[k]`` is the causal set at time ``k``.
    """

    x: list[Domain]
    y: list[Domain]
    domains: str
    time_s: float
    stats: dict

    def __repr__(self) -> str:
        """Counts and timing, not the domains (``x``, ``y`` hold them)."""
        boxes = sum(len(d) if isinstance(d, Subpaving) else int(np.prod(d.shape[:-1]))
                    for d in self.x)
        return (f"ChainEstimate(K={len(self.x) - 1}, domains={self.domains!r}, "
                f"boxes={boxes}, time_s={self.time_s:.3g})")

    def hull(self) -> Interval:
        """Interval hulls of the ``x`` domains, shape ``(..., K + 1, nx)``."""
        hs = [d.hull() if isinstance(d, Subpaving) else d for d in self.x]
        shape = np.broadcast_shapes(*(h.shape for h in hs))
        return Interval.trusted(np.stack([np.broadcast_to(h.lo, shape) for h in hs], axis=-2),
                             np.stack([np.broadcast_to(h.hi, shape) for h in hs], axis=-2))


def _xn(k: int) -> tuple[str, int]:
    return ("x", k)


def _yn(k: int) -> tuple[str, int]:
    return ("y", k)


def _chain(system: DiscreteSystem, K: int, ops: BoxSets | PavingSets,
           tick: Callable[[], None]) -> TreeSCSP:
    """The SCSP of Jaulin et al. 2001 eq. 20 with the local operators of ``ops``."""
    arcs = []

    def arc(a: tuple, b: tuple, m: Map) -> Arc:  # b = m(a)
        def toward_a(va: Domain, vb: Domain) -> Domain:
            tick()
            return ops.toward_in(m, va, vb)

        def toward_b(vb: Domain, va: Domain) -> Domain:
            tick()
            return ops.toward_out(m, vb, va)
        return Arc(a, b, toward_a, toward_b)

    for k in range(1, K + 1):
        arcs.append(arc(_xn(k - 1), _xn(k), system.f(k, K)))
    for k in range(1, K + 1):  # after the f arcs: FALL contracts x_k by y_k before x_{k-1}
        arcs.append(arc(_xn(k), _yn(k), system.g(k, K)))
    names = [_xn(k) for k in range(K + 1)] + [_yn(k) for k in range(1, K + 1)]
    return TreeSCSP(names, arcs)


def _setup(system: DiscreteSystem, y: Interval, x0: Interval | None, x_prior: Interval | None,
           y_prior: Interval | None, domains: str, eps: float, max_boxes: int
           ) -> tuple[int, BoxSets | PavingSets, list[Interval], list[Interval], list[Interval]]:
    if not isinstance(y, Interval) or y.ndim < 2 or y.shape[-1] != system.ny:
        raise ValueError(f"y must be an Interval of shape (..., K, {system.ny}), got "
                         f"{getattr(y, 'shape', type(y).__name__)}")
    K = y.shape[-2]
    if K < 1:
        raise ValueError("y holds no measurement (K = 0)")
    if domains == "boxes":
        ops: BoxSets | PavingSets = BoxSets()
    elif domains == "subpavings":
        if y.ndim != 2:
            raise ValueError(f"subpaving domains take one problem: y of shape (K, ny), got "
                             f"{y.shape}")
        ops = PavingSets(eps=eps, max_boxes=max_boxes)
    else:
        raise ValueError(f"domains must be 'boxes' or 'subpavings', got {domains!r}")

    def per_step(prior: Interval | None, n: int, count: int, what: str) -> list[Interval]:
        if prior is None:
            return [Interval.entire(n)] * count
        if not isinstance(prior, Interval) or prior.shape[-1] != n:
            raise ValueError(f"{what} must be an Interval of shape (..., {n}) or (..., "
                             f"{count}, {n}), got {getattr(prior, 'shape', prior)!r}")
        if prior.ndim >= 2 and prior.shape[-2] == count and prior.ndim > (y.ndim - 2) + 1:
            return [prior[..., k, :] for k in range(count)]
        return [prior] * count

    xs = per_step(x_prior, system.nx, K + 1, "x_prior")
    if x0 is not None:
        if not isinstance(x0, Interval) or x0.shape[-1] != system.nx:
            raise ValueError(f"x0 must be an Interval of shape (..., {system.nx}), got "
                             f"{getattr(x0, 'shape', x0)!r}")
        xs[0] = _empty_rows(xs[0] & x0)
    ys = per_step(y_prior, system.ny, K, "y_prior")
    meas = [y[..., k, :] for k in range(K)]
    if domains == "subpavings":
        if any(p.ndim != 1 for p in (*xs, *ys)):
            raise ValueError("subpaving domains take priors of shape (n,) or (K + 1, n)")
        ops.informative_priors = not all(bool(np.all(d.is_entire())) for d in (*xs[1:], *ys))
        # bound the state priors by the interval images of the previous ones (a consequence of
        # the constraints, so sound): a bounded domain is paved, so that a reciprocal image
        # g^-1(Y_k) keeps its shape instead of its hull
        for k in range(1, K + 1):
            xs[k] = _empty_rows(xs[k] & system.f(k, K)(xs[k - 1]))
    return K, ops, xs, ys, meas


def _progress(total: int, desc: str, show: bool) -> tuple[Callable[[], None], Progress]:
    """A tick per local operator call and its bar; ``total`` must be the exact number of calls
    (``_calls``), so that the bar ends at its total."""
    bar = Progress(show, desc=desc, total=total, unit="op")
    return bar.update, bar


def _calls(K: int, ops: BoxSets | PavingSets, estimator: str) -> int:
    """Local operator calls of ``ncse``/``rcse`` on the chain of ``K`` steps (``2K`` arcs):
    FALL-CLIMB contracts every arc twice (``4K``); RCSE runs it on the priors when ``_initial``
    does, then three operators per step."""
    if estimator == "ncse":
        return 4 * K
    initial = not (isinstance(ops, PavingSets) and not ops.informative_priors)
    return 3 * K + (4 * K if initial else 0)


def ncse(system: DiscreteSystem, y: Interval, *, x0: Interval | None = None,
        x_prior: Interval | None = None,
         y_prior: Interval | None = None, domains: str = "boxes", eps: float = 0.01,
         max_boxes: int = 2_000_000, progress: bool = False) -> ChainEstimate:
    """Non-causal state estimator NCSE (Jaulin et al. 2001 section 4): FALL-CLIMB from ``x_K``.

    Parameters
    ----------
    system : DiscreteSystem
    y : Interval, shape (..., K, ny)
        The measurement uncertainty sets ``Y_k = phi(y_k^m)``, k = 1..K.
    x0 : Interval, shape (..., nx), optional
        Prior domain of ``x_0`` (default ``R^nx``). With subpavings a domain stays a box while
        it is unbounded: give a bounded ``x0`` to pave ``x_0`` and get optimal images.
    x_prior, y_prior : Interval, optional
        Prior domains (state and output constraints): one box for every k, or one per k
        (``(..., K + 1, nx)`` / ``(..., K, ny)``); default ``R^n``.
    domains : {"boxes", "subpavings"}
    eps, max_boxes : subpaving precision and per-operator box budget (``PavingSets``).
    progress : show a progress bar over the local operators (on a terminal only).

    Returns
    -------
    ChainEstimate
        The contracted domains of every ``x_k`` and ``y_k`` given all the measurements.
    """
    K, ops, xs, ys, meas = _setup(system, y, x0, x_prior, y_prior, domains, eps, max_boxes)
    tick, bar = _progress(_calls(K, ops, "ncse"), "NCSE", progress)
    tree = _chain(system, K, ops, tick)
    t0 = time.perf_counter()
    doms: dict = {_xn(k): xs[k] for k in range(K + 1)}
    doms.update({_yn(k): ops.intersect(ys[k - 1], meas[k - 1]) for k in range(1, K + 1)})
    with bar:
        doms = tree.fall_climb(doms, root=_xn(K))
    return ChainEstimate([doms[_xn(k)] for k in range(K + 1)],
                         [doms[_yn(k)] for k in range(1, K + 1)], ops.name,
                         time.perf_counter() - t0, _stats(ops))


def _stats(ops: BoxSets | PavingSets) -> dict:
    return dict(ops.stats) if isinstance(ops, PavingSets) else {}


def _initial(tree: TreeSCSP, ops: BoxSets | PavingSets, xs: list, ys: list, K: int) -> dict:
    """CSE/RCSE steps 1-2: FALL-CLIMB on the priors. With subpavings it is skipped when every
    prior given but ``x_0``'s is the whole space: it then only computes the images ``f^k(X_0)`` (and
    preimages of them), which the recursion recomputes inside tighter sets, at a cost in boxes
    proportional to the area of ``X_0``."""
    doms: dict = {_xn(k): xs[k] for k in range(K + 1)}
    doms.update({_yn(k): ys[k - 1] for k in range(1, K + 1)})
    if isinstance(ops, PavingSets) and not ops.informative_priors:
        return doms
    return tree.fall_climb(doms, root=_xn(K))


def rcse(system: DiscreteSystem, y: Interval, *, x0: Interval | None = None,
        x_prior: Interval | None = None,
         y_prior: Interval | None = None, domains: str = "boxes", eps: float = 0.01,
         max_boxes: int = 2_000_000, progress: bool = False) -> ChainEstimate:
    """Recursive causal state estimator RCSE (Jaulin et al. 2001 section 4).

    Same parameters as ``ncse``. ``x[k]`` of the result is the causal set of ``x_k`` given
    ``y_1..y_k`` (``x[0]``: given none), ``y[k - 1]`` that of ``y_k``; both are consistent with
    the whole SCSP at time ``k`` (Jaulin et al. 2001, Theorem 8).
    """
    return rcse_ncse(system, y, x0=x0, x_prior=x_prior, y_prior=y_prior, domains=domains,
                     eps=eps, max_boxes=max_boxes, progress=progress, smooth=False)[0]


def rcse_ncse(system: DiscreteSystem, y: Interval, *, x0: Interval | None = None,
              x_prior: Interval | None = None, y_prior: Interval | None = None,
              domains: str = "boxes", eps: float = 0.01, max_boxes: int = 2_000_000,
              progress: bool = False, smooth: bool = True
              ) -> tuple[ChainEstimate, ChainEstimate | None]:
    """RCSE, then NCSE from its domains, at the cost of RCSE and one CLIMB.

    Same parameters as ``ncse``. After RCSE every ``x_k`` has been contracted by its sons
    toward the root ``x_K`` (``y_k``, then ``x_{k-1}``, which RCSE no longer changes), in the
    order in which FALL from ``x_K`` contracts them: the domains are up-consistent, what FALL
    computes, so CLIMB from ``x_K`` alone completes NCSE (Jaulin et al. 2001, Theorem 6). On
    subpavings with no prior but ``x0`` the ``x`` sets are those of ``ncse``, in half the time.
    Returns ``(rcse, ncse)``; ``ncse`` is None when ``smooth`` is False. The time of the NCSE
    estimate is that of the RCSE plus the CLIMB.
    """
    K, ops, xs, ys, meas = _setup(system, y, x0, x_prior, y_prior, domains, eps, max_boxes)
    calls = _calls(K, ops, "rcse") + (2 * K if smooth else 0)
    tick, bar = _progress(calls, "RCSE + NCSE" if smooth else "RCSE", progress)
    tree = _chain(system, K, ops, tick)
    arcs = {(a.a, a.b): a for a in tree.arcs}
    t0 = time.perf_counter()
    with bar:
        doms = _initial(tree, ops, xs, ys, K)
        out_x, out_y = [doms[_xn(0)]], []
        for k in range(1, K + 1):
            doms[_yn(k)] = ops.intersect(doms[_yn(k)], meas[k - 1])           # step 5
            doms[_xn(k)] = arcs[(_xn(k), _yn(k))].contract(_xn(k), doms)         # step 6
            doms[_xn(k)] = arcs[(_xn(k - 1), _xn(k))].contract(_xn(k), doms)
            doms[_yn(k)] = arcs[(_xn(k), _yn(k))].contract(_yn(k), doms)         # step 7
            out_x.append(doms[_xn(k)])
            out_y.append(doms[_yn(k)])
        causal = ChainEstimate(out_x, out_y, ops.name, time.perf_counter() - t0, _stats(ops))
        smoothed = None
        if smooth:
            doms = tree.climb(doms, root=_xn(K))
            smoothed = ChainEstimate([doms[_xn(k)] for k in range(K + 1)],
                                     [doms[_yn(k)] for k in range(1, K + 1)], ops.name,
                                     time.perf_counter() - t0, _stats(ops))
    return causal, smoothed


def cse(system: DiscreteSystem, y: Interval, *, x0: Interval | None = None,
        x_prior: Interval | None = None,
        y_prior: Interval | None = None, domains: str = "boxes", eps: float = 0.01,
        max_boxes: int = 2_000_000) -> list[ChainEstimate]:
    """Causal state estimator CSE (Jaulin et al. 2001 section 4): after each measurement ``y_k``,
    CLIMB
    from ``y_k`` makes the whole SCSP minimal (Theorem 7).

    Same parameters as ``ncse``. Returns ``K + 1`` estimates: entry ``k`` holds the domains of
    every variable given ``y_1..y_k`` (past states smoothed, future ones predicted).
    """
    K, ops, xs, ys, meas = _setup(system, y, x0, x_prior, y_prior, domains, eps, max_boxes)
    tree = _chain(system, K, ops, lambda: None)
    t0 = time.perf_counter()
    doms = _initial(tree, ops, xs, ys, K)
    history = []

    def snapshot() -> None:
        history.append(ChainEstimate([doms[_xn(k)] for k in range(K + 1)],
                                     [doms[_yn(k)] for k in range(1, K + 1)], ops.name,
                                     time.perf_counter() - t0, _stats(ops)))
    snapshot()
    for k in range(1, K + 1):
        doms[_yn(k)] = ops.intersect(doms[_yn(k)], meas[k - 1])
        doms = tree.climb(doms, root=_yn(k))
        snapshot()
    return history
