"""The polar contractor: ``x = rho cos(theta)``, ``y = rho sin(theta)``, minimal.

:class:`CtcPolar` returns the interval hull of the solutions in the box (up to outward
rounding), where a forward-backward pass on the decomposition loses tightness to the four
occurrences of ``rho`` and ``theta``. The method (our derivation; the contractor is Desrochers
and Jaulin's, as in Codac's ``CtcPolar``) splits ``theta`` at the multiples of ``pi / 2``.

**One quarter turn.** On a piece ``theta in [j pi/2, (j+1) pi/2]`` the rotation by ``-j pi/2``
(an exact swap and negation of ``x`` and ``y``; for ``j = -1`` the reflection ``y -> -y``, so
that the angles near 0 keep all their digits) brings the points to the first quadrant, with
local angle ``psi = theta - j pi/2 in [alpha, beta] ⊂ [0, pi/2]``, box ``[a, b] x [c, d]``
(clipped to ``x, y >= 0``) and ``rho in [r1, r2]``, ``r1 >= 0``. For a fixed ``psi`` the
feasible ``rho`` form ``[L, U]`` with ``L = max(r1, a / cos psi, c / sin psi)`` and
``U = min(r2, b / cos psi, d / sin psi)``; ``L <= U`` is six monotone conditions in ``psi``, so
the feasible angles are one interval ``[psi_lo, psi_hi]``::

    psi_lo = max(alpha, acos(min(1, b/r1)), asin(c/r2), atan2(c, b))
    psi_hi = min(beta,  asin(min(1, d/r1)), acos(a/r2), atan2(d, a))

(a term is left out when its ``r1``, ``a`` or ``c`` is 0; ``a > r2`` or ``c > r2``: empty).
On ``[psi_lo, psi_hi]``, ``L cos psi = max(r1 cos psi, a, c cot psi)`` decreases and
``L sin psi = max(r1 sin psi, a tan psi, c)`` increases (and ``U`` likewise), so::

    x in [max(a, r1 cos psi_hi, c cot psi_hi), min(b, r2 cos psi_lo, d cot psi_lo)]
    y in [max(c, r1 sin psi_lo, a tan psi_lo), min(d, r2 sin psi_hi, b tan psi_hi)]
    rho in [max(r1, |(a, c)|, a / cos psi_lo, c / sin psi_hi),
            min(r2, |(b, d)|, b / cos psi_hi, d / sin psi_lo)]

each bound attained (the ``rho`` bounds: ``max(a / cos, c / sin)`` is least at the corner's
angle ``atan2(c, a)``, where it is ``|(a, c)|``, and increases away from it, so the maximum of
the three is its least value on the interval; likewise for the far corner). Every function is
evaluated at its float bounds with the outward-rounded kernels of :mod:`boundest.interval`,
and ``psi_lo``, ``psi_hi`` are rounded outward, so the monotonicity keeps every bound sound.
At an end of ``theta`` inside the piece, cos and sin of the end are those of that float
``theta`` (``cos psi = sin theta`` etc.), and they bound those of ``psi_lo`` (``psi_hi``) as well
as the term's float bound does: the tighter of the two is taken, since the float bound of the
end's angle can be far from it (one ulp of ``theta``, 9e-16 near ``5 pi/2``, where the angle
may be 3e-16, so a term above that float bound may still lie below the end's angle).
Near a multiple of ``pi/2`` the sign of
``sin(theta - j pi/2)`` tells which piece it starts: ``theta = 2*math.pi``, a float just below
``2 pi``, stays exact.

**The whole box.** The solutions are the union over the quarter turns of the pieces' solutions
and the hull of a union is the hull of the hulls: every piece met by ``theta`` is solved (at
most 11; for ``theta`` wider than about 2.5 turns, the seven lowest and seven highest pieces
and the four full quadrants, which give the same hull). A piece holds the origin when
``r1 = a = c = 0``, and then keeps all its angles. An end of ``theta`` beyond ``2**30`` in
magnitude (infinite included; no libm accuracy is assumed there) is kept as it is, the other
components are then contracted as for a full turn. ``rho < 0`` is no solution.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..interval import Interval
from ..interval.explog import _atan2_dn, _atan2_up
from ..interval.rounding import (
    INF,
    NAN,
    add_dn,
    add_up,
    div_dn,
    div_up,
    mul_dn,
    mul_up,
    sqrt_dn,
    sqrt_up,
    sub_dn,
    sub_up,
)
from ..interval.trig import (
    BIG,
    PIO2_HI,
    _acos_enc,
    _asin_enc,
    _cos_enc,
    _halfpi_dn,
    _halfpi_up,
    _sin_enc,
)
from .base import Contractor

__all__ = ["CtcPolar", "polar_box"]

_njit = nb.njit(cache=True, error_model="numpy")
_TWO_OVER_PI = 2.0 / math.pi
#: more pieces than this: only the lowest and highest ones and the four full quadrants. The
#: estimated first piece ``j0`` is at most two below the true one, so the lowest 7 pieces
#: hold a full turn (likewise at the top).
_MAX_PIECES = 11
_END_PIECES = 7


# The interval kernels inline these at every call site (Numba IR), which multiplies the
# compile time of a caller with many calls (45 s cold here): call them through one wrapper each.
@_njit
def _cos_w(x):
    return _cos_enc(x)


@_njit
def _sin_w(x):
    return _sin_enc(x)


@_njit
def _asin_w(z):
    return _asin_enc(z)


@_njit
def _atan2_dn_w(y, x):
    return _atan2_dn(y, x)


@_njit
def _atan2_up_w(y, x):
    return _atan2_up(y, x)


class CtcPolar(Contractor):
    """Minimal contractor of ``x = rho cos(theta), y = rho sin(theta)``.

    Boxes have shape ``(..., 4)``: ``(x, y, rho, theta)``, ``theta`` in radians (any interval,
    several turns and unbounded included), ``rho >= 0`` (negative ``rho`` has no solution).

    Parameters
    ----------
    center : (float, float), optional
        Polar coordinates about this point instead of the origin:
        ``x - cx = rho cos(theta)``, ``y - cy = rho sin(theta)`` (a range ``rho`` and bearing
        ``theta`` from a landmark at ``center``). The translation is outward rounded, so the
        result is then minimal up to those roundings as well.

    Notes
    -----
    "Minimal" (exact): each returned component is the interval hull of that coordinate over the
    solutions in the box, widened only by outward rounding (a few ulps of libm error on the
    angles). So it is contained (up to those roundings) in the result of any other sound
    contraction, e.g. a fixpoint of :class:`CtcFwdBwd` on the same two equations, and strictly
    narrower where the two occurrences of ``rho`` and of ``theta`` matter (the corners of the
    box). One call is idempotent up to rounding. The contractor is Desrochers and Jaulin's
    (2016) minimal polar contractor, ``CtcPolar`` in Codac and pyIbex; the method here
    (quarter turns, monotone bounds) is in the module docstring. One compiled call over the
    batch, box by box.

    Examples
    --------
    A point at range 2 within 0.1 and bearing 45 degrees within 0.05 rad:

    >>> ctc = CtcPolar()
    >>> box = ctc(Interval([-10, -10, 1.9, 0.735], [10, 10, 2.1, 0.835]))
    >>> [round(float(v), 3) for v in (*box.lo[:2], *box.hi[:2])]
    [1.275, 1.274, 1.558, 1.557]
    """

    n = 4

    def __init__(self, center: tuple[float, float] | None = None) -> None:
        self.center = None if center is None else (float(center[0]), float(center[1]))

    def contract(self, x: Interval) -> Interval:
        lo = np.array(x.lo, dtype=np.float64, order="C").reshape(-1, 4)
        hi = np.array(x.hi, dtype=np.float64, order="C").reshape(-1, 4)
        if self.center is None:
            _polar_rows(lo, hi)
        else:
            _polar_rows_about(lo, hi, *self.center)
        return Interval.trusted(lo.reshape(x.shape), hi.reshape(x.shape))


@_njit
def _quarter(q, alpha, ca_u, sa_d, beta, cb_d, sb_u, xl, xh, yl, yh, r1, r2):
    """Solve the polar constraint on the quarter turn ``q`` (0..3) of the plane, local angle
    ``psi = theta - q pi/2``, or on the fourth quadrant reflected (``q = -1``,
    ``psi = -theta``), ``r1 >= 0`` (module docstring). The angles: ``psi in [a_e, b_e]
    ⊂ [0, pi/2]`` with ``alpha <= a_e``, ``ca_u >= cos a_e``, ``sa_d <= sin a_e`` and
    ``beta >= b_e``, ``cb_d <= cos b_e``, ``sb_u >= sin b_e``. Returns
    ``(ok, x_lo, x_hi, y_lo, y_hi, rho_lo, rho_hi, psi_lo, psi_hi)`` in global ``x, y``."""
    # rotate by -q pi/2: local (x', y') = (x, y), (y, -x), (-x, -y), (-y, x); or reflect
    # (q = -1): (x, -y)
    if q == -1:
        a, b, c, d = xl, xh, -yh, -yl
    elif q == 0:
        a, b, c, d = xl, xh, yl, yh
    elif q == 1:
        a, b, c, d = yl, yh, -xh, -xl
    elif q == 2:
        a, b, c, d = -xh, -xl, -yh, -yl
    else:
        a, b, c, d = -yh, -yl, xl, xh
    a = max(a, 0.0) + 0.0  # + 0.0: no -0.0
    c = max(c, 0.0) + 0.0
    if not (a <= b and c <= d and alpha <= beta and a <= r2 and c <= r2):
        return False, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN
    # psi_lo, psi_hi: the end of the angles, or a float bound of the tighter term; the
    # functions are then evaluated at that float (a bound of psi_lo, psi_hi the right way)
    plo, phi = alpha, beta
    if r1 > 0.0:
        plo = max(plo, _acos_enc(min(1.0, div_up(b, r1)))[0])
        phi = min(phi, _asin_w(min(1.0, div_up(d, r1)))[1])
    if c > 0.0:
        plo = max(plo, _asin_w(div_dn(c, r2))[0], _atan2_dn_w(c, b))
    if a > 0.0:
        phi = min(phi, _acos_enc(div_dn(a, r2))[1], _atan2_up_w(d, a))
    if not plo <= phi:
        return False, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN
    # cos, sin at psi_lo: both the end's (exact theta) and the term's (float plo <= the
    # term) bound them, psi_lo being the larger of the two; take the tighter of each. The
    # float alpha can be far below the end's angle (one ulp of theta, 9e-16 near 5 pi/2,
    # where the angle itself may be 3e-16), so plo > alpha does not mean the term wins.
    cl_u, sl_d = ca_u, sa_d
    if plo > alpha:
        cl_u, sl_d = min(cl_u, _cos_w(plo)[1]), max(sl_d, _sin_w(plo)[0])
    ch_d, sh_u = cb_d, sb_u
    if phi < beta:
        ch_d, sh_u = max(ch_d, _cos_w(phi)[0]), min(sh_u, _sin_w(phi)[1])
    # x' bounds
    xlo = max(a, mul_dn(r1, ch_d))
    if c > 0.0:
        if sh_u <= 0.0:
            xlo = INF
        elif ch_d > 0.0:
            xlo = max(xlo, div_dn(mul_dn(c, ch_d), sh_u))
    xhi = min(b, mul_up(r2, cl_u))
    if sl_d > 0.0 and cl_u >= 0.0:
        xhi = min(xhi, div_up(mul_up(d, cl_u), sl_d))
    # y' bounds
    ylo = max(c, mul_dn(r1, sl_d))
    if a > 0.0:
        if cl_u <= 0.0:
            ylo = INF
        elif sl_d > 0.0:
            ylo = max(ylo, div_dn(mul_dn(a, sl_d), cl_u))
    yhi = min(d, mul_up(r2, sh_u))
    if ch_d > 0.0 and sh_u >= 0.0:
        yhi = min(yhi, div_up(mul_up(b, sh_u), ch_d))
    # rho bounds
    rlo = max(r1, sqrt_dn(add_dn(mul_dn(a, a), mul_dn(c, c))))
    if a > 0.0 and cl_u > 0.0:
        rlo = max(rlo, div_dn(a, cl_u))
    if c > 0.0 and sh_u > 0.0:
        rlo = max(rlo, div_dn(c, sh_u))
    rhi = min(r2, sqrt_up(add_up(mul_up(b, b), mul_up(d, d))))
    if ch_d > 0.0:
        rhi = min(rhi, div_up(b, ch_d))
    if sl_d > 0.0:
        rhi = min(rhi, div_up(d, sl_d))
    if not (xlo <= xhi and ylo <= yhi and rlo <= rhi) or xlo == INF or ylo == INF:
        return False, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN
    # rotate (reflect) back
    if q == -1:
        gx = (xlo, xhi, -yhi, -ylo)
    elif q == 0:
        gx = (xlo, xhi, ylo, yhi)
    elif q == 1:
        gx = (-yhi, -ylo, xlo, xhi)
    elif q == 2:
        gx = (-xhi, -xlo, -yhi, -ylo)
    else:
        gx = (ylo, yhi, -xhi, -xlo)
    return True, gx[0], gx[1], gx[2], gx[3], rlo, rhi, plo, phi


@_njit
def _side(t, n):
    """The sign of ``t - n pi/2`` for a float ``t`` near ``n pi/2``: 1 or -1 when certain
    (from the sign of ``sin(t - n pi/2)``, libm being accurate to a few ulps), else 0."""
    if n == 0:
        return 1 if t > 0.0 else (-1 if t < 0.0 else 0)
    if abs(t) > BIG:
        return 0
    m = n % 4
    lo, hi = _sin_w(t) if m % 2 == 0 else _cos_w(t)
    if m == 1 or m == 2:
        lo, hi = -hi, -lo
    return 1 if lo > 0.0 else (-1 if hi < 0.0 else 0)


@_njit
def _cos_sin(t, q, psi):
    """``(cos_up, sin_dn, cos_dn, sin_up)`` of the local angle ``psi_e`` of ``theta = t`` in
    the frame ``q`` (``_quarter``), from libm at ``t`` (or, beyond ``BIG``, at the float
    ``psi``, a bound of ``psi_e`` on the side where the caller uses it)."""
    if abs(t) > BIG:
        cd, cu = _cos_w(psi)
        sd, su = _sin_w(psi)
        return cu, sd, cd, su
    cd, cu = _cos_w(t)
    sd, su = _sin_w(t)
    if q == -1:  # psi = -theta
        return cu, -su, cd, -sd
    if q == 1:  # cos psi = sin theta, sin psi = -cos theta
        return su, -cu, sd, -cd
    if q == 2:
        return -cd, -su, -cu, -sd
    if q == 3:  # cos psi = -sin theta, sin psi = cos theta
        return -sd, cd, -su, cu
    return cu, sd, cd, su


@_njit
def _piece(j, tl, th, xl, xh, yl, yh, r1, r2):
    """The quarter turn ``theta in [j pi/2, (j+1) pi/2] ∩ [tl, th]`` (``|j| pi/2 <= BIG``):
    ``_quarter``'s result with the local angles mapped back to ``theta``. An end of the
    piece inside ``[tl, th]`` is exact (cos, sin of ``tl`` or ``th`` from libm), an end on
    the axis too; the float bounds ``alpha``, ``beta`` only serve the comparisons."""
    hd, hu = _halfpi_dn(j), _halfpi_up(j)
    hd1, hu1 = _halfpi_dn(j + 1), _halfpi_up(j + 1)
    # tl certainly above j pi/2 (then it starts the piece) or certainly above (j+1) pi/2
    tl_in = tl > hu or (tl >= hd and _side(tl, j) > 0)
    th_in = th < hd1 or (th <= hu1 and _side(th, j + 1) < 0)
    if (tl > hu1 or (tl >= hd1 and _side(tl, j + 1) > 0)
            or th < hd or (th <= hu and _side(th, j) < 0)):
        return False, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN
    u, v = max(tl, hd), min(th, hu1)
    # the ends (whether inside [tl, th], which theta, their float bound): one call site each
    # for the compiled helpers (the compile time grows with the inlined code)
    if j == -1:  # psi = -theta, exact: the angles near 0 keep their digits
        q = -1
        a_in, a_t, alpha = th_in, th, -th if th_in else 0.0
        b_in, b_t, beta = tl_in, tl, -tl if tl_in else PIO2_HI
    else:
        q = j % 4
        a_in, a_t, alpha = tl_in, tl, max(0.0, sub_dn(tl, hu)) if tl_in else 0.0
        b_in, b_t, beta = th_in, th, min(PIO2_HI, sub_up(th, hd)) if th_in else PIO2_HI
    ca_u, sa_d = _cos_sin(a_t, q, alpha)[0:2] if a_in else (1.0, 0.0)
    cb_d, sb_u = _cos_sin(b_t, q, beta)[2:4] if b_in else (0.0, 1.0)
    ok, x0, x1, y0, y1, r0, rr1, p0, p1 = _quarter(q, alpha, ca_u, sa_d, beta, cb_d, sb_u,
                                                   xl, xh, yl, yh, r1, r2)
    if j == -1:
        t0, t1 = max(u, -p1), min(v, -p0)
    else:
        t0, t1 = max(u, add_dn(p0, hd)), min(v, add_up(p1, hu))
    return ok and t0 <= t1, x0, x1, y0, y1, r0, rr1, t0, t1


@_njit
def polar_box(xl, xh, yl, yh, rl, rh, tl, th):
    """The minimal contraction of one box ``(x, y, rho, theta)`` by the polar constraint
    (module docstring), as 8 bounds; all NaN when it is empty. For compiled callers."""
    rl = max(rl, 0.0) + 0.0
    if not (xl <= xh and yl <= yh and rl <= rh and tl <= th):
        return NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN
    # hull of the pieces' solutions: x, y, rho, and theta from the pieces at each end
    hx0, hx1, hy0, hy1, hr0, hr1, ht0, ht1 = INF, -INF, INF, -INF, INF, -INF, INF, -INF
    low, high = -BIG <= tl <= BIG, -BIG <= th <= BIG
    j0 = math.floor(tl * _TWO_OVER_PI) - 1 if low else 0
    j1 = math.floor(th * _TWO_OVER_PI) + 1 if high else 0
    few = low and high and j1 - j0 < _MAX_PIECES
    # (first, last, whether they bound theta below, above) of each run of pieces
    runs = ((j0, j1, True, True) if few else (j0, j0 + _END_PIECES - 1, True, False),
            (0, -1, False, False) if few or not high else (j1 - _END_PIECES + 1, j1, False,
                                                           True),
            (0, -1, False, False) if few else (0, 3, False, False))
    for k in range(3):
        first, last, below, above = runs[k]
        if k == 0 and not few and not low:
            continue
        for j in range(first, last + 1):
            # k = 2: a full quadrant (the pieces between the ends), its angles unused
            ok, x0, x1, y0, y1, r0, r1, t0, t1 = _piece(j, -INF if k == 2 else tl,
                                                        INF if k == 2 else th, xl, xh, yl, yh,
                                                        rl, rh)
            if not ok:
                continue
            hx0, hx1, hy0, hy1 = min(hx0, x0), max(hx1, x1), min(hy0, y0), max(hy1, y1)
            hr0, hr1 = min(hr0, r0), max(hr1, r1)
            if below:
                ht0 = min(ht0, t0)
            if above:
                ht1 = max(ht1, t1)
    if hx0 > hx1:  # no piece has a solution
        return NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN
    if not few:  # (an end run without a solution cannot happen; tl, th would be sound)
        ht0 = ht0 if low and ht0 < INF else tl
        ht1 = ht1 if high and ht1 > -INF else th
    return (max(xl, hx0), min(xh, hx1), max(yl, hy0), min(yh, hy1), max(rl, hr0),
            min(rh, hr1), max(tl, ht0), min(th, ht1))


@_njit
def _store(lo, hi, i, r):
    for k in range(4):
        lo[i, k], hi[i, k] = r[2 * k], r[2 * k + 1]


@_njit
def _polar_rows(lo, hi):
    """Contract each row ``(x, y, rho, theta)`` of ``lo``/``hi`` in place."""
    for i in range(lo.shape[0]):
        _store(lo, hi, i, polar_box(lo[i, 0], hi[i, 0], lo[i, 1], hi[i, 1], lo[i, 2], hi[i, 2],
                                    lo[i, 3], hi[i, 3]))


@_njit
def _polar_rows_about(lo, hi, cx, cy):
    """``_polar_rows`` for ``(x - cx, y - cy) = rho (cos theta, sin theta)``: translate
    outward, contract, translate back outward and intersect with the box."""
    for i in range(lo.shape[0]):
        xl, xh, yl, yh = lo[i, 0], hi[i, 0], lo[i, 1], hi[i, 1]
        r = polar_box(sub_dn(xl, cx), sub_up(xh, cx), sub_dn(yl, cy), sub_up(yh, cy),
                      lo[i, 2], hi[i, 2], lo[i, 3], hi[i, 3])
        ok = r[0] == r[0]
        nxl, nxh = max(xl, add_dn(r[0], cx)), min(xh, add_up(r[1], cx))
        nyl, nyh = max(yl, add_dn(r[2], cy)), min(yh, add_up(r[3], cy))
        if ok and nxl <= nxh and nyl <= nyh:
            _store(lo, hi, i, (nxl, nxh, nyl, nyh, r[4], r[5], r[6], r[7]))
        else:
            lo[i, :] = NAN
            hi[i, :] = NAN
