"""Codac side of the SIVIA benchmark; run by bench_sivia.py in a subprocess.

Run it with the interpreter of ``.bench-venv/`` (codac 2.x: ``pave(X, SepInverse(f, Y), eps)``
and ``sivia(X, f, Y, eps)``) or of ``.bench-venv-codac1/`` (codac 1.5.7:
``SIVIA(X, SepFwdBwd(f, Y), eps)``), never in the process that runs boundest: importing codac
switches the FPU to rounding upward. Input: a JSON file written by ``bench_sivia.py`` whose
floats are ``float.hex`` strings, decoded before codac is imported. Output: one JSON document on
stdout.

Problem ``shell``: ``{x in [lo, hi]^dim : a <= x_1^2 + ... + x_dim^2 <= b}``. Timed: the paving
call alone (wall clock), median of ``repeat`` runs after one untimed warm-up run. Counted:

codac 2 ``pave``   nodes of the paving tree (= boxes separated), leaves, and the boxes returned
                   by ``p.boxes(PavingInOut.inner)`` / ``.bound`` (inside / boundary boxes);
codac 2 ``sivia``  the same for the natural inclusion test version (``f.eval`` per box);
codac 1 ``SIVIA``  the lengths of the IN / UNKNOWN / OUT lists it returns.

Usage (normally through bench_sivia.py)::

    .bench-venv/bin/python benchmarks/sivia_codac.py INPUT.json
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from importlib import metadata


def main() -> None:
    with open(sys.argv[1]) as fh:
        spec = json.load(fh)
    cases = [(c["label"], int(c["dim"]), float.fromhex(c["lo"]), float.fromhex(c["hi"]),
              float.fromhex(c["a"]), float.fromhex(c["b"]), float.fromhex(c["eps"]))
             for c in spec["cases"]]
    repeat = int(spec["repeat"])
    long_s = float(spec["long_s"])
    variants = spec["variants"]

    t0 = time.perf_counter()
    import codac
    import_s = time.perf_counter() - t0
    version = metadata.version("codac")
    major = int(version.split(".")[0])

    def runner(variant: str, dim: int, lo: float, hi: float, a: float, b: float, eps: float):
        names = ["x", "y", "z", "u", "v", "w"][:dim]
        X = codac.IntervalVector([[lo, hi]] * dim)
        if major >= 2:
            x = codac.VectorVar(dim)
            expr = codac.sqr(x[0])
            for i in range(1, dim):
                expr = expr + codac.sqr(x[i])
            f = codac.AnalyticFunction([x], expr)
            Y = codac.Interval(a, b)
            if variant == "pave":
                sep = codac.SepInverse(f, Y)

                def run():
                    return codac.pave(X, sep, eps)
            else:
                def run():
                    return codac.sivia(X, f, Y, eps)

            def count(p) -> dict:
                nodes = [0, 0]

                def visit(n) -> bool:
                    nodes[0] += 1
                    nodes[1] += n.is_leaf()
                    return True

                p.tree().visit(visit)
                return {"processed": nodes[0], "leaves": nodes[1],
                        "inside": len(p.boxes(codac.PavingInOut.inner)),
                        "boundary": len(p.boxes(codac.PavingInOut.bound))}
            return (f, X), run, count
        f = codac.Function(*names, "+".join(f"{v}^2" for v in names))
        sep = codac.SepFwdBwd(f, codac.Interval(a, b))

        def run1():
            return codac.SIVIA(X, sep, eps, display_result=False, return_result=True)

        def count1(r) -> dict:
            by = {str(k).split(".")[-1]: len(v) for k, v in r.items()}
            return {"inside": by.get("IN", 0), "boundary": by.get("UNKNOWN", 0),
                    "outside": by.get("OUT", 0)}
        return (f, sep, X), run1, count1

    results = []
    for label, dim, lo, hi, a, b, eps in cases:
        for variant in variants:
            keep, run, count = runner(variant, dim, lo, hi, a, b, eps)
            t = time.perf_counter()
            first = run()
            first_s = time.perf_counter() - t
            counts = count(first)
            del first
            times = []
            n = repeat if first_s < long_s else max(1, min(repeat, 2))
            for _ in range(n):
                t = time.perf_counter()
                run()
                times.append(time.perf_counter() - t)
            rec = {"label": label, "variant": variant, "dim": dim, "eps": eps.hex(),
                   "first_run_s": first_s, "times_s": times,
                   "time_s": statistics.median(times), **counts}
            results.append(rec)
            print(f"codac {version} {variant} {label}: {rec['time_s']:.4f} s {counts}",
                  file=sys.stderr)
            del keep
    json.dump({"codac_version": version, "python": sys.version.split()[0],
               "import_s": import_s, "results": results}, sys.stdout)


if __name__ == "__main__":
    main()
