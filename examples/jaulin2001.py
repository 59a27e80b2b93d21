"""Causal and non-causal set estimation with subpavings (Jaulin, Kieffer, Braems, Walter 2001).

The test case of the paper (section 5, equation 21): a two-dimensional state moved by a
nonlinear map and observed through an absolute value,

    x(k) = 3 (sin(x1(k-1) + x2(k-1)), cos(x1(k-1) + x2(k-1))),   y(k) = |x1(k)|,   k = 1..10,

with measurements known to +-0.1 and nothing known of x(0) but the frame [-4, 4]^2. The
domains are subpavings (unions of boxes), so the sets keep their several pieces. ``rcse`` is
the causal estimator (x(k) given y(1..k)), ``ncse`` the non-causal one (given all the data,
by FALL/CLIMB on the chain of constraints).

The truth is simulated here with boundest's own interval arithmetic from a point x(0): each
step is an outward-rounded enclosure of the exact map, so after ten steps the box ``X[k]``
(about 1e-8 wide) is proven to contain the exact trajectory, and the check asks that the
whole box lie in the estimated set. ``eps = 0.02`` (the command's default is 0.01) keeps the
run short.

To adapt it: write your own ``f`` and ``g`` with ``boundest``'s functions (they accept
intervals and expressions alike), give your measurement intervals ``Y`` of shape (K, ny)
and a bounded prior box ``x0`` to pave.
"""

from __future__ import annotations

import numpy as np

import boundest as bd

K, NOISE, EPS = 10, 0.1, 0.02
FRAME = bd.Interval([-4.0, -4.0], [4.0, 4.0])  # the prior of x(0), Fig. 7 of the paper


def f(x) -> list:  # x: a box or a list of variables; boundest's functions take both
    """The state map x(k) = f(x(k-1)) of equation 21."""
    return [3 * bd.sin(x[0] + x[1]), 3 * bd.cos(x[0] + x[1])]


def g(x) -> list:
    """The output y(k) = g(x(k))."""
    return [bd.abs(x[0])]


# the truth, enclosed: X[k] is a thin box around the exact x(k) from x(0) = (1, 0.5)
X = [bd.Interval([1.0, 0.5])]
for _ in range(K):
    X.append(bd.Interval.stack(f(X[-1])))
rng = np.random.default_rng(3)
y_true = bd.Interval.stack([g(x)[0] for x in X[1:]])        # |x1(k)|, k = 1..K
Y = bd.Interval(y_true.mid() + rng.uniform(-0.9, 0.9, K) * NOISE) + bd.Interval(-NOISE, NOISE)
assert bool(np.all(Y.contains(y_true))), "a measurement interval misses the true output"

system = bd.DiscreteSystem(f, g, nx=2, ny=1)
# both estimators at once: NCSE continues from the RCSE's sets (bd.rcse and bd.ncse alone
# give the same sets, in about twice the time)
causal, smooth = bd.rcse_ncse(system, Y.reshape(K, 1), x0=FRAME, domains="subpavings", eps=EPS)


def holds(domain: bd.Subpaving | bd.Interval, box: bd.Interval) -> bool:
    """Whether the domain (a subpaving, or a box where the estimator kept one) contains the
    whole box. For a subpaving this asks for one of its boxes to hold it: a truth box
    straddling two paving boxes would be a false alarm, never a false pass."""
    if isinstance(domain, bd.Interval):
        return box in domain
    return bool(np.any(box.is_subset(domain.boxes).all(axis=1)))


print("boxes per k, causal:", [len(d) if isinstance(d, bd.Subpaving) else 1 for d in causal.x])
print("boxes per k, non-causal:", [len(d) for d in smooth.x])
print(f"width of the truth's enclosure at k = {K}: {X[K].width().max():.1e}")
for k in range(K + 1):
    for name, est in (("RCSE", causal), ("NCSE", smooth)):
        assert holds(est.x[k], X[k]), f"{name}: the truth leaves the set at k = {k}"
print(f"OK: the truth lies in every causal and non-causal set (k = 0..{K})")
