#!/usr/bin/env bash
# Side-by-side benchmark and statistics check of plumetrace against pompy 0.1.1, the reference
# implementation of the Farrell et al. (2002) plume model, on pompy's own scenario.
#
# Installs pompy 0.1.1 with numpy < 2.4 (pompy fails on numpy 2.4) and scipy into a virtual
# environment under scripts/.venv, builds plumetrace in release mode, times both in the same run
# and prints the ratios, then compares mean live puff counts, cross-flow spreads and the
# intermittency on the centreline.
#
# Usage: scripts/compare_pompy.sh [--quick] [--seeds N] [--stats-duration S] [--jobs J]
# The full run takes about fifty minutes on 2 cores (pompy is slow); --quick takes a few minutes.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
venv="$here/.venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet "pompy==0.1.1" "numpy<2.4" "scipy"
cargo build --release --quiet --manifest-path "$root/Cargo.toml" -p plumetrace-cli
exec "$venv/bin/python" "$here/compare_pompy.py" --plumetrace "$root/target/release/plumetrace" "$@"
