"""The shipped kernel archive: its manifest, when it is refused, and where it is unpacked."""

from __future__ import annotations

import hashlib
import io
import json
import os
import pickle
import subprocess
import sys
import tarfile

import pytest

from boundest import _kernels as k
from boundest import _numba_cache as nc

SOURCE = "interval/arith.py"
INDEX = "interval/arith._fake-1.py311.nbi"
DATA = "interval/arith._fake-1.py311.1.nbc"


def _manifest(**changes) -> dict:
    doc = {**k.running_versions(), "cpu_name": k.TARGET_CPU, "cpu_features": k.TARGET_FEATURES,
           "sources_sha256": nc.numba_sources_digest(), "archive_sha256": "0" * 64,
           "files": [DATA, INDEX], "sources": {INDEX: SOURCE}}
    doc.update(changes)
    return doc


def _index(stamp) -> bytes:
    out = io.BytesIO()
    pickle.dump("0.68.1", out, protocol=-1)
    out.write(pickle.dumps((stamp, {"key": "arith._fake-1.py311.1.nbc"}), protocol=-1))
    return out.getvalue()


def _content_stamp() -> bytes:
    return hashlib.sha256((nc._PKG / SOURCE).read_bytes()).digest()


@pytest.fixture
def archive(tmp_path, monkeypatch):
    """A tiny archive and its manifest in place of the shipped ones, in a fresh cache folder;
    the running process's Numba target is left alone."""
    tar_path, man_path = tmp_path / "kernels.tar.xz", tmp_path / "kernels.json"
    with tarfile.open(tar_path, "w:xz") as tar:
        for name, data in ((DATA, b"machine code"), (INDEX, _index(_content_stamp()))):
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    man_path.write_text(json.dumps(_manifest()))
    monkeypatch.setattr(k, "ARCHIVE", tar_path)
    monkeypatch.setattr(k, "MANIFEST", man_path)
    monkeypatch.setattr(k, "host_supports_target", lambda: True)
    monkeypatch.setattr(k, "_codegen_cpu", lambda: None)  # as if Numba's codegen were not up
    used = []
    monkeypatch.setattr(k, "_use_target", lambda: used.append(True))
    monkeypatch.delenv(k.ENV_SWITCH, raising=False)
    monkeypatch.delenv("NUMBA_CPU_NAME", raising=False)
    monkeypatch.delenv("NUMBA_CPU_FEATURES", raising=False)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))
    return used


def _installed(name: str):
    return k._destination(name)


def test_manifest_parsing(tmp_path):
    good = tmp_path / "good.json"
    good.write_text(json.dumps(_manifest()))
    assert k.read_manifest(good)["cpu_name"] == k.TARGET_CPU
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert k.read_manifest(bad) is None
    partial = tmp_path / "partial.json"
    partial.write_text(json.dumps({"numba": "0.68.1"}))
    assert k.read_manifest(partial) is None
    assert k.read_manifest(tmp_path / "missing.json") is None
    if k.MANIFEST.exists():  # the shipped one parses and names its files
        shipped = k.read_manifest()
        assert shipped is not None and shipped["files"]


def test_refused_on_a_version_digest_or_cpu_mismatch(monkeypatch):
    monkeypatch.delenv("NUMBA_CPU_NAME", raising=False)
    monkeypatch.delenv("NUMBA_CPU_FEATURES", raising=False)
    assert k.refusal(_manifest(), cpu_ok=True) is None
    assert "numba" in k.refusal(_manifest(numba="0.1.0"), cpu_ok=True)
    assert "llvmlite" in k.refusal(_manifest(llvmlite="0.1.0"), cpu_ok=True)
    assert "python" in k.refusal(_manifest(python="3.9.0"), cpu_ok=True)
    assert "stale" in k.refusal(_manifest(sources_sha256="f" * 64), cpu_ok=True)
    assert "CPU" in k.refusal(_manifest(cpu_name="znver4"), cpu_ok=True)
    assert "does not run" in k.refusal(_manifest(), cpu_ok=False)
    monkeypatch.setenv("NUMBA_CPU_NAME", "generic")
    assert "NUMBA_CPU_NAME" in k.refusal(_manifest(), cpu_ok=True)
    assert k.refusal(None) is not None


def test_unpacked_where_numba_looks_then_in_use(archive):
    assert k.activate() == "installed" and archive == [True]
    data, index = _installed(DATA), _installed(INDEX)
    assert data.read_bytes() == b"machine code" and index.exists()
    assert data.parent == nc.cache_folder_for(nc._PKG / "interval")
    assert nc.kernels_marker().exists()
    assert k.activate() == "in use" and archive == [True, True]


def test_a_changed_source_refuses_the_archive_and_drops_the_marker(archive, monkeypatch):
    assert k.activate() == "installed"
    monkeypatch.setattr(k, "numba_sources_digest", lambda: "e" * 64)
    assert k.activate().startswith("not used: stale")
    nc._cache_folders()[1].write_text("a digest of other sources")
    nc.drop_stale_numba_cache()
    assert not nc.kernels_marker().exists() and not _installed(INDEX).exists()


def test_not_unpacked_over_kernels_compiled_here(archive):
    own = _installed(INDEX).with_name("arith._add_lo-10.py311.nbi")
    own.parent.mkdir(parents=True)
    own.write_bytes(b"compiled on this machine")
    assert "already holds" in k.activate() and archive == []
    assert not _installed(DATA).exists()


def test_disabled_by_the_environment(archive, monkeypatch):
    monkeypatch.setenv(k.ENV_SWITCH, "0")
    assert k.activate().startswith("disabled") and archive == []
    assert not _installed(INDEX).exists() and not nc.kernels_marker().exists()


def test_a_read_only_cache_location_is_left_alone(archive, tmp_path, monkeypatch):
    blocker = tmp_path / "a-file"  # a cache folder under a file cannot be made, even by root
    blocker.write_text("")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(blocker / "cache"))
    status = k.activate()
    assert status.startswith("not used") and archive == []


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root writes anywhere")
def test_a_read_only_folder_is_left_alone(archive, tmp_path, monkeypatch):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        monkeypatch.setenv("NUMBA_CACHE_DIR", str(ro))
        assert k.activate().startswith("not used") and archive == []
        assert list(ro.iterdir()) == []
    finally:
        ro.chmod(0o700)


def test_index_stamps_are_checked_or_rewritten(tmp_path):
    src = nc._PKG / SOURCE
    assert k._restamp(_index(_content_stamp()), src) == _index(_content_stamp())
    with pytest.raises(ValueError, match="differs"):
        k._restamp(_index(b"x" * 32), src)
    st = src.stat()
    old = k._restamp(_index((12345.0, st.st_size)), src)  # an older Numba's (mtime, size)
    buf = io.BytesIO(old)
    assert pickle.load(buf) == "0.68.1"
    assert pickle.loads(buf.read())[0] == (st.st_mtime, st.st_size)
    with pytest.raises(ValueError, match="size"):
        k._restamp(_index((12345.0, st.st_size + 1)), src)


@pytest.mark.slow  # a subprocess run of `boundest demo`, about 6 s with the archive
def test_demo_with_an_empty_cache_compiles_nothing_when_the_archive_matches(tmp_path):
    why = k.refusal(k.read_manifest())
    if why is not None:
        pytest.skip(f"kernel archive {why}")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               BOUNDEST_COMPILE_LOG=str(tmp_path / "log.json"), MPLBACKEND="Agg")
    for var in (k.ENV_SWITCH, "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
        env.pop(var, None)
    out = subprocess.run([sys.executable, "-m", "boundest._kernels_build", "_run", "demo", "--out",
                          str(tmp_path / "out")], env=env, capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    log = json.loads((tmp_path / "log.json").read_text())
    assert log == {"compiled": [], "status": "installed"}
    assert "compiling" not in out.stderr


_USER_MODEL = """
import json
from numba.core import event
compiled = []
class Log(event.Listener):
    def on_start(self, ev):
        compiled.append(repr((ev.data or {}).get("dispatcher")))
    def on_end(self, ev):
        pass
event.register("numba:compile", Log())
import boundest as bd
import boundest._kernels as k
from boundest.csp import CtcBox
from boundest.expr import parse_model
m = parse_model("Variables x in [-2, 2], y in [-2, 2];\\n"
                "Constraints sin(x) + exp(y) = 1.5, x - y = 0;")
box = bd.Interval([-2.0, -2.0], [2.0, 2.0])
batch = bd.Interval([[-2.0, -2.0], [0.0, 0.0]], [[2.0, 2.0], [1.0, 1.0]])
for b in (box, batch):  # one box and a batch: the same compiled kernel
    bd.CtcCentered(m)(b)
    bd.CtcCentered(m, hc4=True)(b)
bd.CtcCentered(m, precondition="lp")(batch)
bd.CtcNewton(m).prove(box)
bd.CtcNewton(m).prove(batch)
roots = bd.solve_square(m, box)
bd.jacobian(m, box)
bd.centered_form(m, box)
bd.propagate(m, mode="bc")
CtcBox(m, ["x", "y"])(box)
for f in (bd.log2, bd.tanh, bd.tan, bd.acosh):
    f(box)
print(json.dumps({"compiled": compiled, "status": k.STATUS, "proved": len(roots.solutions)}))
"""


@pytest.mark.slow  # a subprocess, about 10 s with the archive
def test_a_users_model_through_the_library_api_compiles_nothing(tmp_path):
    """The centered-form contractor (on one box and on a batch, in each mode), interval
    Newton (one box, a batch), ``solve_square``, ``jacobian``, ``centered_form``, box
    consistency (the mode and ``CtcBox``) on a model of one's own (trig and exp/log operators)
    and elementary functions no command calls load their kernels from the archive (they
    compiled for 1-2 minutes on first use before it held them)."""
    why = k.refusal(k.read_manifest())
    if why is not None:
        pytest.skip(f"kernel archive {why}")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), MPLBACKEND="Agg")
    for var in (k.ENV_SWITCH, "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
        env.pop(var, None)
    out = subprocess.run([sys.executable, "-c", _USER_MODEL], env=env, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    log = json.loads(out.stdout.strip().splitlines()[-1])
    assert log == {"compiled": [], "status": "installed", "proved": 1}, log
