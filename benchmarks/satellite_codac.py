"""Codac 1.5.7 side of the satellite benchmark (Jaulin 2002, equation 14); run by
bench_satellite.py.

Run it with the interpreter of ``.bench-venv-codac1/`` (``codac==1.5.7``), never in the process
that runs boundest: importing codac switches the FPU to rounding upward (Gaol), and boundest
refuses to run then. Input: a JSON file written by ``bench_satellite.py``; every float in it is a
``float.hex`` string, read *before* codac is imported, so no decimal conversion happens under the
upward rounding mode. Output: one JSON document on stdout, enclosures again as ``float.hex``
strings (exact whatever the rounding mode).

Formulation (one forward-backward contractor per time step, in a ``ContractorNetwork``)::

    f(x1..x4, w1..w4, y1..y3, n1..n4) = 0 with
      n1 - (x1 + 0.5 x3 + w1)               n2 - (x2 + 0.5 x4 + w2)
      n3 - (x3 - 0.5 x1 / sqrt(y3)^3 + w3)  n4 - (x4 - 0.5 x2 / sqrt(y3)^3 + w4)
      y1 - x2 / x1     y2 - (x1 x3 + x2 x4)     y3 - (x1^2 + x2^2)

where ``x = x(k)``, ``n = x(k+1)``, ``w = w(k)``, ``y = y(k)``: ``x1^2 + x2^2`` is shared with
``y3`` by writing ``sqrt(y3)^3`` in the dynamics. Every scalar is an ``Interval`` domain of the
network (15 per contractor; ``x(k+1)`` is the same object in steps k and k+1). Variants:

``cn``           ``CtcFunction(f)`` (one HC4Revise pass per call) per step;
``cn_fixpoint``  ``CtcFixPoint(CtcFunction(f), fixpoint_ratio)`` per step: each step's
                 contractor is iterated to its own fixed point before the network moves on.

The network stops at Codac's fixed point (``set_fixedpoint_ratio``; Codac's default, 1e-4, unless
``ratio`` is given): a contractor is queued again when a domain's diameter shrank by more than
that ratio. Timed: ``cn.contract()`` (wall clock); building the network is timed apart.

Usage (normally through bench_satellite.py)::

    .bench-venv-codac1/bin/python benchmarks/satellite_codac.py INPUT.json
"""

from __future__ import annotations

import json
import statistics
import sys
import time

from _subprocess import fegetround

FUNCTION_ARGS = ("x1", "x2", "x3", "x4", "w1", "w2", "w3", "w4", "y1", "y2", "y3",
                 "n1", "n2", "n3", "n4")
FUNCTION_EXPR = ("(n1-(x1+0.5*x3+w1); n2-(x2+0.5*x4+w2); "
                 "n3-(x3-0.5*x1/(sqrt(y3)^3)+w3); n4-(x4-0.5*x2/(sqrt(y3)^3)+w4); "
                 "y1-x2/x1; y2-(x1*x3+x2*x4); y3-(x1^2+x2^2))")


def main() -> None:
    with open(sys.argv[1]) as fh:
        spec = json.load(fh)
    # decode every number before codac is imported (round-to-nearest still in force here)
    cases = []
    for c in spec["cases"]:
        ylo = [[float.fromhex(v) for v in row] for row in c["y_lo"]]
        yhi = [[float.fromhex(v) for v in row] for row in c["y_hi"]]
        cases.append((c["label"], ylo, yhi))
    w_bound = float.fromhex(spec["w_bound"])
    variants = spec["variants"]
    repeat = int(spec["repeat"])
    limit_s = float(spec["limit_s"])
    ratio = spec.get("ratio")
    fix_ratio = float(spec["fixpoint_ratio"])

    mode_before = fegetround()
    t0 = time.perf_counter()
    import codac
    from codac import ContractorNetwork, CtcFixPoint, CtcFunction, Function, Interval, oo
    import_s = time.perf_counter() - t0
    mode_after = fegetround()

    def contractor(variant: str):
        f = Function(*FUNCTION_ARGS, FUNCTION_EXPR)
        ctc = CtcFunction(f)
        if variant == "cn":
            return f, ctc, None
        if variant == "cn_fixpoint":
            return f, ctc, CtcFixPoint(ctc, fix_ratio)
        raise ValueError(f"unknown variant {variant!r}")

    def run(variant: str, ylo: list, yhi: list, limit: float) -> dict:
        K = len(ylo) - 1
        t_build = time.perf_counter()
        keep = contractor(variant)              # the Function/Ctc objects must outlive the CN
        ctc = keep[2] if keep[2] is not None else keep[1]
        x = [[Interval(-oo, oo) for _ in range(4)] for _ in range(K + 2)]
        x[0] = [Interval(0.0, oo), Interval(0.0, oo), Interval(-oo, 0.0), Interval(0.0, oo)]
        w = [[Interval(-w_bound, w_bound) for _ in range(4)] for _ in range(K + 1)]
        y = [[Interval(a, b) for a, b in zip(lo, hi, strict=True)]
             for lo, hi in zip(ylo, yhi, strict=True)]
        cn = ContractorNetwork()
        if ratio is not None:
            cn.set_fixedpoint_ratio(float(ratio))
        for k in range(K + 1):
            cn.add(ctc, x[k] + w[k] + y[k] + x[k + 1])
        build_s = time.perf_counter() - t_build
        t = time.perf_counter()
        cpu_s = cn.contract_during(limit)
        wall_s = time.perf_counter() - t
        finished = cn.nb_ctc_in_stack() == 0
        empty = any(v.is_empty() for row in x for v in row)

        def bounds(attr: str) -> list:
            return [[float(getattr(v, attr)()).hex() for v in row] for row in x]

        return {"k_max": K, "time_s": wall_s, "cpu_s": cpu_s, "build_s": build_s,
                "finished": finished, "empty": empty, "n_contractors": cn.nb_ctc(),
                "n_domains": cn.nb_dom(), "x_lo": bounds("lb"), "x_hi": bounds("ub")}

    results = []
    for label, ylo, yhi in cases:
        for variant in variants:
            first = run(variant, ylo, yhi, limit_s)
            rec = {"label": label, "variant": variant, "k_max": first["k_max"],
                   "first_run_s": first["time_s"], "n_contractors": first["n_contractors"],
                   "n_domains": first["n_domains"]}
            if not first["finished"]:
                rec.update(skipped=f"not at its fixed point after {limit_s:g} s of CPU time "
                                   "(contract_during); not repeated", finished=False)
                results.append(rec)
                print(f"codac {variant} {label}: over {limit_s:g} s, skipped", file=sys.stderr)
                continue
            runs = [run(variant, ylo, yhi, limit_s) for _ in range(repeat)]
            last = runs[-1]
            rec.update(
                finished=all(r["finished"] for r in runs),
                empty=last["empty"],
                times_s=[r["time_s"] for r in runs],
                time_s=statistics.median(r["time_s"] for r in runs),
                cpu_s=statistics.median(r["cpu_s"] for r in runs),
                build_s=statistics.median(r["build_s"] for r in runs),
                x_lo=last["x_lo"], x_hi=last["x_hi"],
                deterministic=all(r["x_lo"] == last["x_lo"] and r["x_hi"] == last["x_hi"]
                                  for r in runs))
            results.append(rec)
            print(f"codac {variant} {label}: {rec['time_s']:.4f} s", file=sys.stderr)

    out = {"codac_version": getattr(codac, "__version__", None) or _dist_version("codac"),
           "python": sys.version.split()[0],
           "import_s": import_s,
           "fegetround_before_import": mode_before,
           "fegetround_after_import": mode_after,
           "formulation": {"function_args": list(FUNCTION_ARGS), "function": FUNCTION_EXPR,
                           "network_fixedpoint_ratio": ratio if ratio is not None
                           else "codac default (1e-4)",
                           "ctcfixpoint_ratio": fix_ratio},
           "results": results}
    json.dump(out, sys.stdout)


def _dist_version(name: str) -> str | None:
    from importlib import metadata
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


if __name__ == "__main__":
    main()
