"""Codac 1.5.7 side of the AUV mine-survey benchmark (``boundest.scenarios.auv_data``).

Run it with the interpreter of ``.bench-venv-codac1/`` (``codac==1.5.7``, a benchmark-only
dependency), never in the process that runs boundest: importing codac switches the FPU to
rounding upward. Protocol (as ``_subprocess.run_json_script`` runs it)::

    .bench-venv-codac1/bin/python benchmarks/auv_codac.py SPEC.json

The spec is a JSON object whose floats are ``float.hex`` strings, decoded *before* codac is
imported (``fegetround`` is recorded before and after the import); one JSON document comes back
on stdout (enclosures as ``float.hex`` strings), progress goes to stderr.

Spec fields (arrays row-major, lists of ``float.hex`` strings): ``n``; ``dt_lo``, ``dt_hi`` (the
decimal 0.1 enclosed); ``att_lo``, ``att_hi`` (n x 3: phi, theta, psi); ``vel_lo``, ``vel_hi``
(n x 3, body frame); ``alt_lo``, ``alt_hi`` (n); ``depth_lo``, ``depth_hi`` (n); ``fix_k``
(ints), ``fix_lo``, ``fix_hi`` (f x 3: north, east, depth); ``det_k``, ``det_mine`` (ints),
``r_lo``, ``r_hi``; ``n_mines``; ``seabed_tol``; ``modes`` (``"localization"`` and/or
``"slam"``); ``rel_eps``; ``repeat``.

Model. World NED ``p = (north, east, depth)``, body to world ``R = R_psi R_theta R_phi``,
attitude and body velocity held over each sample, so ``p[k+1] = p[k] + dt R[k] v[k]``. Time in
the tubes is counted in samples: tdomain ``[0, n-1]``, timestep 1, so slice ``k`` is
``[k, k+1]`` and gate ``k`` is ``p[k]``; the derivative tube ``[w]`` holds
``[dt] R([att_k]) [v_k]`` over slice ``k`` (a Codac ``Function`` evaluated on the sample's box,
``Function.eval_vector``). The position tube ``[p]``: north and east unbounded except the GPS
boxes at the fix gates (``Tube.set``); depth built as ``Tube(lb, ub, 1)`` from two
``Trajectory`` objects through the gate values ``[max(depth_lo, 0), depth_hi]`` (the depth box
and ``p_z >= 0`` at every gate; the slice codomains are the hulls of adjacent gates, sound since
``p`` is affine over a slice), intersected with the fix's depth box at the fix gates. (Setting
60,000 gates one by one with ``Tube.set`` costs O(n) each in Codac 1, about 12 s.)

``localization``: ``CtcDeriv`` (forward and backward, ``preserve_slicing(True)``) applied on
``([p], [w])`` until the volume of ``[p]`` decreases by less than ``rel_eps`` (relative) in a
round (two rounds: the first sweep reaches the fixed point). Build (evaluating ``[w]``, making
the tubes) and contraction are timed separately.

``slam``: the same tubes, the mines as ``IntervalVector(3)`` domains (unbounded), and per
detection ``i`` at sample ``k``: ``p_i`` (``IntervalVector(3)``) tied to the tube by ``CtcEval``
with the degenerate date ``Interval(k)`` (``p_i = [p](k)``, a gate; ``preserve_slicing(True)``,
``enable_time_propag(spec.get("eval_time_propag", False))``), the attitude box ``a_i`` of
sample ``k``, the body-frame offset ``b_i = R^T (m - p_i)`` in ``{0} x [0, oo) x [0, oo)``, and
the ``CtcFunction`` s::

    m - p_i - R(a_i) b_i      = 0                (1) side-scan plane, starboard, below
    |m - p_i|                 in [r_i]           (2) slant range
    |b_i|                     in [r_i]           (2) again, through b_i (R is orthogonal)
    m_z - p_i,z               in [alt_k] + [-tol, tol]         (3) seabed

Constraint (1) is written with ``b_i`` as a variable (``m - p = R b``) rather than as
``R^T (m - p)`` in the cone: HC4 on the latter barely contracts ``m`` (a tilted plane through a
box; mine 4 came out 51 m wide instead of 12 m). ``slam_variant`` (spec, optional):
``"rounds"`` (default) puts the detection contractors and the ``CtcEval`` s in one
``ContractorNetwork`` (``set_fixedpoint_ratio(rel_eps)``) and alternates
``CtcDeriv.contract([p], [w])`` and ``trigger_all_contractors(); contract()`` until the volume of
``[p]`` decreases by less than ``rel_eps`` in a round (``iterations`` = rounds); ``"cn"`` also
adds ``CtcDeriv`` on ``([p], [w])`` to the network, which splits it into one contractor per
slice and runs one ``contract()`` (``contract_during(limit_s)`` if ``limit_s`` is given). The
latter is quadratic in n in Codac 1.5.7 (2.4 s at n = 4000, 9.7 s at 8000, with or without
detections; over 9 min at 60,000), the former about 18 s on 2 cores; both give the same boxes on
the 8000-sample prefix. The network reports no iteration count; ``contract(verbose=True)``
prints to C++ ``stdout``, captured (file descriptor 1 redirected) and returned as ``cn_log``.

Reported per mode: median wall times over ``repeat`` runs (``build_s``, ``contract_s``,
``total_s``) and process CPU time (``time.process_time``), mean/max gate width of north, east,
depth over the n gates (read after the contraction, untimed, through ``enable_synthesis`` for
O(log n) evaluations), the gates at the fixes and detections, the mine boxes (SLAM) as hex, and
the peak RSS (``ru_maxrss``, kB) at the end of the mode.
"""

from __future__ import annotations

import json
import os
import resource
import statistics
import sys
import tempfile
import time
from typing import Any

from _subprocess import decode_hex, fegetround


def _h(v: float) -> str:
    return float(v).hex()




def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


# p' = dt R v with R = R_psi R_theta R_phi; a = (phi, theta, psi), v body, d = [dt]
_RV = ("(d*(cos(a[2])*cos(a[1])*v[0]"
       " + (cos(a[2])*sin(a[1])*sin(a[0]) - sin(a[2])*cos(a[0]))*v[1]"
       " + (cos(a[2])*sin(a[1])*cos(a[0]) + sin(a[2])*sin(a[0]))*v[2]) ;"
       " d*(sin(a[2])*cos(a[1])*v[0]"
       " + (sin(a[2])*sin(a[1])*sin(a[0]) + cos(a[2])*cos(a[0]))*v[1]"
       " + (sin(a[2])*sin(a[1])*cos(a[0]) - cos(a[2])*sin(a[0]))*v[2]) ;"
       " d*(-sin(a[1])*v[0] + cos(a[1])*sin(a[0])*v[1] + cos(a[1])*cos(a[0])*v[2]))")

# constraint (1) as m - p = R(a) b with b in {0} x [0, oo) x [0, oo) (b = R^T (m - p))
_BODY = ("(m[0] - p[0] - (cos(a[2])*cos(a[1])*b[0]"
         " + (cos(a[2])*sin(a[1])*sin(a[0]) - sin(a[2])*cos(a[0]))*b[1]"
         " + (cos(a[2])*sin(a[1])*cos(a[0]) + sin(a[2])*sin(a[0]))*b[2]) ;"
         " m[1] - p[1] - (sin(a[2])*cos(a[1])*b[0]"
         " + (sin(a[2])*sin(a[1])*sin(a[0]) + cos(a[2])*cos(a[0]))*b[1]"
         " + (sin(a[2])*sin(a[1])*cos(a[0]) - cos(a[2])*sin(a[0]))*b[2]) ;"
         " m[2] - p[2] - (-sin(a[1])*b[0] + cos(a[1])*sin(a[0])*b[1]"
         " + cos(a[1])*cos(a[0])*b[2]))")
_BNORM = "sqrt(b[0]^2 + b[1]^2 + b[2]^2)"
_RANGE = "sqrt((m[0]-p[0])^2 + (m[1]-p[1])^2 + (m[2]-p[2])^2)"
_SEABED = "m[2] - p[2]"


class _CaptureStdout:
    """Redirects file descriptor 1 (C++ ``std::cout``) to a temporary file."""

    def __enter__(self) -> _CaptureStdout:
        sys.stdout.flush()
        self._file = tempfile.TemporaryFile(mode="w+b")
        self._saved = os.dup(1)
        os.dup2(self._file.fileno(), 1)
        self.text = ""
        return self

    def __exit__(self, *exc: object) -> None:
        sys.stdout.flush()
        os.dup2(self._saved, 1)
        os.close(self._saved)
        self._file.seek(0)
        self.text = self._file.read().decode(errors="replace")
        self._file.close()


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
        Trajectory,
        Tube,
        TubeVector,
        oo,
    )
    import_s = time.perf_counter() - t0
    mode_after = fegetround()

    n: int = spec["n"]
    rows = range(n)
    att = [(spec["att_lo"][3 * k:3 * k + 3], spec["att_hi"][3 * k:3 * k + 3]) for k in rows]
    vel = [(spec["vel_lo"][3 * k:3 * k + 3], spec["vel_hi"][3 * k:3 * k + 3]) for k in rows]
    fix_k: list[int] = spec["fix_k"]
    det_k: list[int] = spec["det_k"]
    det_mine: list[int] = spec["det_mine"]
    rel_eps: float = spec["rel_eps"]
    tol: float = spec["seabed_tol"]

    def box(lo: list[float], hi: list[float]) -> Any:
        return IntervalVector([[a, b] for a, b in zip(lo, hi, strict=True)])

    def build() -> tuple[Any, Any]:
        """The derivative tube ``[w]`` (per sample) and the position tube ``[p]``."""
        f = Function("a[3]", "v[3]", "d", _RV)
        d = [spec["dt_lo"], spec["dt_hi"]]
        w = [f.eval_vector(IntervalVector([*[[a, b] for a, b in zip(*att[k], strict=True)],
                                           *[[a, b] for a, b in zip(*vel[k], strict=True)],
                                           d]))
             for k in range(n - 1)]
        w_tube = TubeVector([Interval(k, k + 1) for k in range(n - 1)], w)
        tdom = Interval(0, n - 1)
        north, east = Tube(tdom, 1.0), Tube(tdom, 1.0)
        zlo = {float(k): max(spec["depth_lo"][k], 0.0) for k in rows}
        zhi = {float(k): spec["depth_hi"][k] for k in rows}
        for i, k in enumerate(fix_k):
            zlo[float(k)] = max(zlo[float(k)], spec["fix_lo"][3 * i + 2])
            zhi[float(k)] = min(zhi[float(k)], spec["fix_hi"][3 * i + 2])
        depth = Tube(Trajectory(zlo), Trajectory(zhi), 1.0)
        for i, k in enumerate(fix_k):
            north.set(Interval(spec["fix_lo"][3 * i], spec["fix_hi"][3 * i]), float(k))
            east.set(Interval(spec["fix_lo"][3 * i + 1], spec["fix_hi"][3 * i + 1]), float(k))
        p_tube = TubeVector([north, east, depth])
        return p_tube, w_tube

    def widths(p_tube: Any) -> dict[str, Any]:
        """Gate widths per axis (mean, max) and the gates at the fixes and detections."""
        out: dict[str, Any] = {}
        for j, name in enumerate(("north", "east", "depth")):
            comp = Tube(p_tube[j])
            comp.enable_synthesis()
            gates = [comp(float(k)) for k in rows]
            diams = [g.diam() for g in gates]
            out[f"{name}_mean"] = statistics.fmean(diams)
            out[f"{name}_max"] = max(diams)
            out[f"{name}_at_fix"] = [[_h(gates[k].lb()), _h(gates[k].ub())] for k in fix_k]
            out[f"{name}_at_det"] = [[_h(gates[k].lb()), _h(gates[k].ub())] for k in det_k]
        return out

    def localization() -> dict[str, Any]:
        c0, t_b = time.process_time(), time.perf_counter()
        p_tube, w_tube = build()
        t_c = time.perf_counter()
        build_s = t_c - t_b
        ctc = CtcDeriv()
        ctc.preserve_slicing(True)
        prev, rounds = float("inf"), 0
        while True:
            ctc.contract(p_tube, w_tube)
            rounds += 1
            vol = p_tube.volume()
            if prev < float("inf") and prev - vol <= rel_eps * prev:
                break
            prev = vol
        t_e = time.perf_counter()
        cpu = time.process_time() - c0
        return {"build_s": build_s, "contract_s": t_e - t_c, "total_s": t_e - t_b,
                "cpu_s": cpu, "rounds": rounds, "empty": p_tube.is_empty(),
                "p_tube": p_tube}

    def slam() -> dict[str, Any]:
        c0, t_b = time.process_time(), time.perf_counter()
        p_tube, w_tube = build()
        ctc_deriv = CtcDeriv()
        ctc_deriv.preserve_slicing(True)
        ctc_eval = CtcEval()
        ctc_eval.preserve_slicing(True)
        ctc_eval.enable_time_propag(bool(spec.get("eval_time_propag", False)))
        f_body = Function("m[3]", "p[3]", "a[3]", "b[3]", _BODY)
        f_range = Function("m[3]", "p[3]", _RANGE)
        f_bnorm = Function("b[3]", _BNORM)
        f_seabed = Function("m[3]", "p[3]", _SEABED)
        c_body = CtcFunction(f_body, IntervalVector(3, Interval(0.0)))
        mines = [IntervalVector(3) for _ in range(spec["n_mines"])]
        keep: list[Any] = [f_body, f_range, f_bnorm, f_seabed, c_body, ctc_deriv, ctc_eval]
        variant = spec.get("slam_variant", "rounds")
        cn = ContractorNetwork()
        cn.set_fixedpoint_ratio(rel_eps)
        if variant == "cn":
            cn.add(ctc_deriv, [p_tube, w_tube])
        p_det = []
        for i, (k, j) in enumerate(zip(det_k, det_mine, strict=True)):
            t_i = Interval(k)
            p_i = IntervalVector(3)
            a_i = box(*att[k])
            seabed = Interval(spec["alt_lo"][k], spec["alt_hi"][k]) + Interval(-tol, tol)
            b_i = IntervalVector([[0, 0], [0, oo], [0, oo]])
            r_i = Interval(spec["r_lo"][i], spec["r_hi"][i])
            c_range = CtcFunction(f_range, r_i)
            c_bnorm = CtcFunction(f_bnorm, r_i)
            c_seabed = CtcFunction(f_seabed, seabed)
            keep += [t_i, p_i, a_i, b_i, r_i, c_range, c_bnorm, c_seabed]
            p_det.append(p_i)
            cn.add(ctc_eval, [t_i, p_i, p_tube, w_tube])
            cn.add(c_body, [mines[j], p_i, a_i, b_i])
            cn.add(c_bnorm, [b_i])
            cn.add(c_range, [mines[j], p_i])
            cn.add(c_seabed, [mines[j], p_i])
        t_c = time.perf_counter()
        build_s = t_c - t_b
        rounds, log = 0, ""
        if variant == "cn":
            with _CaptureStdout() as cap:
                if spec.get("limit_s") is None:
                    cn.contract(True)
                else:
                    cn.contract_during(spec["limit_s"], True)
            rounds, log = 1, cap.text
        else:
            prev = float("inf")
            while True:
                ctc_deriv.contract(p_tube, w_tube)
                cn.trigger_all_contractors()
                with _CaptureStdout() as cap:
                    cn.contract(True)
                rounds += 1
                log += cap.text
                vol = p_tube.volume()
                _log(f"  codac auv slam round {rounds}: {time.perf_counter() - t_c:.2f} s")
                if prev < float("inf") and prev - vol <= rel_eps * prev:
                    break
                prev = vol
        t_e = time.perf_counter()
        cpu = time.process_time() - c0
        return {"build_s": build_s, "contract_s": t_e - t_c, "total_s": t_e - t_b,
                "cpu_s": cpu, "nb_ctc": cn.nb_ctc(), "nb_dom": cn.nb_dom(),
                "nb_ctc_in_stack": cn.nb_ctc_in_stack(),
                "finished": cn.nb_ctc_in_stack() == 0, "variant": variant,
                "iterations": rounds, "cn_log": log[-4000:],
                "empty": p_tube.is_empty(),
                "mines_lo": [[_h(m[a].lb()) for a in range(3)] for m in mines],
                "mines_hi": [[_h(m[a].ub()) for a in range(3)] for m in mines],
                "p_det_lo": [[_h(p[a].lb()) for a in range(3)] for p in p_det],
                "p_det_hi": [[_h(p[a].ub()) for a in range(3)] for p in p_det],
                "p_tube": p_tube, "keep": keep}

    results: dict[str, Any] = {}
    for mode in spec["modes"]:
        fn = {"localization": localization, "slam": slam}[mode]
        runs = []
        for r in range(spec["repeat"]):
            run = fn()
            _log(f"codac auv {mode} run {r + 1}: build {run['build_s']:.2f} s, contract "
                 f"{run['contract_s']:.2f} s, cpu {run['cpu_s']:.2f} s")
            if r < spec["repeat"] - 1:
                run.pop("p_tube")
                run.pop("keep", None)
            runs.append(run)
        last = runs[-1]
        rec = {k: v for k, v in last.items() if k not in ("p_tube", "keep")}
        rec.update(widths(last.pop("p_tube")))
        last.pop("keep", None)
        for key in ("build_s", "contract_s", "total_s", "cpu_s"):
            rec[f"{key}_runs"] = [run[key] for run in runs]
            rec[key] = statistics.median(rec[f"{key}_runs"])
        rec["peak_rss_kb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        if mode == "slam":
            rec["mine_widths"] = [[float.fromhex(hi) - float.fromhex(lo)
                                   for lo, hi in zip(mlo, mhi, strict=True)]
                                  for mlo, mhi in zip(rec["mines_lo"], rec["mines_hi"],
                                                      strict=True)]
        _log(f"codac auv {mode}: {rec['total_s']:.2f} s wall, {rec['cpu_s']:.2f} s cpu, "
             f"mean width n/e/d {rec['north_mean']:.2f}/{rec['east_mean']:.2f}/"
             f"{rec['depth_mean']:.3f} m, peak {rec['peak_rss_kb'] / 1024:.0f} MB")
        results[mode] = rec

    from importlib.metadata import version
    print(json.dumps({"codac_version": version("codac"), "python": sys.version.split()[0],
                      "import_s": import_s, "fe_round_before": mode_before,
                      "fe_round_after": mode_after, "n": n, "results": results}))


if __name__ == "__main__":
    main()
