#!/usr/bin/env bash
# Create .bench-venv/ in the repository root: boundest (editable) plus the reference libraries the
# benchmarks compare against. They are NOT dependencies of boundest.
#   codac  2.x  (module codac, LGPL-3; scalar intervals and contractors, C++ via pybind11)
#   crival 0.2.x (module ival, MIT; vectorized tight IEEE 1788 intervals, C via ctypes)
# Usage: bash benchmarks/setup_bench_env.sh [PYTHON]      (default: python3; needs >= 3.11)
# A failure to install codac or crival is reported and the benchmarks then skip that column.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${1:-python3}"
VENV=.bench-venv

if [ ! -x "$VENV/bin/python" ]; then
    "$PY" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet -e .
for spec in "codac>=2,<3" "crival>=0.2,<0.3"; do
    if ! "$VENV/bin/python" -m pip install --quiet "$spec"; then
        echo "setup_bench_env: could not install $spec; its benchmark columns will be skipped" >&2
    fi
done
"$VENV/bin/python" - <<'PY'
import importlib.metadata as md
for dist in ("boundest", "numpy", "numba", "codac", "crival"):
    try:
        print(f"{dist:9s} {md.version(dist)}")
    except md.PackageNotFoundError:
        print(f"{dist:9s} (not installed)")
PY
echo "bench env ready: $VENV/bin/python benchmarks/bench_interval.py --quick"
