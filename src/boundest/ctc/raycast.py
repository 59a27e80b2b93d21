"""The range-sensor contractor: ``d = g(x, y, beta)``, the distance to the first obstacle hit.

The observation of Jaulin's robust set-membership observer (pool robot): a sonar at ``(x, y)``
pointing along ``beta`` reads the distance ``d`` along the ray to the first obstacle of an
:class:`ObstacleMap`. :class:`CtcRayCast` contracts boxes ``(x, y, beta, d)`` with two
necessary conditions of ``d = g(x, y, beta)``, written with ``u = (cos beta, sin beta)`` and
``p = (x, y)``:

(a) **the end point is on some obstacle.** The box becomes the hull, over the obstacles ``O``,
    of the box contracted (one forward-backward pass, :class:`CtcFwdBwd`) by ``O``'s
    constraints (``tau`` an auxiliary variable, ``x`` the 2-D cross product
    ``u x v = u_x v_y - u_y v_x``, ``e = b - a`` and ``w = p - c`` evaluated on the tape):

    - segment ``a -> b``: ``p + d u = a + tau e``, ``tau in [0, 1]``,
      ``d (u x e) = (a - p) x e``, ``d^2 = |a + tau e - p|^2``, ``d >= 0``;
    - circle ``(c, rho)``: ``|w + d u|^2 = rho^2``, ``u . (w + d u) <= 0``,
      ``d = -u . w - sqrt(rho^2 - (u x w)^2)``, ``d >= 0``.

    Sound: if ``O`` is the first obstacle hit, the true tuple satisfies all of ``O``'s
    constraints. For a segment the hit point is ``a + tau e`` with ``0 <= tau <= 1``, and the
    data formula ``s = ((a - p) x e) / (u x e)`` gives the third equation (which also holds,
    as ``0 = 0``, for a ray along the segment's line); the fourth is ``|d u| = d`` (it bounds
    ``d`` without ``beta``, when ``beta`` is wide). For a circle, ``|w|^2 = (u . w)^2 +
    (u x w)^2`` turns the near root ``s = -b - sqrt(b^2 - q)`` of the data formulas
    (``b = u . w``, ``q = |w|^2 - rho^2``) into the third equation, and
    ``u . (w + s u) = b + s = -sqrt(b^2 - q) <= 0`` (the near side). So the true tuple
    survives the contraction for ``O``, hence the hull; an obstacle whose contraction is empty
    drops out.

(b) **no obstacle is nearer.** ``d <= s_O(x, y, beta)`` for every obstacle that the ray meets.
    For each obstacle *certainly* met by every ray of the box, ``d`` is cut to the upper bound
    of an enclosure of ``s_O`` over the box; the others add nothing. ``[.]`` below is an
    interval extension (outward rounded) over the box, so it holds the exact value at every
    point of the box, and a test on its bounds holds at every point:

    - segment: with ``A = u x (a - p)``, ``B = u x (b - p)`` and ``den = u x e = B - A``,
      the data formula is ``tau = A / (A - B)``, so ``0 <= tau <= 1`` iff ``A`` and ``B``
      have opposite signs (or one is 0) and ``den != 0``. Certain when ``0 not in [den]``,
      (``sup [A] <= 0 <= inf [B]`` or ``sup [B] <= 0 <= inf [A]``) and
      ``inf [s] > 0`` with ``[s] = [(a - p) x e] / [den]``; then ``d <= sup [s]``.
    - circle: the near root is ``s = -b - sqrt(rho^2 - c^2)`` with ``b = u . w`` and
      ``c = u x w`` (a real hit iff ``rho^2 - c^2 >= 0``, in front iff ``s > 0``). Certain when
      ``inf [rho^2 - c^2] > 0`` and ``inf [s] > 0``, ``[s] = -[b] - sqrt([rho^2 - c^2])``;
      then ``d <= sup [s]``. (The form ``b^2 - q`` would lose the hit to the dependency
      between ``b`` and ``q``.)

Either part alone is sound, so their sequence is. One call makes ``passes`` passes of (a) then
(b) (default one; or wrap it in :class:`boundest.ctc.Fixpoint`). A box whose rays meet no
obstacle has no real solution and becomes empty.

Both parts are compiled (Numba) and run box by box: part (a) is one forward-backward pass
(:func:`boundest.ctc.revise.hc4_pass`) over the tape of each obstacle's constraints, part (b)
the interval formulas above with the outward-rounded scalar kernels of :mod:`boundest.interval`.
:func:`raycast_box` is the kernel for one box, for compiled callers (the pool observer).
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

from ..expr import Const, Constraint, Var
from ..expr.functions import cos, sin, sqr, sqrt
from ..expr.tape import compile_model
from ..interval import Interval
from ..interval import arith as ar
from ..interval import trig as tr
from .base import Contractor
from .obstacles import ObstacleMap
from .revise import family_flags, hc4_pass

__all__ = ["CtcRayCast", "RayTapes", "raycast_box"]

_VARS = ("x", "y", "beta", "d")


class RayTapes(NamedTuple):
    """The obstacles' constraint tapes packed for the compiled kernel (obstacle ``o``: nodes
    ``node_ptr[o]:node_ptr[o+1]``, slots ``slot_ptr[o]:slot_ptr[o+1]`` with initial domains
    ``lo0``/``hi0``, and the slots of ``x, y, beta, d`` at ``var_slot[o]``, relative to its
    first slot), with the map's segments ``(ns, 4)``, centres ``(nc, 2)`` and radii, and the op
    families the tapes use (:func:`boundest.ctc.revise.family_flags`)."""

    op: np.ndarray
    out: np.ndarray
    a: np.ndarray
    b: np.ndarray
    param: np.ndarray
    node_ptr: np.ndarray
    lo0: np.ndarray
    hi0: np.ndarray
    slot_ptr: np.ndarray
    var_slot: np.ndarray
    segments: np.ndarray
    centers: np.ndarray
    radii: np.ndarray
    piecewise: bool | None
    pown: bool | None
    explog: bool | None
    trig: bool | None


def pack_tapes(obstacles: ObstacleMap) -> RayTapes:
    """Compile the constraints of every obstacle of ``obstacles`` and pack them."""
    tapes = [compile_model(_segment_constraints(a, b)) for a, b in obstacles.segments]
    tapes += [compile_model(_circle_constraints(c, r))
              for c, r in zip(obstacles.centers, obstacles.radii, strict=True)]
    node_ptr = np.cumsum([0] + [t.n_nodes for t in tapes]).astype(np.int64)
    slot_ptr = np.cumsum([0] + [t.n_slots for t in tapes]).astype(np.int64)

    def cat(name: str, dtype: type) -> np.ndarray:
        parts = [np.asarray(getattr(t, name), dtype=dtype) for t in tapes]
        return np.concatenate(parts) if parts else np.zeros(0, dtype)

    var_slot = np.array([[t.slot_of[v] for v in _VARS] for t in tapes],
                        dtype=np.int64).reshape(-1, 4)
    # int32 codes and slots, as the engine's tapes: one compiled revise serves both
    op = cat("op", np.int32)
    return RayTapes(op, cat("out", np.int32), cat("a", np.int32),
                    cat("b", np.int32), cat("param", np.float64), node_ptr, cat("lo", np.float64),
                    cat("hi", np.float64), slot_ptr, var_slot,
                    np.ascontiguousarray(obstacles.segments.reshape(-1, 4), dtype=np.float64),
                    np.ascontiguousarray(obstacles.centers, dtype=np.float64).reshape(-1, 2),
                    np.ascontiguousarray(obstacles.radii, dtype=np.float64), *family_flags(op))


class CtcRayCast(Contractor):
    """Contractor of ``d = g(x, y, beta)``, the first-hit distance along a ray of a map.

    Parameters
    ----------
    obstacles : ObstacleMap
        The segments and circles (:meth:`ObstacleMap.pool` for the pool).
    passes : int
        Passes of (a) then (b) per call (stopping early when a pass changes nothing).

    Notes
    -----
    Boxes have shape ``(..., 4)``: ``(x, y, beta, d)``, ``beta`` in radians counter-clockwise
    from +x. The constraints and why they are sound are in the module docstring. The batch is
    contracted box by box inside one compiled call: no Python loop over boxes.

    Examples
    --------
    A robot at (5, 6.5) looking along +x: the pillar of centre (7, 6.5) and radius 0.6 is at
    1.4 m, so a reading of 15 m (the far wall) is impossible, and one of about 1.4 m pins x.

    >>> ctc = CtcRayCast(ObstacleMap.pool())
    >>> bool(ctc(Interval([4.9, 6.5, 0.0, 14.0], [5.1, 6.5, 0.0, 16.0])).is_empty().all())
    True
    >>> box = ctc(Interval([4.0, 6.5, 0.0, 1.39], [6.0, 6.5, 0.0, 1.41]))
    >>> bool(4.98 < box.lo[0] < box.hi[0] < 5.02)
    True
    """

    n = 4

    def __init__(self, obstacles: ObstacleMap, passes: int = 1) -> None:
        if not isinstance(obstacles, ObstacleMap):
            raise TypeError(f"CtcRayCast needs an ObstacleMap, got {type(obstacles).__name__}")
        if passes < 1:
            raise ValueError(f"passes must be >= 1, got {passes}")
        self.map = obstacles
        self.passes = int(passes)
        self.tapes = pack_tapes(obstacles)

    def contract(self, x: Interval) -> Interval:
        return self._run(x, self.passes, 3)

    def contract_on_obstacle(self, x: Interval) -> Interval:
        """Part (a) alone: the hull over the obstacles of the box contracted by "the end point
        ``(x + d cos beta, y + d sin beta)`` lies on this obstacle"."""
        return self._run(x, 1, 1)

    def contract_nearest(self, x: Interval) -> Interval:
        """Part (b) alone: ``d <= sup s_O`` for every obstacle ``O`` certainly met by all the
        rays of the box (``s_O``: the distance to ``O`` along the ray)."""
        return self._run(x, 1, 2)

    def nearest_bound(self, rays: Interval) -> np.ndarray:
        """An upper bound of ``g`` over each box ``(x, y, beta)`` of ``rays`` (shape
        ``(..., 3)``): the least ``sup s_O`` over the obstacles certainly met by every ray of
        the box, ``inf`` where none is certain."""
        lo = np.ascontiguousarray(rays.lo, dtype=np.float64).reshape(-1, 3)
        hi = np.ascontiguousarray(rays.hi, dtype=np.float64).reshape(-1, 3)
        t = self.tapes
        return _nearest_bounds(lo, hi, t.segments, t.centers, t.radii).reshape(rays.shape[:-1])

    def _run(self, x: Interval, passes: int, parts: int) -> Interval:
        lo = np.ascontiguousarray(x.lo, dtype=np.float64).reshape(-1, 4).copy()
        hi = np.ascontiguousarray(x.hi, dtype=np.float64).reshape(-1, 4).copy()
        _raycast_boxes(lo, hi, passes, parts, *self.tapes)
        return Interval.trusted(lo.reshape(x.shape), hi.reshape(x.shape))


_njit = nb.njit(cache=True, error_model="numpy")
_add_lo, _add_hi = ar._add_lo.scalar, ar._add_hi.scalar
_sub_lo, _sub_hi = ar._sub_lo.scalar, ar._sub_hi.scalar
_mul_lo, _mul_hi = ar._mul_lo.scalar, ar._mul_hi.scalar
_div_lo, _div_hi = ar._div_lo.scalar, ar._div_hi.scalar
_sqr_lo, _sqr_hi = ar._sqr_lo.scalar, ar._sqr_hi.scalar
_sqrt_lo, _sqrt_hi = ar._sqrt_lo.scalar, ar._sqrt_hi.scalar
_sin, _cos = tr._sin.scalar, tr._cos.scalar


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mul(al, ah, bl, bh):
    return _mul_lo(al, ah, bl, bh), _mul_hi(al, ah, bl, bh)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _cross(ul, uh, vl, vh, wl, wh, zl, zh):
    """``u v - w z`` outward."""
    pl, ph = _mul(ul, uh, vl, vh)
    ql, qh = _mul(wl, wh, zl, zh)
    return _sub_lo(pl, ph, ql, qh), _sub_hi(pl, ph, ql, qh)


@_njit
def nearest_bound(px_l, px_h, py_l, py_h, b_l, b_h, segments, centers, radii, buf):
    """Part (b): an upper bound of the first-hit distance over the rays of the box (the least
    ``sup s_O`` over the obstacles certainly met by every ray; ``inf`` when none is)."""
    _cos(b_l, b_h, buf[0:1], buf[1:2])
    _sin(b_l, b_h, buf[2:3], buf[3:4])
    uxl, uxh, uyl, uyh = buf[0], buf[1], buf[2], buf[3]
    bound = np.inf
    for i in range(segments.shape[0]):
        ax, ay, bx, by = segments[i, 0], segments[i, 1], segments[i, 2], segments[i, 3]
        exl, exh = _sub_lo(bx, bx, ax, ax), _sub_hi(bx, bx, ax, ax)
        eyl, eyh = _sub_lo(by, by, ay, ay), _sub_hi(by, by, ay, ay)
        waxl, waxh = _sub_lo(ax, ax, px_l, px_h), _sub_hi(ax, ax, px_l, px_h)  # a - p
        wayl, wayh = _sub_lo(ay, ay, py_l, py_h), _sub_hi(ay, ay, py_l, py_h)
        wbxl, wbxh = _sub_lo(bx, bx, px_l, px_h), _sub_hi(bx, bx, px_l, px_h)  # b - p
        wbyl, wbyh = _sub_lo(by, by, py_l, py_h), _sub_hi(by, by, py_l, py_h)
        cal, cah = _cross(uxl, uxh, wayl, wayh, uyl, uyh, waxl, waxh)
        cbl, cbh = _cross(uxl, uxh, wbyl, wbyh, uyl, uyh, wbxl, wbxh)
        dl, dh = _cross(uxl, uxh, eyl, eyh, uyl, uyh, exl, exh)
        nl, nh = _cross(waxl, waxh, eyl, eyh, wayl, wayh, exl, exh)
        sl, sh = _div_lo(nl, nh, dl, dh), _div_hi(nl, nh, dl, dh)
        certain = ((dl > 0.0) or (dh < 0.0)) and sl > 0.0 and (
            (cah <= 0.0 and cbl >= 0.0) or (cbh <= 0.0 and cal >= 0.0))
        if certain and sh < bound:
            bound = sh
    for i in range(centers.shape[0]):
        cx, cy, r = centers[i, 0], centers[i, 1], radii[i]
        wxl, wxh = _sub_lo(px_l, px_h, cx, cx), _sub_hi(px_l, px_h, cx, cx)  # p - c
        wyl, wyh = _sub_lo(py_l, py_h, cy, cy), _sub_hi(py_l, py_h, cy, cy)
        pl, ph = _mul(uxl, uxh, wxl, wxh)
        ql, qh = _mul(uyl, uyh, wyl, wyh)
        al, ah = _add_lo(pl, ph, ql, qh), _add_hi(pl, ph, ql, qh)  # u . w
        ol, oh = _cross(uxl, uxh, wyl, wyh, uyl, uyh, wxl, wxh)  # u x w
        s2l, s2h = _sqr_lo(ol, oh), _sqr_hi(ol, oh)
        rl, rh = _sqr_lo(r, r), _sqr_hi(r, r)
        cl, ch = _sub_lo(rl, rh, s2l, s2h), _sub_hi(rl, rh, s2l, s2h)  # rho^2 - (u x w)^2
        if not cl > 0.0:
            continue
        tl, th = _sqrt_lo(cl, ch), _sqrt_hi(cl, ch)
        sl, sh = _sub_lo(-ah, -al, tl, th), _sub_hi(-ah, -al, tl, th)
        if sl > 0.0 and sh < bound:
            bound = sh
    return bound


@_njit
def raycast_box(box_lo, box_hi, passes, parts, op, out, a, b, param, node_ptr, lo0, hi0,
                slot_ptr, var_slot, segments, centers, radii, piecewise, pown, explog, trig, slo,
                shi, buf):
    """Contract one box ``(x, y, beta, d)`` in place (``parts``: 1 = (a), 2 = (b), 3 = both,
    ``passes`` times at most; the tapes and the family flags: :class:`RayTapes`).
    ``slo``/``shi``: scratch of at least ``lo0.size`` floats, ``buf``: 4. Returns False when
    the box is empty (its bounds are then NaN)."""
    for _ in range(passes):
        before = 0.0
        for j in range(4):
            before += box_hi[j] - box_lo[j]
        if parts & 1:
            hull_lo = np.full(4, np.inf)
            hull_hi = np.full(4, -np.inf)
            for o in range(node_ptr.size - 1):
                s0, s1 = slot_ptr[o], slot_ptr[o + 1]
                sl, sh = slo[s0:s1], shi[s0:s1]
                sl[:] = lo0[s0:s1]
                sh[:] = hi0[s0:s1]
                ok = True
                for j in range(4):
                    v = var_slot[o, j]
                    sl[v] = max(sl[v], box_lo[j])
                    sh[v] = min(sh[v], box_hi[j])
                    ok = ok and sl[v] <= sh[v]
                n0, n1 = node_ptr[o], node_ptr[o + 1]
                if ok and hc4_pass(op[n0:n1], out[n0:n1], a[n0:n1], b[n0:n1], param[n0:n1],
                                   sl, sh, buf, piecewise, pown, explog, trig):
                    for j in range(4):
                        v = var_slot[o, j]
                        hull_lo[j] = min(hull_lo[j], sl[v])
                        hull_hi[j] = max(hull_hi[j], sh[v])
            for j in range(4):
                box_lo[j] = max(box_lo[j], hull_lo[j])
                box_hi[j] = min(box_hi[j], hull_hi[j])
            if not box_lo[0] <= box_hi[0]:  # no obstacle can be the one hit
                box_lo[:] = np.nan
                box_hi[:] = np.nan
                return False
        if parts & 2:
            bound = nearest_bound(box_lo[0], box_hi[0], box_lo[1], box_hi[1], box_lo[2],
                                  box_hi[2], segments, centers, radii, buf)
            box_hi[3] = min(box_hi[3], bound)
            if not box_lo[3] <= box_hi[3]:
                box_lo[:] = np.nan
                box_hi[:] = np.nan
                return False
        after = 0.0
        for j in range(4):
            after += box_hi[j] - box_lo[j]
        if not after < before:  # a fixed point (or infinite widths that did not change)
            break
    return True


@_njit
def _nearest_bounds(lo, hi, segments, centers, radii):
    out, buf = np.empty(lo.shape[0]), np.empty(4)
    for i in range(lo.shape[0]):
        out[i] = nearest_bound(lo[i, 0], hi[i, 0], lo[i, 1], hi[i, 1], lo[i, 2], hi[i, 2],
                               segments, centers, radii, buf)
    return out


@_njit
def _raycast_boxes(lo, hi, passes, parts, op, out, a, b, param, node_ptr, lo0, hi0, slot_ptr,
                   var_slot, segments, centers, radii, piecewise, pown, explog, trig):
    slo, shi, buf = np.empty(lo0.size), np.empty(lo0.size), np.empty(4)
    for i in range(lo.shape[0]):
        empty = False
        for j in range(4):
            empty = empty or not lo[i, j] <= hi[i, j]
        if empty or not raycast_box(lo[i], hi[i], passes, parts, op, out, a, b, param,
                                    node_ptr, lo0, hi0, slot_ptr, var_slot, segments, centers,
                                    radii, piecewise, pown, explog, trig, slo, shi, buf):
            lo[i, :] = np.nan
            hi[i, :] = np.nan


def _segment_constraints(a: np.ndarray, b: np.ndarray) -> list[Constraint]:
    x, y, beta, d, tau = Var("x"), Var("y"), Var("beta"), Var("d"), Var("tau")
    ax, ay, bx, by = (Const(float(v)) for v in (a[0], a[1], b[0], b[1]))
    ex, ey = bx - ax, by - ay  # evaluated on the tape, outward rounded
    ux, uy = cos(beta), sin(beta)
    hx, hy = ax + tau * ex, ay + tau * ey  # the hit point
    return [x + d * ux == hx, y + d * uy == hy,
            d * (ux * ey - uy * ex) == (ax - x) * ey - (ay - y) * ex,
            sqr(d) == sqr(hx - x) + sqr(hy - y),
            tau.in_((0.0, 1.0)), d >= 0]


def _circle_constraints(c: np.ndarray, r: float) -> list[Constraint]:
    x, y, beta, d = Var("x"), Var("y"), Var("beta"), Var("d")
    rho = Const(float(r))
    ux, uy = cos(beta), sin(beta)
    wx, wy = x - Const(float(c[0])), y - Const(float(c[1]))  # p - c
    ex, ey = wx + d * ux, wy + d * uy  # end point minus centre
    return [sqr(ex) + sqr(ey) == sqr(rho), ux * ex + uy * ey <= 0,
            d == -(ux * wx + uy * wy) - sqrt(sqr(rho) - sqr(ux * wy - uy * wx)), d >= 0]
