#!/usr/bin/env bash
# Runs scripts/two_sample.py in a virtual environment with scipy (made on first use under the
# target directory): bash scripts/two_sample.sh RUNS_CSV CONFIG_A CONFIG_B [--alpha 0.01]
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${CARGO_TARGET_DIR:-target}/stats-venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet "scipy>=1.11,<2"
fi
exec "$venv/bin/python" scripts/two_sample.py "$@"
