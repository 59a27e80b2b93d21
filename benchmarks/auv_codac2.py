"""Codac 2.x side of the AUV localization comparison (``boundest.scenarios.auv.localize``).

Run it with the interpreter of ``.bench-venv-codac2/`` (``pip install "codac>=2,<3" numpy``),
never in the process that runs boundest: importing codac switches the FPU to rounding upward
(``fegetround`` is recorded before and after the import). Input: a JSON file in which every
float is a ``float.hex`` string, decoded *before* codac is imported; arrays are flat row-major
lists. Output: one JSON document on stdout (enclosures as ``float.hex`` strings, flat row-major
like the input); progress on stderr.

Spec fields: ``n``; ``dt_lo``, ``dt_hi`` (the decimal sampling period enclosed); ``att_lo``,
``att_hi`` (n x 3: phi, theta, psi); ``vel_lo``, ``vel_hi`` (n x 3: body velocity);
``depth_lo``, ``depth_hi`` (n); ``fix_k`` (ints); ``fix_lo``, ``fix_hi`` (f x 3: north, east,
depth); ``repeat`` (runs timed, median reported); optional ``modes`` (a subset of
``centered``, ``natural``, ``default``; all three by default) and ``check_recurrence``
(default true); optional ``positions_modes`` and ``w_modes`` (modes whose position gates
or world velocities are also written out; none by default).

Model (data set section 1.3): world velocity ``w[k] = R(phi, theta, psi)[k] v[k]`` with
``R = R_psi R_theta R_phi``, attitude and body velocity held over each sample, and
``p[k+1] = p[k] + dt w[k]``.

1. ``w[k]`` by one Codac ``AnalyticFunction`` of the six scalars ``(phi, theta, psi, vx, vy,
   vz)`` -> 3-vector (the entries of ``R v`` written out), evaluated per sample with
   ``EvalMode.CENTERED`` (the mean-value form alone), ``EvalMode.NATURAL`` (the natural
   extension) and ``EvalMode.DEFAULT`` (Codac's intersection of the two). The centred form
   alone can be *wider* than the natural one on some components.
2. Localization with Codac's ``CtcDeriv`` (default: forward-backward, fast mode) on two
   ``SlicedTube`` of ``IntervalVector`` over ``create_tdomain([0, n-1], 1, with_gates=True)``:
   time in samples, one slice per sample and a gate at every sample (2n - 1 tslices). The
   derivative tube's slice ``k`` holds ``[dt] * w[k]`` (its gates are left unbounded; slices
   are set with ``propagate=False`` so that no gate is the intersection of two adjacent,
   disjoint slices). The position tube starts as ``R x R x [0, oo)`` (``p_z >= 0``) with the
   depth box on every gate and the GPS box intersected into the gates ``fix_k``. One
   ``contract`` (forward then backward) is the fixed point of these constraints on a chain.
   With ``check_recurrence``, the same gates are also computed by the explicit
   ``IntervalVector`` recurrence in a Python loop (forward ``p[k+1] &= p[k] + dt w[k]``, then
   backward ``p[k] &= p[k+1] - dt w[k]``) and compared (``recurrence_max_abs_diff``).

Output fields: ``codac_version``, ``python``, ``import_s``, ``fegetround_before_import``,
``fegetround_after_import``, ``fegetround_end``, ``n``, ``method``, ``repeat``;
``positions_lo``, ``positions_hi`` (n x 3, centred mode, the tube's gates);
``modes[mode]``: ``consistent``, ``mean_width``, ``max_width`` (per axis, of the position
gates), ``w_mean_width``, ``w_max_width`` (of ``w``), ``w_eval_s`` (median) and
``w_eval_times_s``, ``tube_build_s`` (median: tdomain, two tubes, slices and gates set),
``ctc_deriv_s`` (median of the ``contract`` call) and ``ctc_deriv_times_s``,
``recurrence_s``, ``recurrence_times_s``, ``recurrence_max_abs_diff`` (with
``check_recurrence``); ``positions_lo``, ``positions_hi`` for the modes in
``positions_modes``, ``w_lo``, ``w_hi`` (n x 3, ``w`` itself, not ``dt w``) for those in
``w_modes``.

Usage::

    .bench-venv-codac2/bin/python benchmarks/auv_codac2.py SPEC.json > OUT.json
"""

from __future__ import annotations

import json
import math
import statistics
import sys
import time

from _subprocess import decode_hex, fegetround

MODES = ("centered", "natural", "default")


def _h(v: float) -> str:
    return float(v).hex()




def _rows(flat: list, width: int) -> list:
    return [flat[i:i + width] for i in range(0, len(flat), width)]


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def main() -> None:
    with open(sys.argv[1]) as fh:
        spec = decode_hex(json.load(fh))      # decoded under round-to-nearest, before codac
    mode_before = fegetround()
    t0 = time.perf_counter()
    from codac import (
        AnalyticFunction,
        CtcDeriv,
        EvalMode,
        Interval,
        IntervalVector,
        ScalarVar,
        SlicedTube,
        cos,
        create_tdomain,
        oo,
        sin,
        vec,
    )
    import_s = time.perf_counter() - t0
    mode_after = fegetround()

    n = int(spec["n"])
    repeat = max(1, int(spec.get("repeat", 1)))
    modes = spec.get("modes", list(MODES))
    check = bool(spec.get("check_recurrence", True))
    positions_modes = set(spec.get("positions_modes", []))
    w_modes = set(spec.get("w_modes", []))
    dt = Interval(spec["dt_lo"], spec["dt_hi"])
    att = list(zip(_rows(spec["att_lo"], 3), _rows(spec["att_hi"], 3), strict=True))
    vel = list(zip(_rows(spec["vel_lo"], 3), _rows(spec["vel_hi"], 3), strict=True))
    args = [[Interval(lo[i], hi[i]) for lo, hi in (a, b) for i in range(3)]
            for a, b in zip(att, vel, strict=True)]
    assert len(args) == n
    depth = [Interval(lo, hi) & Interval(0.0, oo)
             for lo, hi in zip(spec["depth_lo"], spec["depth_hi"], strict=True)]
    fixes = {int(k): IntervalVector([[a, b] for a, b in zip(lo, hi, strict=True)])
             for k, lo, hi in zip(spec["fix_k"], _rows(spec["fix_lo"], 3),
                                  _rows(spec["fix_hi"], 3), strict=True)}

    # R v with R = R_psi R_theta R_phi, written out entry by entry
    phi, theta, psi, vx, vy, vz = (ScalarVar() for _ in range(6))
    cf, sf, ct, st, cp, sp = cos(phi), sin(phi), cos(theta), sin(theta), cos(psi), sin(psi)
    f = AnalyticFunction([phi, theta, psi, vx, vy, vz], vec(
        cp * ct * vx + (cp * st * sf - sp * cf) * vy + (cp * st * cf + sp * sf) * vz,
        sp * ct * vx + (sp * st * sf + cp * cf) * vy + (sp * st * cf - cp * sf) * vz,
        -st * vx + ct * sf * vy + ct * cf * vz))
    eval_mode = {"centered": EvalMode.CENTERED, "natural": EvalMode.NATURAL,
                 "default": EvalMode.DEFAULT}

    def gate_box(k: int):
        box = IntervalVector([[-oo, oo], [-oo, oo], [0.0, oo]])
        box[2] = depth[k]
        if k in fixes:
            box = box & fixes[k]
        return box

    def tube_localize(dtw: list) -> tuple[list, float, float]:
        """Gates of the position tube after ``CtcDeriv``; build and contract times."""
        t_build = time.perf_counter()
        td = create_tdomain(Interval(0.0, float(n - 1)), 1.0, True)
        x = SlicedTube(td, IntervalVector([[-oo, oo], [-oo, oo], [0.0, oo]]))
        v = SlicedTube(td, IntervalVector(3))
        s, k = v.first_slice(), 0
        while s is not None:
            if not s.is_gate():
                s.set(dtw[k], False)
                k += 1
            s = s.next_slice()
        assert k == n - 1, (k, n)
        s, k = x.first_slice(), 0
        while s is not None:
            if s.is_gate():
                s.set(gate_box(k), False)
                k += 1
            s = s.next_slice()
        assert k == n, (k, n)
        build_s = time.perf_counter() - t_build
        t1 = time.perf_counter()
        CtcDeriv().contract(x, v)
        ctc_s = time.perf_counter() - t1
        gates = []
        s = x.first_slice()
        while s is not None:
            if s.is_gate():
                gates.append(s.codomain())
            s = s.next_slice()
        return gates, build_s, ctc_s

    def recurrence(dtw: list) -> tuple[list, float]:
        t1 = time.perf_counter()
        p = [gate_box(k) for k in range(n)]
        for k in range(n - 1):
            p[k + 1] = p[k + 1] & (p[k] + dtw[k])
        for k in range(n - 2, -1, -1):
            p[k] = p[k] & (p[k + 1] - dtw[k])
        return p, time.perf_counter() - t1

    def bounds(boxes: list) -> tuple[list, list]:
        return ([[b[i].lb() for i in range(3)] for b in boxes],
                [[b[i].ub() for i in range(3)] for b in boxes])

    def widths(lo: list, hi: list) -> tuple[list, list]:
        w = [[h - l for l, h in zip(a, b, strict=True)] for a, b in zip(lo, hi, strict=True)]
        return ([math.fsum(r[i] for r in w) / len(w) for i in range(3)],
                [max(r[i] for r in w) for i in range(3)])

    out_modes, positions = {}, None
    for mode in modes:
        em = eval_mode[mode]
        w_times = []
        for _ in range(repeat):
            t1 = time.perf_counter()
            w = [f.eval(em, *a) for a in args]
            w_times.append(time.perf_counter() - t1)
        _log(f"codac2 {mode}: R v in {statistics.median(w_times):.3f} s")
        dtw = [dt * wk for wk in w[: n - 1]]
        runs = [tube_localize(dtw) for _ in range(repeat)]
        gates = runs[-1][0]
        _log(f"codac2 {mode}: CtcDeriv in {statistics.median(r[2] for r in runs):.3f} s")
        lo, hi = bounds(gates)
        consistent = not any(g.is_empty() for g in gates)
        rec = {"consistent": consistent,
               "w_eval_s": statistics.median(w_times), "w_eval_times_s": w_times,
               "tube_build_s": statistics.median(r[1] for r in runs),
               "ctc_deriv_s": statistics.median(r[2] for r in runs),
               "ctc_deriv_times_s": [r[2] for r in runs]}
        wlo, whi = bounds(w)
        rec["w_mean_width"], rec["w_max_width"] = widths(wlo, whi)
        if consistent:
            rec["mean_width"], rec["max_width"] = widths(lo, hi)
        if check:
            rruns = [recurrence(dtw) for _ in range(repeat)]
            rlo, rhi = bounds(rruns[-1][0])
            rec["recurrence_s"] = statistics.median(r[1] for r in rruns)
            rec["recurrence_times_s"] = [r[1] for r in rruns]
            diff = [abs(a - b) for ra, rb in ((lo, rlo), (hi, rhi))
                    for xa, xb in zip(ra, rb, strict=True)
                    for a, b in zip(xa, xb, strict=True) if a != b]
            rec["recurrence_max_abs_diff"] = max(diff, default=0.0)
            _log(f"codac2 {mode}: recurrence in {rec['recurrence_s']:.3f} s, "
                 f"max |diff| to CtcDeriv {rec['recurrence_max_abs_diff']:.3g}")
        if mode in positions_modes:
            rec["positions_lo"] = [_h(v) for row in lo for v in row]
            rec["positions_hi"] = [_h(v) for row in hi for v in row]
        if mode in w_modes:
            rec["w_lo"] = [_h(v) for row in wlo for v in row]
            rec["w_hi"] = [_h(v) for row in whi for v in row]
        out_modes[mode] = rec
        if mode == "centered":
            positions = (lo, hi)

    from importlib.metadata import version
    doc = {"codac_version": version("codac"), "python": sys.version.split()[0],
           "import_s": import_s, "fegetround_before_import": mode_before,
           "fegetround_after_import": mode_after, "fegetround_end": fegetround(),
           "n": n, "repeat": repeat,
           "method": "CtcDeriv (FWD_BWD) on SlicedTube<IntervalVector>, tdomain [0, n-1], "
                     "dt 1, with gates",
           "modes": out_modes}
    if positions is not None:
        doc["positions_lo"] = [_h(v) for row in positions[0] for v in row]
        doc["positions_hi"] = [_h(v) for row in positions[1] for v in row]
    print(json.dumps(doc))


if __name__ == "__main__":
    main()
