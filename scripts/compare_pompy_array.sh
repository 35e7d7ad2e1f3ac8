#!/usr/bin/env bash
# pompy's own concentration_array_demo set-up (100 m x 50 m, 21 x 11 wind grid, 10 puffs/s,
# concentrations on a 500 x 250 array at z = 0.01 m, time-averaged over the demo's 200 frames)
# run by pompy 0.1.1 and by plumetrace (its `pompy` preset with --set overrides that give the
# demo's every number), compared over many seeds: the time-averaged profile's width across the
# flow at x = 25, 50 and 75 m, the mean over the array region, the puff cloud's cross-flow
# spread at fixed times, and pompy's array generator against the exact sum of its own puffs.
# Results: docs/results/pompy-array.md.
#
# Installs pompy 0.1.1 with numpy < 2.4 and scipy into scripts/.venv (as compare_pompy.sh does);
# does not build plumetrace: it takes --bin PATH, else $PLUMETRACE_BIN, else target/release/plumetrace,
# else `plumetrace` on the PATH (build one with `cargo build --release -p plumetrace-cli`).
# Everything runs on one core (numpy's BLAS and plumetrace's RAYON_NUM_THREADS at 1).
#
# Usage: scripts/compare_pompy_array.sh [--bin PATH] [--pompy-seeds N] [--plumetrace-seeds M]
#                                       [--quick] [more options of compare_pompy_array.py]
#   --pompy-seeds N       pompy seeds 20181108 + k, k < N (default 200; the demo's seed first)
#   --plumetrace-seeds M  plumetrace seeds 1..M (default 4 N)
#   --quick               2 pompy and 4 plumetrace seeds (checks the pipeline in about a minute
#                         and a half, most of it pompy's own loop checked against the vectorised one)
#   --pompy-update pompy  step pompy with its own per-puff loop (about 56-62 s of CPU per seed
#                         instead of 3.4 s; the default vectorised loop is checked to give the
#                         same bits on the first --verify-seeds seeds, default 1)
#   --set KEY=VALUE       an extra plumetrace override (a variant); --reuse-pompy JSON takes
#                         pompy's seeds from an earlier --json PATH instead of running pompy
#   --diagnose            only the displays' diagnostics (pompy's generator and plumetrace's own
#                         grid against exact sums; under a minute)
# Cost on one core: about 6 s per pompy seed and 1.3 s per plumetrace seed, plus about 60 s per
# verified seed; the default (200 + 800 seeds) takes about 40 minutes.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
venv="$here/.venv"

bin=""
args=()
while [ $# -gt 0 ]; do
    case "$1" in
        --bin) bin=$2; shift 2 ;;
        --bin=*) bin=${1#--bin=}; shift ;;
        -h|--help)
            sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
            exit 0 ;;
        *) args+=("$1"); shift ;;
    esac
done
if [ -z "$bin" ]; then
    if [ -n "${PLUMETRACE_BIN:-}" ]; then
        bin=$PLUMETRACE_BIN
    elif [ -x "$root/target/release/plumetrace" ]; then
        bin=$root/target/release/plumetrace
    elif command -v plumetrace >/dev/null 2>&1; then
        bin=$(command -v plumetrace)
    else
        echo "no plumetrace binary: give --bin PATH (or build one: cargo build --release -p plumetrace-cli)" >&2
        exit 2
    fi
fi
if [ ! -x "$bin" ]; then
    echo "not an executable: $bin" >&2
    exit 2
fi

if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet "pompy==0.1.1" "numpy<2.4" "scipy"
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 RAYON_NUM_THREADS=1
echo "plumetrace: $bin ($("$bin" --version))"
exec "$venv/bin/python" "$here/compare_pompy_array.py" --plumetrace "$bin" ${args[@]+"${args[@]}"}
