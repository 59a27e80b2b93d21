"""Building and verifying the kernel archive (``boundest._kernels``): a tool, not a layer.

``python -m boundest._kernels_build build`` compiles every command's kernels into an empty
cache (each command in a new process, a few minutes on 2 cores) and writes
``data/kernels.tar.xz`` and ``data/kernels.json``; ``verify`` runs every command with a fresh
cache from the archive and fails if anything compiles; ``build | verify COMMAND ...`` takes
some commands only (a quick try). Each rebuild adds the archive's size (about 11 MB) to the
repository's history: rebuild once per change that needs it (``python -m boundest._kernels
check`` says when).

It runs the command line and the library's kernels, so it sits above every layer; no module
of the package imports it (``tests/test_layers.py`` checks it).
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import sys
import tarfile
import tempfile
from pathlib import Path

from ._kernels import (
    ARCHIVE,
    ENV_SWITCH,
    MANIFEST,
    TARGET_CPU,
    TARGET_FEATURES,
    _write_atomic,
    running_versions,
)
from ._numba_cache import _PKG, numba_sources_digest

#: name -> arguments of ``boundest``: the commands whose kernels the archive holds
COMMANDS: dict[str, list[str]] = {
    "satellite": ["run", "satellite"],
    "jaulin2001": ["run", "jaulin2001"],
    "range-only": ["run", "range-only"],
    "drifting-clock": ["run", "drifting-clock"],
    "auv": ["run", "auv"],
    "pool": ["run", "pool"],
    "pool-online": ["run", "pool", "--online"],
    "solve": ["solve", str(_PKG / "data" / "satellite_k200.txt")],
    "demo": ["demo"],
}


def _run_logged(argv: list[str], env: dict, log: Path, timeout: float) -> dict:
    """``boundest ARGV`` in a new process that records every Numba compilation."""
    import subprocess
    import time

    env = dict(env, BOUNDEST_COMPILE_LOG=str(log))
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "boundest._kernels_build", "_run", *argv], env=env,
                       capture_output=True, text=True, timeout=timeout, check=False)
    wall = time.perf_counter() - t0
    try:
        rec = json.loads(log.read_text())
    except (OSError, ValueError):
        rec = {"compiled": None, "status": None}
    return {"rc": p.returncode, "wall_s": round(wall, 1), **rec,
            "stderr_tail": p.stderr[-1500:] if p.returncode not in (0, 1) else ""}


def _command_argv(name: str, out: Path) -> list[str]:
    argv = list(COMMANDS[name])
    return argv if argv[0] == "solve" else [*argv, "--out", str(out)]


def _logged_main(argv: list[str]) -> int:
    """Run ``boundest ARGV``, writing the kernels Numba compiled to $BOUNDEST_COMPILE_LOG."""
    from numba.core import event

    compiled: list[str] = []

    class _Log(event.Listener):
        def on_start(self, ev: event.Event) -> None:
            d = (ev.data or {}).get("dispatcher")
            f = getattr(d, "py_func", None) or getattr(d, "__wrapped__", None)
            compiled.append(getattr(f, "__qualname__", None) or repr(d))

        def on_end(self, ev: event.Event) -> None:
            pass

    event.register("numba:compile", _Log())
    from .cli import main

    try:
        rc = _build_all_ufuncs() if argv == ["_ufuncs"] else main(argv)
    finally:
        status = getattr(sys.modules.get("boundest._kernels"), "STATUS", None)
        Path(os.environ["BOUNDEST_COMPILE_LOG"]).write_text(json.dumps(
            {"compiled": compiled, "status": status}))
    return rc


def _build_all_ufuncs() -> int:
    """Compile every lazy (g)ufunc the package declares (interval elementary functions...)."""
    import importlib
    import pkgutil

    import boundest

    from .interval.rounding import _LazyGufunc, _LazyUfunc

    for info in pkgutil.walk_packages(boundest.__path__, "boundest."):
        if info.name.startswith(("boundest._kernels", "boundest.__main__")):
            continue
        try:
            mod = importlib.import_module(info.name)
        except Exception:  # optional extras (scipy, dask) may be missing
            continue
        for obj in list(vars(mod).values()):
            if isinstance(obj, (_LazyGufunc, _LazyUfunc)) and obj._ufunc is None:
                obj._build()
    # a compiled contractor that no command runs (its kernel would compile on first use)
    from .ctc import CtcPolar
    from .interval import Interval

    box = Interval([-10.0, -10.0, 1.9, 0.7], [10.0, 10.0, 2.1, 0.8])
    CtcPolar()(box)
    CtcPolar(center=(1.0, 2.0))(box)
    from .interval.relaxed import qinter  # CtcQInter and RobustObserver; no command runs it

    qinter(Interval([[0.0], [1.0]], [[2.0], [3.0]]), 1)
    _build_interval_functions()
    _build_engine_variants()
    _build_derivative_variants()
    _build_tube_kernels()
    _build_test_entry_points()
    return 0


def _build_interval_functions() -> None:
    """Compile the loop of every forward elementary function of the interval layer
    (``exp``, ``log2``, ``tanh``, ``tan``...): no command calls most of them, and each would
    otherwise compile for a second or two on a user's first call."""
    from .interval import Interval, explog, trig

    x = Interval([0.5, 1.5], [0.75, 2.0])
    for mod in (explog, trig):
        for f in vars(mod).values():
            if isinstance(f, explog._Forward):
                f(x)


#: one operator of each family of ``boundest.ctc.revise.FAMILIES``, in the model text format
_FAMILY_TERMS = {"piecewise": "abs(x)", "pown": "x^3", "explog": "exp(y)", "trig": "sin(x)"}


def _build_engine_variants() -> None:
    """Compile the kernels of ``propagate``'s default mode (hull consistency, shaving, the
    centered windows), of its box-consistency mode, of ``CtcFwdBwd`` and of ``CtcBox`` for
    every combination of operator families.

    They pass each family that a tape does not use as ``None``, so that Numba prunes its
    branches: one specialisation per combination (16). The commands use a few of them; with
    all of them in the archive a user's own model compiles nothing in the default mode or in
    ``"hc4"``, ``"bc"``, whatever operators it has (the other modes compile on first use).
    """
    from .csp import CtcBox, propagate
    from .ctc import CtcFwdBwd
    from .expr import parse_model
    from .interval import Interval

    box = Interval([-1.0, -1.0, -9.0], [1.0, 1.0, 9.0])
    for terms in _family_sums():
        model = parse_model(f"Variables x in [-1, 1], y in [-1, 1], z in [-9, 9];\n"
                            f"Constraints z = {terms};")
        propagate(model)  # the default mode: hull consistency, shaving, centered
        propagate(model, mode="bc")  # box consistency (BC3) on top of hull consistency
        CtcFwdBwd(model, ["x", "y", "z"])(box)
        CtcBox(model, ["x", "y", "z"])(box)


def _family_sums():
    """``y`` plus one term of each chosen family, for each of the 16 combinations of
    operator families (``"y"``, ``"y + abs(x)"``, ...)."""
    from itertools import combinations

    names = list(_FAMILY_TERMS)
    for r in range(len(names) + 1):
        for chosen in combinations(names, r):
            yield " + ".join(["y", *(_FAMILY_TERMS[n] for n in chosen)])


def _family_models():
    """A square model (2 equations, 2 unknowns in ``[-1, 1]^2``) for each of the 16
    combinations of operator families."""
    from .expr import parse_model

    for terms in _family_sums():
        yield parse_model(f"Variables x in [-1, 1], y in [-1, 1];\n"
                          f"Constraints {terms} = 0.5, x - y = 0;")


def _build_derivative_variants() -> None:
    """Compile the derivative-based kernels of the library (``jacobian``, ``centered_form``,
    ``CtcCentered``, ``CtcNewton``, ``solve_square``) for every combination of operator
    families: like the default mode's kernels, they are specialised per combination, and a
    user's first ``CtcCentered`` or ``solve_square`` on a model of their own otherwise
    compiles for a minute or more on 2 cores."""
    from .ctc import CtcCentered, CtcNewton
    from .ctc.derivatives import centered, jacobian
    from .interval import Interval
    from .paving import solve_square

    box = Interval([-1.0, -1.0], [1.0, 1.0])
    for model in _family_models():
        jacobian(model, box)
        centered(model, box)
        for ctc in (CtcCentered(model), CtcCentered(model, hc4=True),
                    CtcCentered(model, precondition="lp")):
            ctc(box)
        CtcNewton(model).prove(box)
        solve_square(model, box, eps=1e-3)


def _build_tube_kernels() -> None:
    """Compile the tube kernels that no command reaches: evaluation at an uncertain time
    (``CtcEval``, with and without the derivative) of a scalar tube and of a tube vector,
    inversion (of a scalar tube and of a component), integrals and primitives of both."""
    import numpy as np

    from .interval import Interval, cos, sin
    from .tube import CtcEval, Tube

    def pair(f):
        def g(t: Interval) -> Interval:
            v = f(t)
            return Interval.trusted(np.stack([v.lo, -v.hi], -1), np.stack([v.hi, -v.lo], -1))
        return g

    x, w = Tube.from_function(0, 10, 0.1, pair(sin)), Tube.from_function(0, 10, 0.1, pair(cos))
    y, v = Tube.from_function(0, 10, 0.1, sin), Tube.from_function(0, 10, 0.1, cos)
    for deriv in (True, False):
        CtcEval(time_deriv=deriv).contract(Interval(0, 10), Interval([0, 0], [2, 2]), x.copy(), w)
        CtcEval(time_deriv=deriv).contract(Interval(2, 3), Interval(-0.5, 0.5), y.copy(), v)
    for tube in (x, y):
        (tube[0] if tube.is_vector else tube).inverse(Interval(0.0, 0.5))
        tube.integral(1.0, 2.0)
        tube.integral(Interval(1.0, 1.5), Interval(2.0, 2.5))
        tube.primitive()


def _build_test_entry_points() -> None:
    """Compile the internal kernels that the test suite calls straight from Python (the row
    contraction, the engine's image and reverse steps): inside the library they are inlined
    into their callers, so no other entry compiles them, and a fresh clone's test run would
    spend half a minute on them."""
    import numpy as np

    from .ctc.linear_forms import contract_rows
    from .ctc.revise import EXP, POWN, image, revise

    jl, jh = np.array([[1.0, -1.0]]), np.array([[1.0, -1.0]])
    dl, dh = np.array([-1.0, -1.0]), np.array([1.0, 1.0])
    contract_rows(jl, jh, np.array([0.0]), np.array([0.0]), dl, dh, False, np.empty((6, 3)))
    buf = np.empty(4)
    image(EXP, 0.0, 1.0, 0.0, 0.0, 0.0, buf, None, None, True, True)
    revise(POWN, 0.0, 1.0, -3.0, 3.0, 0.0, 0.0, 3.0, buf, None, True, None, None)


def build(names: list[str] | None = None, timeout: float = 1800.0) -> int:
    """Compile every command's kernels (or those of ``names``, for a quick try) into a new
    cache and write the archive and manifest."""
    import time

    digest = numba_sources_digest()
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="boundest-kernels-") as tmp:
        cache = Path(tmp) / "cache"
        env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), NUMBA_CPU_NAME=TARGET_CPU,
                   NUMBA_CPU_FEATURES=TARGET_FEATURES, MPLBACKEND="Agg")
        env[ENV_SWITCH] = "0"
        for name in [*(names or COMMANDS), "_ufuncs"]:
            argv = ["_ufuncs"] if name == "_ufuncs" else _command_argv(name, Path(tmp) / "out")
            r = _run_logged(argv, env, Path(tmp) / "log.json", timeout)
            n = len(r["compiled"] or [])
            print(f"build: {name:<15} {r['wall_s']:6.1f} s, {n} compilations, rc {r['rc']}",
                  file=sys.stderr, flush=True)
            if r["rc"] not in (0, 1):
                print(r["stderr_tail"], file=sys.stderr)
                return 1
        files: dict[str, Path] = {}
        sources: dict[str, str] = {}
        for src_dir in sorted({p.parent for p in _PKG.rglob("*.py")}):
            env_dir = _cache_folder_under(cache, src_dir)
            rel = src_dir.relative_to(_PKG).as_posix()
            mods = {p.stem for p in src_dir.glob("*.py")}
            for f in sorted(env_dir.glob("*.nb[ic]")):
                member = f"{rel}/{f.name}"
                files[member] = f
                mod = _module_of(f.name, mods)
                if f.suffix == ".nbi" and mod:
                    sources[member] = (src_dir / f"{mod}.py").relative_to(_PKG).as_posix()
        if not files:
            print("build: no cache files were written", file=sys.stderr)
            return 1
        tmp_archive = Path(tmp) / "kernels.tar.xz"
        with tarfile.open(tmp_archive, "w:xz", preset=9) as tar:
            for member, f in files.items():
                info = tarfile.TarInfo(member)
                data = f.read_bytes()
                info.size, info.mtime, info.mode = len(data), 0, 0o644
                tar.addfile(info, io.BytesIO(data))
        raw = sum(f.stat().st_size for f in files.values())
        packed = tmp_archive.read_bytes()
    if numba_sources_digest() != digest:
        print("build: the Numba sources changed while building (nothing written): build "
              "again", file=sys.stderr)
        return 1
    manifest = {
        **running_versions(), "cpu_name": TARGET_CPU, "cpu_features": TARGET_FEATURES,
        "sources_sha256": digest, "archive_sha256": hashlib.sha256(packed).hexdigest(),
        "archive_bytes": len(packed), "unpacked_bytes": raw,
        "commands": list(names or COMMANDS), "files": list(files), "sources": sources}
    _write_atomic(ARCHIVE, packed)
    _write_atomic(MANIFEST, (json.dumps(manifest, indent=1) + "\n").encode())
    print(f"build: {len(files)} files, {raw / 1e6:.1f} MB -> {ARCHIVE} "
          f"{ARCHIVE.stat().st_size / 1e6:.1f} MB in {time.perf_counter() - t_start:.0f} s",
          file=sys.stderr)
    return 0


def _cache_folder_under(cache: Path, src_dir: Path) -> Path:
    sub = os.path.abspath(src_dir)
    return cache / f"{os.path.basename(sub)}_{hashlib.sha1(sub.encode()).hexdigest()}"


def _module_of(filename: str, modules: set[str]) -> str | None:
    """The module a cache file belongs to: ``[prefix-]module.qualname-line.pyXY...``."""
    head = filename.split(".", 1)[0]
    if head in modules:
        return head
    if "-" in head and head.split("-", 1)[1] in modules:
        return head.split("-", 1)[1]
    return None


def verify(names: list[str] | None = None, timeout: float = 900.0) -> int:
    """Run every command (or ``names``) with a fresh cache from the archive; fail if anything
    compiles."""
    bad = 0
    with tempfile.TemporaryDirectory(prefix="boundest-kernels-verify-") as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "cache"), MPLBACKEND="Agg")
        for var in (ENV_SWITCH, "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
            env.pop(var, None)
        for name in names or COMMANDS:
            r = _run_logged(_command_argv(name, Path(tmp) / "out"), env,
                            Path(tmp) / "log.json", timeout)
            ok = r["rc"] in (0, 1) and r["compiled"] == [] and r["status"] in ("installed",
                                                                                "in use")
            bad += not ok
            print(f"verify: {name:<15} {r['wall_s']:6.1f} s, archive {r['status']}, "
                  f"compiled {r['compiled']}, rc {r['rc']}: {'ok' if ok else 'FAILED'}",
                  file=sys.stderr, flush=True)
    return 1 if bad else 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "_run":
        return _logged_main(argv[1:])
    cmds = {"build": build, "verify": verify}
    names = argv[1:]
    if not argv or argv[0] not in cmds or any(n not in COMMANDS for n in names):
        print("usage: python -m boundest._kernels_build build | verify [COMMAND ...]\n"
              f"commands: {' '.join(COMMANDS)}", file=sys.stderr)
        return 2
    return cmds[argv[0]](names) if names else cmds[argv[0]]()


if __name__ == "__main__":
    raise SystemExit(main())
