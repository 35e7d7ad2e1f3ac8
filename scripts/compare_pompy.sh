#!/usr/bin/env bash
# Side-by-side benchmark and statistics check of plumetrace against pompy 0.1.1, the reference
# implementation of the Farrell et al. (2002) plume model, on pompy's own scenario.
#
# Installs pompy 0.1.1 with numpy < 2.4 (pompy fails on numpy 2.4) and scipy into a virtual
# environment under scripts/.venv, builds plumetrace in release mode, times both in the same run
# and prints the ratios, then compares plume statistics (pompy seeds against four times as many
# plumetrace seeds, release 5/s, after a 100 s warm-up): mean live puff counts, cross-flow spreads
# of puffs at x = 25, 50 and 75 m, and intermittency there, the fraction of 10 Hz samples at z = 0
# above 0.2, both on the centreline (y = 0) and as the mean over a cross-flow transect (y = -40 to
# 40 m every metre), each with its standard error between seeds and that of the difference. The
# verdict asks live puffs, spreads and transect intermittency to agree within 10 %; the centreline
# intermittency is printed for information (it varies 30-60 % between seeds with the meander, too
# much to resolve 10 % without about a hundred pompy seeds).
#
# Usage: scripts/compare_pompy.sh [--quick] [--seeds N] [--stats-duration S] [--jobs J]
#                                 [--skip-timing] [--skip-stats] [--plumetrace BIN]
#                                 [--reference-build BIN]
#   --plumetrace BIN       check this plumetrace binary instead of building one (without it, the
#                          script runs cargo build --release and checks target/release/plumetrace)
#   --reference-build BIN  compare against this plumetrace binary instead of pompy: both builds run
#                          the same N seeds (100 .. 100 + N - 1), each row also gets the paired
#                          difference's standard error, pompy is neither installed nor run nor timed
#                          (only the venv is made if missing; the standard library is enough, so
#                          python3 scripts/compare_pompy.py ... runs it just as well). For example,
#                          to check a change to the filament model's numerics against the build
#                          before it: --plumetrace NEW --reference-build OLD --seeds 112
#                          --stats-duration 300 (about 2 s of one core per seed and build: 7.5
#                          minutes in all)
# The statistics cost about 2.7 minutes of one core per pompy seed of 300 s (pompy is slow; its
# four plumetrace seeds take seconds): --seeds 28 --stats-duration 300 --jobs 1 --skip-timing
# takes 76 minutes and resolves the transect intermittency to a standard error of 2-3 %. The full
# run (timing, then 8 seeds x 600 s) takes about fifty minutes on 2 cores; --quick takes a few
# minutes.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
venv="$here/.venv"
# The options this script acts on are also passed on to compare_pompy.py.
given_bin=0
reference=0
for arg in "$@"; do
    case "$arg" in
        --plumetrace|--plumetrace=*) given_bin=1 ;;
        --reference-build|--reference-build=*) reference=1 ;;
    esac
done
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
if [ "$reference" = 0 ]; then
    "$venv/bin/pip" install --quiet "pompy==0.1.1" "numpy<2.4" "scipy"
fi
if [ "$given_bin" = 1 ]; then
    exec "$venv/bin/python" "$here/compare_pompy.py" "$@"
fi
cargo build --release --quiet --manifest-path "$root/Cargo.toml" -p plumetrace-cli
exec "$venv/bin/python" "$here/compare_pompy.py" --plumetrace "$root/target/release/plumetrace" "$@"
