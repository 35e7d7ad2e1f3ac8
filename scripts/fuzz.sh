#!/usr/bin/env bash
# Fuzzes plumetrace's scenario, campaign, family and onboard files, and the NetCDF currents and
# bathymetry readers, with the plumetrace-fuzz harness (crates/plumetrace-fuzz): mutated presets
# and example campaigns are checked as `plumetrace check` does, accepted scenarios are run
# briefly, campaigns are resolved and checked, mutated currents and bathymetry files are read by
# the example site's scenario (every 16th input, the two in turn), and every input is classified (accepted, rejected_located, or a finding: rejected_unlocated, panic,
# nonfinite_output, hang, abort). Inputs run in child processes limited to 2 GB of address space
# (prlimit) and 30 s each; findings are written to OUT/findings/<class>/<index>.toml with the
# message in <index>.txt. The last line of output is a JSON report; exit status 1 if anything
# was found.
#
# Usage: scripts/fuzz.sh [--quick] [pass options...]
#   --quick              3,000 inputs on 2 jobs (under 2 minutes on 2 cores)
#   (default)            1,000,000 inputs on every core
#   any other option goes to `plumetrace-fuzz pass`, e.g. --inputs 50000 --seed 7 --jobs 4
#   --out DIR (default target/fuzz-out)
# Replay one input: target/release/plumetrace-fuzz one --index I --seed S
#
# CARGO_TARGET_DIR is honoured (default: target).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
target_dir=${CARGO_TARGET_DIR:-$root/target}
cargo build --release --quiet --manifest-path "$root/Cargo.toml" -p plumetrace-fuzz
bin="$target_dir/release/plumetrace-fuzz"

quick=()
args=()
have_out=0
for a in "$@"; do
    case "$a" in
        --quick) quick=(--quick) ;;
        --out|--out=*) have_out=1; args+=("$a") ;;
        *) args+=("$a") ;;
    esac
done
if [ "$have_out" = 0 ]; then
    args+=(--out "$target_dir/fuzz-out")
fi
# The pass's defaults are the limits above (--memory-mb 2048, --timeout-s 30); give either
# option to change it.
exec "$bin" pass ${quick[@]+"${quick[@]}"} ${args[@]+"${args[@]}"}
