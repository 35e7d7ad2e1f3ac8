#!/usr/bin/env bash
# The Python package's checks: formatting and lints of its Rust crate, then `pip install` of the
# package from the repository (maturin builds the wheel) into the virtual environment
# scripts/venvs.sh makes, its
# pytest suite (which compares with the release command line, so it builds that too), and every
# example of examples/python at a small size.
#
# Usage: scripts/python_tests.sh [pytest arguments]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
py="$root/crates/plumetrace-py"
cli_target="${CARGO_TARGET_DIR:-$root/target}"

# As the README's first command builds it (the same packages selected, so the same build).
(cd "$root" && CARGO_TARGET_DIR="$cli_target" cargo build --release --quiet --bin plumetrace)
# The package is its own workspace; sharing the target directory reuses what the two builds
# have in common.
export CARGO_TARGET_DIR="$cli_target"
cargo fmt --manifest-path "$py/Cargo.toml" --check
cargo clippy --release --manifest-path "$py/Cargo.toml" --all-targets -- -D warnings

# The environment (maturin, Gymnasium, pytest, the optional dependencies) is made once by
# scripts/venvs.sh; the package itself is installed into it anew every time.
venv=$(bash "$here/venvs.sh" package)
start=$SECONDS
"$venv/bin/pip" install --quiet --force-reinstall --no-deps "$py"
echo "pip install of the package: $((SECONDS - start)) s"
(cd "$py/tests" && PLUMETRACE_BIN="$cli_target/release/plumetrace" "$venv/bin/python" -m pytest -q "$@")

# The examples, small: each must run to its end.
examples="$root/examples/python"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
run_example() {
    echo "examples/python/$*"
    "$venv/bin/python" "$examples/$@" >"$work/example.log" 2>&1 || {
        cat "$work/example.log"
        echo "examples/python/$1 failed" >&2
        exit 1
    }
}
run_example quick_start.py --seed 7 --out "$work/quick"
run_example python_planner.py --seed 9
run_example plot_trajectory.py --seed 7 --out "$work/track.png"
run_example gym_training.py --iterations 2 --envs 2 --steps 50
run_example dask_campaign.py --example "$work/dask" --seeds 1 --shards 2 --workers 1
echo "examples: 5 passed, 0 failed"
