"""Codac 1.5.7 side of the Rohou et al. 2018 benchmark (range-only robot, drifting clock); run by
``bench_seed001.py``.

Run it with the interpreter of ``.bench-venv-codac1/`` (``codac==1.5.7``), never in the process
that runs boundest: importing codac switches the FPU to rounding upward. Input: a JSON file
written by ``bench_seed001.py`` in which every float is a ``float.hex`` string, decoded *before*
codac is imported. Output: one JSON document on stdout, enclosures as ``float.hex`` strings.

Models (Rohou et al. 2018, CN (15) and CN (20), as ``boundest.scenarios.range_only`` and
``drifting_clock`` build them), Codac's own contractors over tubes sliced every ``dt``:

range-only robot::

    CtcFunction  v = f(x, u)                                   (equation 13)
    CtcDeriv     x' = v
    CtcFunction  y_k = |x_12 - b_k|,  w_k = x4 cos(x3 - atan2(x2 - b_k2, x1 - b_k1))
    CtcFunction  w_k y_k = (x_12 - b_k).v_12                     (case "rate": "both" only)
    CtcDeriv     y_k' = w_k
    CtcEval      z_i = y_k(t_i)                                one per measurement

with ``[u]`` of equation 14 (``TFunction`` enclosure inflated by 1e-3), ``x3(0) in pi/2 +
[-0.01, 0.01]``, ``x4(0) in [-0.01, 0.01]``, every other domain unbounded. (``w_k`` is the
paper's ``(x_12 - b_k).v_12 / y_k`` written with the bearing: the quotient form is unbounded
while the position is, and then no measurement is ever used.)

drifting clock::

    [x], [v], [phi] from equations 18, 19, 17 (``TFunction`` enclosures)
    CtcDeriv     x' = v
    CtcFunction  y = sqrt(x1^2 + x2^2 + 100), w y = x1 v1 + x2 v2
    CtcDeriv     y' = w,  h' = phi,  h(0) = 0
    CtcEval      tau_i = h(t_i)  and  z_i = y(t_i)                 (equations 21, 22)

Variants. ``loop`` (the default, and boundest's scheme): explicit rounds of Codac's tube
contractors (``CtcFunction.contract`` on tubes, ``CtcDeriv``, ``CtcEval``); for the robot the
dead-reckoning part (``v = f(x, u)``, ``x' = v``) first runs to its own fixed point, then each
round applies ``x' = v``, the distance and rate of every beacon, ``y' = w``, every ``CtcEval``
and the distances again, until the position tube's volume decreases by less than ``rel_eps``
(relative) in a round; the clock's rounds apply ``x' = v``, the distance, ``h' = phi`` and, per
measurement, ``CtcEval`` on ``h``, on ``y``, on ``h``, until ``vol([h]) + sum |[t_i]|`` stops
decreasing. Only the contractions are timed. ``cn`` puts the same contractors in one Codac
``ContractorNetwork`` and runs ``contract()`` once, to the network's own fixed point (ratio
1e-4); Codac then splits every tube constraint into one contractor per slice, which makes the
robot very slow (about 22 s already at dt = 0.1, 15,374 contractors). CtcEval and CtcDeriv keep
the slicing (``preserve_slicing(True)``), so every tube keeps the ``dt`` grid as boundest's do.

Gate values are read every ``every``-th gate (``tube(t)`` walks Codac 1's list of slices, O(n)
per call), and the per-round mean position-box diagonal over those gates is recorded untimed.

Usage (normally through bench_seed001.py)::

    .bench-venv-codac1/bin/python benchmarks/seed001_codac.py INPUT.json
"""

from __future__ import annotations

import json
import math
import statistics
import sys
import time

from _subprocess import decode_hex, fegetround


def _h(v: float) -> str:
    return float(v).hex()




def main() -> None:
    with open(sys.argv[1]) as fh:
        spec = decode_hex(json.load(fh))      # decoded under round-to-nearest, before codac
    mode_before = fegetround()
    t0 = time.perf_counter()
    from codac import (
        ContractorNetwork,
        CtcDeriv,
        CtcEval,
        CtcFunction,
        Function,
        Interval,
        IntervalVector,
        TFunction,
        Tube,
        TubeVector,
    )
    import_s = time.perf_counter() - t0
    mode_after = fegetround()

    def gate_times(tube, every: int) -> tuple[list, list]:
        """Indices and times of every ``every``-th gate, and of the last one.

        Each ``tube.slice(i)`` and ``tube(t)`` walks Codac 1's list of slices (O(n)), so the
        gates are sampled (walking with ``first_slice``/``next_slice`` from Python crashes
        Codac 1.5.7 later on: the bindings take ownership of the slices)."""
        n = tube.nb_slices()
        idx = [*range(0, n, every), n]
        return idx, [tube.slice(i).tdomain().lb() for i in idx[:-1]] + [tube.tdomain().ub()]

    def gates(tube, times) -> list:
        return [[_h(tube(t).lb()) for t in times], [_h(tube(t).ub()) for t in times]]

    def robot(case: dict, variant: str, limit: float) -> dict:
        dt, t0_, tf = case["dt"], case["t0"], case["tf"]
        tdom = Interval(t0_, tf)
        t_build = time.perf_counter()
        x = TubeVector(tdom, dt, 4)
        v = TubeVector(tdom, dt, 4)
        u = TubeVector(tdom, dt, TFunction("(-9/20*cos(t/5) ; 1/10+sin(t/4))"))
        u.inflate(case["u_bound"])
        x0 = IntervalVector(4)
        x0[2] = Interval(*case["x3_0"])
        x0[3] = Interval(*case["x4_0"])
        x.set(x0, t0_)
        ctc_deriv = CtcDeriv()
        ctc_deriv.preserve_slicing(True)
        ctc_eval = CtcEval()
        ctc_eval.preserve_slicing(True)
        ys = [Tube(tdom, dt) for _ in case["beacons"]]
        ws = [Tube(tdom, dt) for _ in case["beacons"]]
        # y_k = |x_12 - b_k| and its derivative w_k = x4 cos(x3 - theta_k), theta_k the bearing
        # of the robot from b_k: (x - b).v / |x - b| written so that |w_k| <= |x4| even while
        # the position is unbounded (the quotient form gives nothing then)
        # with rate "both", also the product form w_k y_k = (x_12 - b_k).v_12
        both = case.get("rate", "bearing") == "both"
        g_src = [f"(y - sqrt((x1-({bx!r}))^2+(x2-({by!r}))^2) ; "
                 f"w - x4*cos(x3-atan2(x2-({by!r}),x1-({bx!r})))"
                 + (f" ; w*y - ((x1-({bx!r}))*v1 + (x2-({by!r}))*v2)" if both else "") + ")"
                 for bx, by in case["beacons"]]
        ts = [Interval(a, b) for a, b in zip(case["t_lo"], case["t_hi"], strict=True)]
        zs = [Interval(a, b) for a, b in zip(case["z_lo"], case["z_hi"], strict=True)]
        beacon = case["beacon"]
        if variant == "cn":
            f_evol = Function("v[4]", "x[4]", "u[2]", "(v[0]-x[3]*cos(x[2]) ; "
                              "v[1]-x[3]*sin(x[2]) ; v[2]-u[0] ; v[3]-u[1])")
            keep = [f_evol, CtcFunction(f_evol)]         # must outlive the CN
            cn = ContractorNetwork()
            if case.get("ratio") is not None:
                cn.set_fixedpoint_ratio(case["ratio"])
            cn.add(keep[1], [v, x, u])
            cn.add(ctc_deriv, [x, v])
            for src, y, w in zip(g_src, ys, ws, strict=True):
                g = Function("y", "w", "x[4]", "v[4]",
                             src.replace("x1", "x[0]").replace("x2", "x[1]")
                             .replace("x3", "x[2]").replace("x4", "x[3]")
                             .replace("v1", "v[0]").replace("v2", "v[1]"))
                keep += [g, CtcFunction(g)]
                cn.add(keep[-1], [y, w, x, v])
            for k, ti, zi in zip(beacon, ts, zs, strict=True):
                cn.add(ctc_eval, [ti, zi, ys[k], ws[k]])
        else:
            fs = [Function("v", "x3", "x4", "v - x4*cos(x3)"),
                  Function("v", "x3", "x4", "v - x4*sin(x3)"),
                  Function("v", "u", "v - u")]
            cf = [CtcFunction(f) for f in fs]
            dist = [Function("y", "x1", "x2", f"y - sqrt((x1-({bx!r}))^2+(x2-({by!r}))^2)")
                    for bx, by in case["beacons"]]
            rate = [Function("w", "x1", "x2", "x3", "x4",
                             f"w - x4*cos(x3-atan2(x2-({by!r}),x1-({bx!r})))")
                    for bx, by in case["beacons"]]
            prod = [Function("w", "y", "x1", "x2", "v1", "v2",
                             f"w*y - ((x1-({bx!r}))*v1 + (x2-({by!r}))*v2)")
                    for bx, by in case["beacons"]]
            cd, cr = [CtcFunction(g) for g in dist], [CtcFunction(g) for g in rate]
            cp = [CtcFunction(g) for g in prod]

            def dead_reckoning() -> None:
                cf[0].contract(v[0], x[2], x[3])
                cf[1].contract(v[1], x[2], x[3])
                cf[2].contract(v[2], u[0])
                cf[2].contract(v[3], u[1])
                ctc_deriv.contract(x, v)

            def one_round() -> None:
                ctc_deriv.contract(x, v)
                for k, (y, w) in enumerate(zip(ys, ws, strict=True)):
                    cd[k].contract(y, x[0], x[1])
                    cr[k].contract(w, x[0], x[1], x[2], x[3])
                    if both:
                        cp[k].contract(w, y, x[0], x[1], v[0], v[1])
                    ctc_deriv.contract(y, w)
                for k, ti, zi in zip(beacon, ts, zs, strict=True):
                    ctc_eval.contract(ti, zi, ys[k], ws[k])
                for k, y in enumerate(ys):
                    cd[k].contract(y, x[0], x[1])
        build_s = time.perf_counter() - t_build
        n = x.nb_slices()
        idx, times = gate_times(x[0], case["every"])

        def diag() -> float:
            return sum(math.hypot(x[0](t).diam(), x[1](t).diam()) for t in times) / len(times)

        def pos_volume() -> float:
            return x[0].volume() + x[1].volume()

        t = time.perf_counter()
        history, rounds, finished = [], 0, True
        if variant == "cn":
            cn.contract_during(limit)
            rounds = 1
            finished = cn.nb_ctc_in_stack() == 0
        else:
            prev, spent = math.inf, 0.0
            t1 = time.perf_counter()
            while True:                           # dead reckoning to its own fixed point
                dead_reckoning()
                vol = x[2].volume() + x[3].volume() + v.volume()
                if math.isfinite(prev) and (prev - vol) <= case["rel_eps"] * prev:
                    break
                prev = vol
            spent += time.perf_counter() - t1
            prev = math.inf
            while True:
                t1 = time.perf_counter()
                one_round()
                vol = pos_volume()
                spent += time.perf_counter() - t1
                rounds += 1
                history.append(diag())          # not timed
                print(f"  codac {case['label']} round {rounds}: {spent:.2f} s",
                      file=sys.stderr, flush=True)
                if math.isfinite(prev) and (prev - vol) <= case["rel_eps"] * prev:
                    break
                prev = vol
                if spent > limit or rounds >= case["max_iter"]:
                    finished = False
                    break
        wall = time.perf_counter() - t if variant == "cn" else spent
        return {"time_s": wall, "build_s": build_s, "finished": finished,
                "rounds": rounds, "diag_history": history, "n_slices": n,
                "mean_diag": diag(), "pos_volume": pos_volume(),
                "gate_index": idx, "x_gates": [gates(x[j], times) for j in range(4)],
                "t_lo": [_h(ti.lb()) for ti in ts], "t_hi": [_h(ti.ub()) for ti in ts],
                "z_lo": [_h(zi.lb()) for zi in zs], "z_hi": [_h(zi.ub()) for zi in zs],
                "empty": x.is_empty()}

    def clock(case: dict, variant: str, limit: float) -> dict:
        dt, tf = case["dt"], case["tf"]
        tdom = Interval(0.0, tf)
        t_build = time.perf_counter()
        # the constants as boundest encloses them, written exactly (see _clock_consts)
        c = case["consts"]

        def iv(b: list[str]) -> str:
            return f"[{b[0]},{b[1]}]"
        x1o, x2o, ve = iv(c["x_offset"][0]), iv(c["x_offset"][1]), iv(c["v_error"])
        x = TubeVector(tdom, dt, TFunction(f"({x1o}+100*cos(t) ; {x2o}+100*sin(t))"))
        v = TubeVector(tdom, dt, TFunction(f"({ve}-100*sin(t) ; {ve}+100*cos(t))"))
        phi = Tube(tdom, dt, TFunction(f"{iv(c['rate'])}*t+{iv(c['offset'])}"))
        h = Tube(tdom, dt)
        h.set(Interval(0.0), 0.0)
        y, w = Tube(tdom, dt), Tube(tdom, dt)
        g_src = "(y - sqrt(x1^2+x2^2+100) ; w*y - (x1*v1+x2*v2))"
        ctc_deriv = CtcDeriv()
        ctc_deriv.preserve_slicing(True)
        ctc_eval = CtcEval()
        ctc_eval.preserve_slicing(True)
        ts = [Interval(0.0, tf) for _ in case["tau_lo"]]
        taus = [Interval(a, b) for a, b in zip(case["tau_lo"], case["tau_hi"], strict=True)]
        zs = [Interval(a, b) for a, b in zip(case["z_lo"], case["z_hi"], strict=True)]
        if variant == "cn":
            g = Function("y", "w", "x[2]", "v[2]", g_src.replace("x1", "x[0]")
                         .replace("x2", "x[1]").replace("v1", "v[0]").replace("v2", "v[1]"))
            ctc_g = CtcFunction(g)
            cn = ContractorNetwork()
            if case.get("ratio") is not None:
                cn.set_fixedpoint_ratio(case["ratio"])
            cn.add(ctc_g, [y, w, x, v])
            cn.add(ctc_deriv, [x, v])
            cn.add(ctc_deriv, [y, w])
            cn.add(ctc_deriv, [h, phi])
            for ti, taui, zi in zip(ts, taus, zs, strict=True):
                cn.add(ctc_eval, [ti, taui, h, phi])
                cn.add(ctc_eval, [ti, zi, y, w])
        else:
            g = Function("y", "w", "x1", "x2", "v1", "v2", g_src)
            ctc_g = CtcFunction(g)

            def one_round() -> None:
                ctc_deriv.contract(x, v)
                ctc_g.contract(y, w, x[0], x[1], v[0], v[1])
                ctc_deriv.contract(y, w)
                ctc_deriv.contract(h, phi)
                for ti, taui, zi in zip(ts, taus, zs, strict=True):
                    ctc_eval.contract(ti, taui, h, phi)
                    ctc_eval.contract(ti, zi, y, w)
                    ctc_eval.contract(ti, taui, h, phi)
        build_s = time.perf_counter() - t_build
        n = h.nb_slices()
        idx, times = gate_times(h, case["every"])

        def t_width() -> float:
            return sum(ti.diam() for ti in ts)

        t = time.perf_counter()
        history, rounds, finished = [], 0, True
        if variant == "cn":
            cn.contract_during(limit)
            rounds = 1
            finished = cn.nb_ctc_in_stack() == 0
        else:
            prev, spent = math.inf, 0.0
            while True:
                t1 = time.perf_counter()
                one_round()
                vol = h.volume() + t_width()
                spent += time.perf_counter() - t1
                rounds += 1
                history.append(t_width())
                if math.isfinite(prev) and (prev - vol) <= case["rel_eps"] * prev:
                    break
                prev = vol
                if spent > limit or rounds >= case["max_iter"]:
                    finished = False
                    break
        wall = time.perf_counter() - t if variant == "cn" else spent
        return {"time_s": wall, "build_s": build_s, "finished": finished, "rounds": rounds,
                "t_width_history": history, "n_slices": n, "h_volume": h.volume(),
                "gate_index": idx, "h_gates": gates(h, times), "y_gates": gates(y, times),
                "t_lo": [_h(ti.lb()) for ti in ts], "t_hi": [_h(ti.ub()) for ti in ts],
                "z_lo": [_h(zi.lb()) for zi in zs], "z_hi": [_h(zi.ub()) for zi in zs],
                "empty": h.is_empty()}

    results = []
    for case in spec["cases"]:
        fn = robot if case["kind"] == "robot" else clock
        for variant in spec["variants"]:
            first = fn(case, variant, spec["limit_s"])
            rec = {"label": case["label"], "variant": variant, "first_run_s": first["time_s"]}
            if not first["finished"] or first["time_s"] > spec["limit_s"]:
                rec.update(skipped=f"not at its fixed point within {spec['limit_s']:g} s",
                           **{k: first[k] for k in ("rounds", "n_slices")})
                results.append(rec)
                print(f"codac {variant} {case['label']}: over the limit, skipped",
                      file=sys.stderr)
                continue
            runs = [first] + [fn(case, variant, spec["limit_s"])
                              for _ in range(spec["repeat"] - 1)]
            last = runs[-1]
            rec.update(last)
            rec["times_s"] = [r["time_s"] for r in runs]
            rec["time_s"] = statistics.median(rec["times_s"])
            rec["build_s"] = statistics.median(r["build_s"] for r in runs)
            results.append(rec)
            print(f"codac {variant} {case['label']}: {rec['time_s']:.3f} s "
                  f"({rec['rounds']} rounds)", file=sys.stderr)

    from importlib.metadata import version
    print(json.dumps({"codac_version": version("codac"), "python": sys.version.split()[0],
                      "import_s": import_s, "fegetround_before_import": mode_before,
                      "fegetround_after_import": mode_after, "results": results}))


if __name__ == "__main__":
    main()
