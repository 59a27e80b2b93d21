"""Each command compiles each of boundest's Numba functions once (with an empty cache and no
kernel archive): a literal int argument (``f(x, 0)``, or a counter that starts at ``0``) makes
Numba compile the callee again for ``Literal[int]``, which cost seconds of a first run in the
engine, the pool observer and the trigonometric kernels before they passed ``np.int64``."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from importlib.resources import files

import pytest

_SCRIPT = textwrap.dedent("""
    import collections, json, sys
    from numba.core import event

    counts = collections.Counter()

    class Count(event.Listener):
        def on_start(self, ev):
            f = ev.data["dispatcher"].py_func
            counts[f.__module__ + "." + f.__qualname__] += 1

        def on_end(self, ev):
            pass

    event.register("numba:compile", Count())
    from boundest.cli import main

    try:
        main(sys.argv[1:])
    except SystemExit:
        pass
    print(json.dumps({"compiled": sum(counts.values()),
                      "twice": {k: v for k, v in counts.items()
                                if v > 1 and k.startswith("boundest.")}}))
""")


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["run", "satellite"], ["run", "drifting-clock"],
                                  ["run", "range-only"], ["run", "auv"], ["run", "jaulin2001"],
                                  ["run", "pool"],  # about 40 s, the others 5-15 s
                                  ["demo"], ["solve", "SATELLITE_MODEL"]])
def test_each_kernel_is_compiled_once(argv, tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "BOUNDEST_KERNEL_ARCHIVE": "0"}
    if argv[0] == "solve":  # the shipped model file; solve writes no figures
        argv = ["solve", str(files("boundest") / "data" / "satellite_k200.txt")]
    else:
        argv = [*argv, "--out", str(tmp_path / "out")]
    proc = subprocess.run([sys.executable, "-c", _SCRIPT, *argv], env=env, capture_output=True,
                          text=True, timeout=1200, check=True)
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    assert report["compiled"] > 10, report  # it did compile (the archive was off)
    assert report["twice"] == {}, f"compiled more than once: {report['twice']}"
