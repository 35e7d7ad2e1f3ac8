#!/usr/bin/env bash
# Cross-checks the onboard fuzzy navigation engine (crates/plumetrace-planner/src/fuzzy) against
# scikit-fuzzy 0.5.0 on 1,000 random inputs: the same Table I membership functions, the same rule
# table (exported by the Rust test), min for AND, max accumulation, centroid on the same grids.
# Only the stateless engine is compared (the side-locking Avoider is not part of it).
#
# Uses scikit-fuzzy 0.5.0 with numpy, scipy, networkx and packaging (skfuzzy imports all four;
# it declares none) in the virtual environment scripts/venvs.sh makes (scripts/.venv-fuzzy), runs the ignored Rust
# test `crosscheck_dump` to evaluate the inputs, then compares; exits non-zero when the largest
# difference of either output is more than 1 % of its range.
#
# Usage: scripts/fuzzy_crosscheck.sh [--n N] [--seed S] [--tolerance FRACTION]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
n=1000
seed=1
tolerance=0.01
while [ $# -gt 0 ]; do
    case "$1" in
        --n) n=$2; shift 2 ;;
        --seed) seed=$2; shift 2 ;;
        --tolerance) tolerance=$2; shift 2 ;;
        *) echo "unknown argument: $1" >&2; exit 2 ;;
    esac
done
venv=$(bash "$here/venvs.sh" fuzzy)

out="${CARGO_TARGET_DIR:-$root/target}/fuzzy-crosscheck"
mkdir -p "$out"
"$venv/bin/python" "$here/fuzzy_crosscheck.py" inputs --out "$out/inputs.csv" --n "$n" --seed "$seed"
FUZZY_INPUTS="$out/inputs.csv" FUZZY_OUTPUTS="$out/outputs.csv" FUZZY_RULES="$out/rules.csv" \
    cargo test --release --quiet --manifest-path "$root/Cargo.toml" --workspace \
    --test fuzzy_avoidance -- --ignored --exact crosscheck_dump
exec "$venv/bin/python" "$here/fuzzy_crosscheck.py" compare --inputs "$out/inputs.csv" \
    --outputs "$out/outputs.csv" --rules "$out/rules.csv" --tolerance "$tolerance"
