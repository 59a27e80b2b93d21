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

Either part alone is sound, so their sequence is. One call makes one pass of (a) then (b); wrap
it in :class:`boundest.ctc.Fixpoint` to iterate. A box whose rays meet no obstacle has no real
solution and becomes empty.
"""

from __future__ import annotations

import numpy as np

from .. import interval as iv
from ..expr import Const, Constraint, Var
from ..expr.functions import cos, sin, sqr, sqrt
from ..interval import Interval
from .base import Contractor, _empty_rows
from .fwdbwd import CtcFwdBwd
from .obstacles import ObstacleMap

__all__ = ["CtcRayCast"]

_VARS = ("x", "y", "beta", "d")


class CtcRayCast(Contractor):
    """Contractor of ``d = g(x, y, beta)``, the first-hit distance along a ray of a map.

    Parameters
    ----------
    obstacles : ObstacleMap
        The segments and circles (:meth:`ObstacleMap.pool` for the pool).

    Notes
    -----
    Boxes have shape ``(..., 4)``: ``(x, y, beta, d)``, ``beta`` in radians counter-clockwise
    from +x. The constraints and why they are sound are in the module docstring. The work is
    one forward-backward pass per obstacle over the whole batch, then a few interval
    operations per obstacle: no Python loop over boxes.

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

    def __init__(self, obstacles: ObstacleMap) -> None:
        if not isinstance(obstacles, ObstacleMap):
            raise TypeError(f"CtcRayCast needs an ObstacleMap, got {type(obstacles).__name__}")
        self.map = obstacles
        self._hits = [CtcFwdBwd(_segment_constraints(a, b), _VARS)
                      for a, b in obstacles.segments]
        self._hits += [CtcFwdBwd(_circle_constraints(c, r), _VARS)
                       for c, r in zip(obstacles.centers, obstacles.radii, strict=True)]

    def contract(self, x: Interval) -> Interval:
        return self.contract_nearest(self.contract_on_obstacle(x))

    def contract_on_obstacle(self, x: Interval) -> Interval:
        """Part (a): the hull over the obstacles of the box contracted by "the end point
        ``(x + d cos beta, y + d sin beta)`` lies on this obstacle"."""
        lo = np.full(x.shape, np.nan)
        hi = np.full(x.shape, np.nan)
        for ctc in self._hits:
            y = _empty_rows(ctc.contract(x))
            lo, hi = np.fmin(lo, y.lo), np.fmax(hi, y.hi)  # an empty result drops out
        return _empty_rows(Interval._new(lo, hi))

    def contract_nearest(self, x: Interval) -> Interval:
        """Part (b): ``d <= sup s_O`` for every obstacle ``O`` certainly met by all the rays
        of the box (``s_O``: the distance to ``O`` along the ray)."""
        bound = self.nearest_bound(x[..., :3])
        lo, hi = x.lo.copy(), x.hi.copy()
        with np.errstate(invalid="ignore"):
            hi[..., 3] = np.fmin(hi[..., 3], bound)
            gone = lo[..., 3] > hi[..., 3]
        lo[gone] = np.nan
        hi[gone] = np.nan
        return Interval._new(lo, hi)

    def nearest_bound(self, rays: Interval) -> np.ndarray:
        """An upper bound of ``g`` over each box ``(x, y, beta)`` of ``rays`` (shape
        ``(..., 3)``): the least ``sup s_O`` over the obstacles certainly met by every ray of
        the box, ``inf`` where none is certain."""
        px, py, beta = rays[..., 0], rays[..., 1], rays[..., 2]
        ux, uy = iv.cos(beta), iv.sin(beta)
        bound = np.full(px.shape, np.inf)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            for (ax, ay), (bx, by) in self.map.segments:
                ex, ey = iv.sub(Interval(bx), Interval(ax)), iv.sub(Interval(by), Interval(ay))
                wax, way = iv.sub(Interval(ax), px), iv.sub(Interval(ay), py)  # a - p
                wbx, wby = iv.sub(Interval(bx), px), iv.sub(Interval(by), py)  # b - p
                cross_a = ux * way - uy * wax
                cross_b = ux * wby - uy * wbx
                den = ux * ey - uy * ex
                s = (wax * ey - way * ex) / den
                certain = ((den.lo > 0) | (den.hi < 0)) & (s.lo > 0) & (
                    ((cross_a.hi <= 0) & (cross_b.lo >= 0))
                    | ((cross_b.hi <= 0) & (cross_a.lo >= 0)))
                bound = np.where(certain, np.fmin(bound, s.hi), bound)
            for (cx, cy), r in zip(self.map.centers, self.map.radii, strict=True):
                wx, wy = iv.sub(px, Interval(cx)), iv.sub(py, Interval(cy))
                along = ux * wx + uy * wy  # u . w
                off = ux * wy - uy * wx  # u x w: offset of the centre from the ray's line
                disc = iv.sqr(Interval(r)) - iv.sqr(off)  # = b^2 - q
                s = -along - iv.sqrt(disc)
                certain = (disc.lo > 0) & (s.lo > 0)
                bound = np.where(certain, np.fmin(bound, s.hi), bound)
        return bound


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
