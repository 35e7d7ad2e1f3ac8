#!/usr/bin/env bash
# Costs from Python: plumetrace's plume step and point queries against pompy 0.1.1 on pompy's
# scenario, and Gymnasium steps per second. Makes its own virtual environment (pompy needs
# numpy < 2.4), builds and installs the package, prints one JSON object.
#
# Usage: scripts/python_bench.sh [--warmup S] [--timed S] [--queries N] [--gym-steps N] [--no-pompy]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
venv="$here/.venv-pybench"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet "maturin==1.16.0" "pompy==0.1.1" "numpy<2.4" "scipy" "gymnasium==1.4.0"
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target/py}" \
    "$venv/bin/pip" install --quiet --force-reinstall --no-deps "$root/crates/plumetrace-py"
exec "$venv/bin/python" "$here/python_bench.py" "$@"
