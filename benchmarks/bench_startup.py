"""Start-up benchmark: whole-process wall time of every command, cold and warm.

Each command runs as a user runs it, the ``boundest`` console script of this interpreter's
environment in a fresh process:

* **cold**: with ``NUMBA_CACHE_DIR`` set to a new empty folder (the first run after an
  install): the shipped kernel archive is unpacked into it (``boundest._kernels``) and
  nothing compiles when it matches the sources;
* **cold without the archive**: another empty folder and ``BOUNDEST_KERNEL_ARCHIVE=0``, so
  every kernel the command uses is compiled (``--skip-without`` leaves these out);
* **warm**: ``--repeat`` more runs with the first folder, every kernel loaded from it (the
  median and the minimum are recorded).

``boundest --help`` is timed ``--repeat`` times. With ``--install``, the README's first command
is timed too, from nothing: a new virtual environment, ``pip install -e .`` of this checkout
(from the same package index pip is configured with), then ``boundest run satellite`` with an
empty cache folder.

The load average is recorded before and after every measurement (``loadavg``: the 1-minute
value); a run on a loaded machine says so, and should be repeated when the machine is quiet.
On a shared machine, hold the benchmark lock::

    flock /tmp/boundest-bench.lock .venv/bin/python benchmarks/bench_startup.py \\
        --out benchmarks/results/startup.json [--repeat 3] [--install] [--only satellite,auv]

JSON goes to stdout (and to ``--out``); a table goes to stderr. The targets of the issue that
asked for it are in ``targets``: README first command (install included) < 90 s, ``run
satellite`` cold < 20 s, every other command cold < 30 s, every warm ``run`` < 2 s,
``--help`` < 0.3 s.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _machine import cpu_model, emit

from boundest._kernels_build import COMMANDS  # name -> arguments: the commands the archive covers

ROOT = Path(__file__).resolve().parents[1]
TARGETS = {"readme_first_command_s": 90.0, "satellite_cold_s": 20.0, "other_cold_s": 30.0,
           "warm_run_s": 2.0, "help_s": 0.3}


def loadavg() -> float | None:
    """The 1-minute load average (None where the OS does not report it)."""
    try:
        return os.getloadavg()[0]
    except OSError:
        return None


def boundest_script(python: Path) -> list[str]:
    """The console script next to ``python``, or ``python -m boundest.cli`` without one."""
    script = python.parent / "boundest"
    return [str(script)] if script.exists() else [str(python), "-m", "boundest.cli"]


def timed(argv: list[str], env: dict, cwd: Path, timeout: float) -> dict:
    """Run ``argv``; wall time, exit code, load before/after and the compile notice, if any."""
    before = loadavg()
    t0 = time.perf_counter()
    p = subprocess.run(argv, env=env, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                       check=False)
    wall = time.perf_counter() - t0
    notice = [ln for ln in p.stderr.splitlines() if ln.startswith("boundest: compiling")]
    out = {"wall_s": round(wall, 3), "rc": p.returncode, "loadavg_before": before,
           "loadavg_after": loadavg(), "compile_notice": notice[0] if notice else None}
    if p.returncode not in (0, 1):
        out["stderr_tail"] = p.stderr[-1500:]
    return out


def bench_command(name: str, cmd: list[str], repeat: int, timeout: float,
                  without: bool = True) -> dict:
    """Cold runs of one command (with the shipped kernel archive, then without it), each with a
    fresh cache folder, then warm runs on the first folder, in a scratch folder."""
    with tempfile.TemporaryDirectory(prefix=f"bench-startup-{name}-") as tmp:
        cache = Path(tmp) / "numba-cache"
        env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
        for var in ("BOUNDEST_KERNEL_ARCHIVE", "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
            env.pop(var, None)
        argv = [*boundest_script(Path(sys.executable)), *cmd]
        if cmd[0] != "solve":
            argv += ["--out", str(Path(tmp) / "out")]
        cold = timed(argv, env, Path(tmp), timeout)
        warm = [timed(argv, env, Path(tmp), timeout) for _ in range(repeat)]
        n_files = sum(1 for _ in cache.rglob("*.nbc"))
        size = sum(f.stat().st_size for f in cache.rglob("*.nb*"))
        cold_without = None
        if without:
            cache0 = Path(tmp) / "numba-cache-without"
            env0 = dict(env, NUMBA_CACHE_DIR=str(cache0), BOUNDEST_KERNEL_ARCHIVE="0")
            cold_without = timed(argv, env0, Path(tmp), timeout)
            cold_without["cache_files_nbc"] = sum(1 for _ in cache0.rglob("*.nbc"))
    ws = [w["wall_s"] for w in warm]
    shown = " ".join(cmd).replace(f"{ROOT}{os.sep}", "")
    return {"command": f"boundest {shown}", "cold": cold, "cold_without_archive": cold_without,
            "warm": warm, "warm_median_s": statistics.median(ws) if ws else None,
            "warm_min_s": min(ws) if ws else None,
            "cache_files_nbc": n_files, "cache_bytes": size}


def bench_help(repeat: int) -> dict:
    argv = [*boundest_script(Path(sys.executable)), "--help"]
    runs = [timed(argv, dict(os.environ), ROOT, 60) for _ in range(repeat)]
    ws = [r["wall_s"] for r in runs]
    return {"command": "boundest --help", "runs": runs, "median_s": statistics.median(ws),
            "min_s": min(ws)}


def bench_install(timeout: float) -> dict:
    """The README's first command from nothing: venv, editable install, satellite run."""
    with tempfile.TemporaryDirectory(prefix="bench-startup-install-") as tmp:
        venv = Path(tmp) / "venv"
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "numba-cache"))
        env.pop("VIRTUAL_ENV", None)
        base = getattr(sys, "_base_executable", None) or shutil.which("python3") or "python3"
        steps = {}
        t0 = time.perf_counter()
        steps["venv"] = timed([base, "-m", "venv", str(venv)], env, ROOT, timeout)
        steps["pip_install"] = timed([str(venv / "bin" / "pip"), "install", "-q", "-e",
                                      str(ROOT)], env, Path(tmp), timeout)
        steps["run_satellite"] = timed([str(venv / "bin" / "boundest"), "run", "satellite",
                                        "--out", str(Path(tmp) / "out")], env, Path(tmp),
                                       timeout)
        total = time.perf_counter() - t0
    return {"command": "python3 -m venv .venv && .venv/bin/pip install -e . && "
                       ".venv/bin/boundest run satellite (empty Numba cache)",
            "total_s": round(total, 2), "steps": steps}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", help="also write the JSON to this file")
    ap.add_argument("--repeat", type=int, default=3, help="warm runs per command (default 3)")
    ap.add_argument("--only", help="comma-separated command names (default: all): "
                    + ", ".join(COMMANDS))
    ap.add_argument("--install", action="store_true",
                    help="also time the README's first command in a new virtual environment")
    ap.add_argument("--timeout", type=float, default=900.0, help="per process, seconds")
    ap.add_argument("--skip-without", action="store_true",
                    help="skip the cold runs without the kernel archive (they compile)")
    args = ap.parse_args(argv)
    names = list(COMMANDS) if not args.only else args.only.split(",")
    unknown = [n for n in names if n not in COMMANDS]
    if unknown:
        ap.error(f"unknown command(s): {', '.join(unknown)}")

    import numba
    import numpy

    from boundest import _kernels

    manifest = _kernels.read_manifest() or {}
    doc: dict = {"benchmark": "startup", "machine": {
        "cpu": cpu_model(), "cores": os.cpu_count(), "python": platform.python_version(),
        "numpy": numpy.__version__, "numba": numba.__version__},
        "kernel_archive": {"refused": _kernels.refusal(_kernels.read_manifest()),
                           "archive_bytes": manifest.get("archive_bytes"),
                           "unpacked_bytes": manifest.get("unpacked_bytes"),
                           "files": len(manifest.get("files", []))},
        "targets": TARGETS, "started_loadavg": loadavg()}
    doc["help"] = bench_help(max(args.repeat, 5))
    print(f"{'boundest --help':<28} median {doc['help']['median_s']:6.2f} s", file=sys.stderr)
    doc["commands"] = {}
    for name in names:
        r = bench_command(name, COMMANDS[name], args.repeat, args.timeout,
                          without=not args.skip_without)
        doc["commands"][name] = r
        c0 = r["cold_without_archive"]
        without = (f", without archive {c0['wall_s']:6.1f} s (load {c0['loadavg_before']})"
                   if c0 else "")
        print(f"{name:<16} cold {r['cold']['wall_s']:6.1f} s (load {r['cold']['loadavg_before']}"
              f"){without}; warm median {r['warm_median_s']:5.2f} s min "
              f"{r['warm_min_s']:5.2f} s; rc "
              f"{r['cold']['rc']}; {r['cache_files_nbc']} cached kernels "
              f"{r['cache_bytes'] / 1e6:.1f} MB", file=sys.stderr)
    if args.install:
        doc["readme_first_command"] = bench_install(args.timeout)
        inst = doc["readme_first_command"]
        print(f"{'README first command':<28} {inst['total_s']:6.1f} s (pip "
              f"{inst['steps']['pip_install']['wall_s']:.1f} s, satellite "
              f"{inst['steps']['run_satellite']['wall_s']:.1f} s)", file=sys.stderr)
    doc["finished_loadavg"] = loadavg()
    emit(doc, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
