"""The kernel archive: the package's Numba machine code, compiled once and shipped.

An empty Numba cache makes a command's first run compile its kernels (tens of seconds to
minutes on 2 cores). ``data/kernels.tar.xz`` holds the ``*.nbi``/``*.nbc`` cache files of
every command's kernels, compiled for a generic x86-64 target (``x86-64-v3``: AVX2, FMA, BMI),
and ``data/kernels.json`` describes it (Numba, llvmlite, NumPy and Python versions, the
target, the digest of the package's Numba sources, the files).

At import (``boundest.interval``), :func:`activate` unpacks the archive into the folder Numba
caches the package's kernels in (``__pycache__`` beside the sources, or under
``NUMBA_CACHE_DIR``) when that cache holds none of the package's kernels yet, the manifest
matches the running versions, sources and platform, and the CPU runs the target's
instructions; the process then compiles for that target, so that Numba's index (keyed on the
CPU name and features) accepts the entries. When anything does not match, or the folder is
read-only, it does nothing and kernels compile as before. ``BOUNDEST_KERNEL_ARCHIVE=0``
disables it.

A kernel that neither the cache nor the archive holds compiles on first use, seconds of
silence: the command line announces it on standard error (:func:`announce_compilation`), library
use once per process through ``logging`` (:func:`notice_compilation`, a WARNING of the
``boundest.kernels`` logger; ``logging.getLogger("boundest").setLevel(logging.ERROR)`` silences
it).

``python -m boundest._kernels check`` says in one line whether the archive matches the
sources. Building and verifying it runs every command, so it lives in a module that the
package never imports, :mod:`boundest._kernels_build` (``python -m boundest._kernels_build
build | verify``): this module imports nothing of the package but ``_numba_cache``, so that
``interval``, which activates the archive at import, stays the bottom layer.

This is the only module that relies on Numba internals: the target-machine settings
(``numba.config.CPU_NAME``/``CPU_FEATURES`` and ``numba.core.registry.cpu_target``), the
layout of the cache index (a pickled Numba version, then a pickled ``(source stamp,
overloads)``) and the cache file names. Checked against Numba 0.68.1 (llvmlite 0.50.0),
whose source stamp is the sha256 of the source file (older Numbas stamp the file's
``(st_mtime, st_size)``, which :func:`_restamp` rewrites). Any exception from them leaves the
cache alone, and kernels compile as usual.
"""

from __future__ import annotations

import hashlib
import io
import json
import logging
import os
import pickle
import platform
import sys
import tarfile
import tempfile
from pathlib import Path

from ._numba_cache import _PKG, cache_folder_for, kernels_marker, numba_sources_digest

ARCHIVE = _PKG / "data" / "kernels.tar.xz"
MANIFEST = _PKG / "data" / "kernels.json"
ENV_SWITCH = "BOUNDEST_KERNEL_ARCHIVE"
#: The generic target the archive is compiled for: LLVM's x86-64-v3 level with no extra
#: features (``NUMBA_CPU_FEATURES=""``: the CPU name implies them), so that the cache key
#: (triple, CPU name, features) is the same on every x86-64 machine that runs it.
TARGET_CPU = "x86-64-v3"
TARGET_FEATURES = ""
#: LLVM's names of the instruction sets x86-64-v3 implies (v1, v2, v3); the host must have all.
V3_FEATURES = frozenset({
    "cmov", "cx8", "fxsr", "mmx", "sse", "sse2",
    "cx16", "popcnt", "sahf", "sse3", "sse4.1", "sse4.2", "ssse3",
    "avx", "avx2", "bmi", "bmi2", "f16c", "fma", "lzcnt", "movbe", "xsave"})

#: What the last :func:`activate` did ("installed", "in use", or why not), for messages.
STATUS = "not checked"

# --- what the running process is ------------------------------------------------------------
def running_versions() -> dict[str, str]:
    """The versions and platform the cache files depend on, for this process."""
    import llvmlite
    import numba
    import numpy
    from llvmlite import binding as ll

    return {"numba": numba.__version__, "llvmlite": llvmlite.__version__,
            "numpy": numpy.__version__, "python": platform.python_version(),
            "triple": ll.get_process_triple()}


def _minor(version: str) -> str:
    return ".".join(version.split(".")[:2])


def host_supports_target() -> bool:
    """Whether this CPU (and OS) runs x86-64-v3 code, by LLVM's host feature detection."""
    from llvmlite import binding as ll

    if platform.machine().lower() not in ("x86_64", "amd64"):
        return False
    ll.initialize_native_target()
    features = ll.get_host_cpu_features()
    return all(features.get(f, False) for f in V3_FEATURES)


def read_manifest(path: Path | None = None) -> dict | None:
    """The manifest (default: the shipped one) as a dict, or None when missing or malformed."""
    try:
        doc = json.loads(Path(path or MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    need = ("numba", "llvmlite", "numpy", "python", "triple", "cpu_name", "cpu_features",
            "sources_sha256", "archive_sha256", "files")
    if not isinstance(doc, dict) or any(k not in doc for k in need):
        return None
    if not isinstance(doc["files"], list):
        return None
    return doc


def refusal(manifest: dict | None, versions: dict | None = None, digest: str | None = None,
            cpu_ok: bool | None = None) -> str | None:
    """Why the archive described by ``manifest`` cannot be used here (None: it can).

    Numba and llvmlite must be the very versions the archive was built with, NumPy and
    Python the same minor version, the platform triple and the digest of the Numba sources
    the same, and the CPU must run the target's instructions.
    """
    if manifest is None:
        return "no kernel archive (or an unreadable manifest)"
    versions = running_versions() if versions is None else versions
    for key in ("numba", "llvmlite", "triple"):
        if manifest[key] != versions[key]:
            return f"built with {key} {manifest[key]}, running {versions[key]}"
    for key in ("numpy", "python"):
        if _minor(manifest[key]) != _minor(versions[key]):
            return f"built with {key} {manifest[key]}, running {versions[key]}"
    digest = numba_sources_digest() if digest is None else digest
    if manifest["sources_sha256"] != digest:
        return ("stale: the Numba sources changed since it was built (rebuild: "
                "python -m boundest._kernels_build build)")
    if manifest["cpu_name"] != TARGET_CPU or manifest["cpu_features"] != TARGET_FEATURES:
        return f"built for CPU {manifest['cpu_name']!r}, this boundest uses {TARGET_CPU!r}"
    cpu_ok = host_supports_target() if cpu_ok is None else cpu_ok
    if not cpu_ok:
        return f"this CPU does not run {TARGET_CPU} code"
    for var, want in (("NUMBA_CPU_NAME", TARGET_CPU), ("NUMBA_CPU_FEATURES", TARGET_FEATURES)):
        if var in os.environ and os.environ[var] != want:
            return f"{var} is set to {os.environ[var]!r}"
    return None


# --- installing -----------------------------------------------------------------------------
def _destination(member: str) -> Path:
    """Where an archive member (``<source folder relative to the package>/<file>``) goes."""
    folder, _, name = member.rpartition("/")
    if not name or name.startswith(".") or ".." in folder.split("/"):
        raise ValueError(f"bad archive member {member!r}")
    src_dir = _PKG if folder in ("", ".") else _PKG / folder
    return cache_folder_for(src_dir) / name


def _package_kernels_cached() -> bool:
    """Whether the cache location already holds any of the package's kernels."""
    folders = {cache_folder_for(p.parent) for p in _PKG.rglob("*.py")}
    return any(next(f.glob("*.nbi"), None) is not None for f in folders if f.is_dir())


def _writable(path: Path) -> bool:
    """Whether ``path`` (created if missing) can take new files."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError:
        return False
    return True


def _restamp(index: bytes, source: Path) -> bytes:
    """A cache index whose source stamp fits ``source`` as installed here.

    The index is a pickled Numba version, then a pickled ``(stamp, overloads)``. Its opcodes
    are read (``pickletools.genops``), never executed: unpickling the overloads would import
    the modules their signatures name, in the middle of importing ``boundest.interval``.
    Numba 0.68 stamps the sha256 of the source's contents: it must equal the installed
    file's (else ValueError). Older Numbas stamp ``(st_mtime, st_size)``: the size must match,
    and the modification time is replaced, in place, by the installed file's.
    """
    import pickletools
    import struct

    buf = io.BytesIO(index)
    pickle.load(buf)  # the Numba version: a plain string
    start = buf.tell()
    ops = (op for op in pickletools.genops(index[start:]) if op[0].name not in ("PROTO",
                                                                              "FRAME"))
    op, arg, pos = next(ops)
    if op.name in ("SHORT_BINBYTES", "BINBYTES", "BINBYTES8"):
        if arg != hashlib.sha256(source.read_bytes()).digest():
            raise ValueError(f"{source.name}: source differs from the archive's")
        return index
    if op.name == "BINFLOAT":
        size_op, size, _ = next(ops)
        st = source.stat()
        if not size_op.name.startswith(("BININT", "LONG")) or size != st.st_size:
            raise ValueError(f"{source.name}: source size differs from the archive's")
        at = start + pos + 1  # the 8 bytes of the float, after its opcode
        return index[:at] + struct.pack(">d", st.st_mtime) + index[at + 8:]
    raise ValueError(f"{source.name}: unknown source stamp ({op.name})")


def _write_atomic(path: Path, data: bytes) -> None:
    tmp = path.with_name(f"{path.name}.tmp.{os.getpid()}")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _unpack(manifest: dict) -> None:
    """Write the archive's files where Numba looks for them (raises on any problem)."""
    sources = manifest.get("sources", {})
    with tarfile.open(ARCHIVE, "r:xz") as tar:
        members = [m for m in tar.getmembers() if m.isfile()]
        names = sorted(m.name for m in members)
        if names != sorted(manifest["files"]):
            raise ValueError("the archive's files differ from its manifest's")
        dests = {m.name: _destination(m.name) for m in members}
        for folder in {d.parent for d in dests.values()}:
            if not _writable(folder):
                raise PermissionError(f"{folder} is not writable")
        # data files first, indexes last: an index never names a file not yet there; on any
        # failure what was written goes again (a later import may try once more)
        written: list[Path] = []
        try:
            for m in sorted(members, key=lambda m: m.name.endswith(".nbi")):
                data = tar.extractfile(m).read()
                if m.name.endswith(".nbi") and m.name in sources:
                    data = _restamp(data, _PKG / sources[m.name])
                _write_atomic(dests[m.name], data)
                written.append(dests[m.name])
        except BaseException:
            for f in written:
                f.unlink(missing_ok=True)
            raise


def _use_target() -> None:
    """Make this process compile for the archive's target (before Numba's codegen exists)."""
    from numba.core import config

    config.CPU_NAME = TARGET_CPU
    config.CPU_FEATURES = TARGET_FEATURES


def _codegen_cpu() -> str | None:
    """The CPU name Numba's CPU codegen was created with (None: not created yet)."""
    from numba.core import registry

    if "_toplevel_target_context" not in vars(registry.cpu_target):
        return None
    return registry.cpu_target.target_context.codegen().magic_tuple()[1]


def activate() -> str:
    """Unpack the archive if it fits and the cache lacks the package's kernels; make this
    process use the archive's target if the archive is (or was) unpacked in this cache.

    Returns (and records in ``STATUS``) what it did. Never raises. Also registers the notice
    of a first compilation in library use (:func:`notice_compilation`).
    """
    global STATUS
    try:
        STATUS = _activate()
    except Exception as exc:  # any failure: plain compilation, as before
        STATUS = f"not used ({type(exc).__name__}: {exc})"
    notice_compilation()
    return STATUS


def _activate() -> str:
    if os.environ.get(ENV_SWITCH, "1").strip().lower() in ("0", "no", "off", "false"):
        return f"disabled ({ENV_SWITCH}=0)"
    manifest = read_manifest()
    why = refusal(manifest)
    if why:
        return f"not used: {why}"
    cpu = _codegen_cpu()
    if cpu is not None and cpu != TARGET_CPU:
        return "not used: Numba's CPU target was set up before boundest was imported"
    marker = kernels_marker()
    try:
        mark = json.loads(marker.read_text())
    except (OSError, ValueError):
        mark = None
    if isinstance(mark, dict) and mark.get("archive_sha256") == manifest["archive_sha256"]:
        _use_target()
        return "in use"
    if _package_kernels_cached():
        return "not used: the cache already holds kernels compiled on this machine"
    try:
        _unpack(manifest)
        _write_atomic(marker, json.dumps({"archive_sha256": manifest["archive_sha256"],
                                          "cpu_name": TARGET_CPU}).encode())
    except OSError as exc:  # read-only or full: leave it, compile as before
        return f"not used: {exc}"
    _use_target()
    return "installed"


#: The logger of the compilation notice of library use (a child of ``boundest``'s logger).
LOG = logging.getLogger("boundest.kernels")
#: Whether this process's compilation notice is the command line's (then the library's is off).
_CLI_ANNOUNCES = False
_LIBRARY_NOTICE: list = []  # the library's listener once registered (once per process)


class _LibraryNotice:
    """The listener behind :func:`notice_compilation` (a Numba ``event.Listener``)."""

    def __init__(self) -> None:
        self.said = False

    def on_start(self, ev: object) -> None:
        if self.said or _CLI_ANNOUNCES:
            return
        func = getattr(getattr(ev, "data", {}).get("dispatcher"), "py_func", None)
        module = getattr(func, "__module__", "") or ""
        if not module.startswith("boundest."):
            return  # the user's own Numba functions are theirs to announce
        self.said = True
        what = ("Numba kernels that the shipped kernel archive lacks"
                if STATUS in ("installed", "in use") else "its Numba kernels")
        LOG.warning("boundest: compiling %s (first %s; a few seconds per family of kernels, "
                    "once: they are cached on disk for later runs) ... [silence: logging."
                    "getLogger('boundest').setLevel(logging.ERROR)]", what, func.__qualname__)

    def on_end(self, ev: object) -> None:
        pass


def notice_compilation() -> None:
    """Log once per process, on the ``boundest.kernels`` logger at WARNING level, that Numba
    compiles one of boundest's kernels (a cache miss: seconds of silence otherwise).

    WARNING, because Python shows a warning on standard error when the application configured
    no logging (``logging.lastResort``) and shows nothing below it: the library configures no
    handler, and an application that configures logging routes the notice with the rest.
    ``logging.getLogger("boundest").setLevel(logging.ERROR)`` silences it. Kernels found in the
    on-disk cache (or the shipped archive) compile nothing and say nothing; the command line
    announces its own compilation instead (:func:`announce_compilation`). Called by
    :func:`activate` (at import of ``boundest.interval``); registering again does nothing.
    Never raises.
    """
    if _LIBRARY_NOTICE:
        return
    try:
        from numba.core import event

        listener = type("_Notice", (_LibraryNotice, event.Listener), {})()
        event.register("numba:compile", listener)
        _LIBRARY_NOTICE.append(listener)
    except Exception:  # a Numba without events: kernels compile without the notice
        pass


class _CommandNotice:
    """The listener behind :func:`announce_compilation` (one per process; each command-line
    call re-aims it at its own command)."""

    def __init__(self) -> None:
        self.said = True
        self.what = ""
        self.estimate_s: float | None = None

    def on_start(self, ev: object) -> None:  # noqa: ARG002 - numba's signature
        if self.said:
            return
        self.said = True
        if STATUS in ("installed", "in use"):  # the archive lacks this one
            print(f"boundest: compiling a Numba kernel {self.what} uses that the shipped kernel "
                  "archive lacks (once: it is cached on disk for later runs) ...",
                  file=sys.stderr, flush=True)
            return
        how_long = (f"about {self.estimate_s:.0f} s on 2 cores" if self.estimate_s is not None
                    else "it may take a minute")
        print(f"boundest: compiling the Numba kernels {self.what} uses ({how_long}; once: they "
              f"are cached on disk for later runs) ...", file=sys.stderr, flush=True)

    def on_end(self, ev: object) -> None:
        pass


_COMMAND_NOTICE: list[_CommandNotice] = []  # registered with Numba once per process


def announce_compilation(what: str, estimate_s: float | None = None) -> None:
    """Print one line on standard error when Numba first compiles a kernel in this command.

    Numba reports a compilation (a ``numba:compile`` event) only on a cache miss, so a run
    that finds every kernel in the on-disk cache (compiled earlier, or unpacked from this
    archive) prints nothing; a kernel the archive lacks is named as such, without the
    estimate. Called by the command line before a command runs; ``what`` names the command,
    ``estimate_s`` is its measured empty-cache compile time on 2 cores (printed as "about N s").
    A process that runs several commands (``boundest.cli.main`` called again) keeps one
    listener, aimed at the latest command: one line per command at most, naming it.
    """
    from numba.core import event

    global _CLI_ANNOUNCES
    _CLI_ANNOUNCES = True  # the command line's notice, naming the command; the library's is off
    if not _COMMAND_NOTICE:
        _COMMAND_NOTICE.append(type("_Notice", (_CommandNotice, event.Listener), {})())
        event.register("numba:compile", _COMMAND_NOTICE[0])
    notice = _COMMAND_NOTICE[0]
    notice.what, notice.estimate_s, notice.said = what, estimate_s, False


def check() -> int:
    """One line: does the shipped archive match the sources and this environment?"""
    why = refusal(read_manifest())
    print(f"kernel archive: {'matches the sources and this environment' if why is None else why}")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv != ["check"]:
        print("usage: python -m boundest._kernels check\n"
              "(building and verifying the archive: python -m boundest._kernels_build "
              "build | verify [COMMAND ...])", file=sys.stderr)
        return 2
    return check()


if __name__ == "__main__":
    raise SystemExit(main())
