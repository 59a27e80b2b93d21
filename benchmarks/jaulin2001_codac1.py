"""Codac 1.5.7 side of the jaulin2001 benchmark (Jaulin et al. 2001 eq. 21); run by
bench_jaulin2001.py.

Run with ``.bench-venv-codac1/bin/python`` in its own process (importing codac switches the FPU
to rounding upward). Input: a JSON file with the measurement bounds as ``float.hex`` strings,
decoded before codac is imported. Formulation (the one quoted in issue 4): one box CSP over
x(0..K) (2K + 2 variables) with ``x(k) = f(x(k-1))`` and ``|x1(k)| in Y(k)``, contracted by
``CtcFixPoint(CtcFunction)``; x(0) in [-4, 4]^2 is bisected (a stack, widest side) until its
width is below ``eps``; boxes contracted to empty are dropped. The non-causal set of x(k) is the
union of the contracted boxes' k-th components; reported: their hull and count.

Usage: ``.bench-venv-codac1/bin/python benchmarks/jaulin2001_codac1.py INPUT.json``
"""

from __future__ import annotations

import json
import statistics
import sys
import time


def main() -> None:
    with open(sys.argv[1]) as fh:
        spec = json.load(fh)
    ylo = [float.fromhex(v) for v in spec["y_lo"]]
    yhi = [float.fromhex(v) for v in spec["y_hi"]]
    eps, repeat = float(spec["eps"]), int(spec["repeat"])
    K = len(ylo)
    import codac
    from codac import CtcFixPoint, CtcFunction, Function, IntervalVector

    n = 2 * (K + 1)
    comps = []
    for k in range(1, K + 1):
        a, b, c, d = 2 * k - 2, 2 * k - 1, 2 * k, 2 * k + 1
        comps.append(f"x[{c}]-3*sin(x[{a}]+x[{b}])")
        comps.append(f"x[{d}]-3*cos(x[{a}]+x[{b}])")
    for k in range(1, K + 1):
        comps.append(f"abs(x[{2 * k}])")
    f = Function(f"x[{n}]", "(" + ";".join(comps) + ")")
    target = IntervalVector([[0, 0]] * (2 * K) + [[lo, hi] for lo, hi in zip(ylo, yhi,
                                                                           strict=True)])
    ctc_f = CtcFunction(f, target)
    ctc = CtcFixPoint(ctc_f, 0.01)

    def run() -> tuple[float, list, int]:
        t = time.perf_counter()
        x0 = IntervalVector([[-4, 4], [-4, 4]] + [[-1e300, 1e300]] * (2 * K))
        stack, kept = [x0], []
        while stack:
            b = stack.pop()
            ctc.contract(b)
            if b.is_empty():
                continue
            if max(b[0].diam(), b[1].diam()) < eps:
                kept.append(b)
                continue
            i = 0 if b[0].diam() >= b[1].diam() else 1
            p1, p2 = b.bisect(i)
            stack += [p1, p2]
        wall = time.perf_counter() - t
        hull = []
        for k in range(K + 1):
            lo = [min(b[2 * k + j].lb() for b in kept) for j in range(2)] if kept else None
            hi = [max(b[2 * k + j].ub() for b in kept) for j in range(2)] if kept else None
            hull.append({"lo": [v.hex() for v in lo] if lo else None,
                         "hi": [v.hex() for v in hi] if hi else None})
        return wall, hull, len(kept)

    runs = [run() for _ in range(repeat)]
    out = {"codac_version": getattr(codac, "__version__", None), "eps": eps,
           "times_s": [r[0] for r in runs], "time_s": statistics.median(r[0] for r in runs),
           "boxes": runs[-1][2], "hull": runs[-1][1]}
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
