"""Running another library's benchmark script in its own interpreter.

Codac lives in its own virtual environment, and importing it switches the FPU to rounding
upward, so its side of a comparison runs as ``python SCRIPT SPEC.json`` in a subprocess: the
spec goes in as a JSON file, one JSON document comes back on stdout. The scripts that run there
use ``fegetround`` to record the rounding mode around their import of codac.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any


def run_json_script(python: Path, script: Path, spec: dict, timeout: float | None = None
                    ) -> dict:
    """Run ``python script SPEC.json`` and return its stdout parsed as JSON, with
    ``subprocess_wall_s`` added; its stderr (progress) is passed through.

    Raises
    ------
    RuntimeError
        When the script exits with a non-zero status (the message ends with its stderr).
    """
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"{Path(script).stem}_input.json"
        path.write_text(json.dumps(spec))
        t0 = time.perf_counter()
        proc = subprocess.run([str(python), str(script), str(path)], capture_output=True,
                              text=True, timeout=timeout, check=False)
        wall = time.perf_counter() - t0
    sys.stderr.write(proc.stderr)
    if proc.returncode != 0:
        raise RuntimeError(f"{Path(script).name} exited with {proc.returncode}: "
                           f"{proc.stderr.strip()[-2000:]}")
    out = json.loads(proc.stdout)
    out["subprocess_wall_s"] = wall
    return out


def fegetround() -> int | None:
    """The C rounding mode (``fegetround`` of libm), None where libm cannot be loaded."""
    try:
        libm = ctypes.CDLL(ctypes.util.find_library("m"))
        return int(libm.fegetround())
    except (OSError, AttributeError, TypeError):
        return None


def decode_hex(obj: Any) -> Any:
    """Every string holding a ``float.hex`` becomes a float (lists and dicts recursively): how
    the Codac scripts read their spec, under round-to-nearest, before importing codac."""
    if isinstance(obj, dict):
        return {k: decode_hex(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [decode_hex(v) for v in obj]
    if isinstance(obj, str) and obj.startswith(("0x", "-0x", "inf", "-inf")):
        return float.fromhex(obj)
    return obj
