#!/usr/bin/env bash
# The Python package's checks: formatting and lints of its Rust crate, then `pip install` of the
# package from the repository (maturin builds the wheel) into a fresh virtual environment, and
# its pytest suite (which compares with the release command line, so it builds that too).
#
# Usage: scripts/python_tests.sh [pytest arguments]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
py="$root/crates/plumetrace-py"
cli_target="${CARGO_TARGET_DIR:-$root/target}"
venv="$root/target/py-venv"

CARGO_TARGET_DIR="$cli_target" cargo build --release --quiet --manifest-path "$root/Cargo.toml" \
    -p plumetrace-cli
# The package is its own workspace; sharing the target directory reuses what the two builds
# have in common.
export CARGO_TARGET_DIR="$cli_target"
cargo fmt --manifest-path "$py/Cargo.toml" --check
cargo clippy --release --manifest-path "$py/Cargo.toml" --all-targets -- -D warnings

rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet "maturin==1.16.0" "gymnasium==1.4.0" "pytest>=7" "pandas" "tqdm" \
    "dask[distributed]"
"$venv/bin/pip" install --quiet "$py"
cd "$py/tests"
PLUMETRACE_BIN="$cli_target/release/plumetrace" "$venv/bin/python" -m pytest -q "$@"
