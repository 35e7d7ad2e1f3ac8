#!/usr/bin/env bash
# Times what two builds of plumetrace run, side by side, after a change of the build (a profile,
# an optimisation level), and prints the table of docs/results/performance.md's "Set-up:
# building" sections (paste it whole; never edit its numbers by hand):
#
#   scripts/runtime_pairs.sh --before BIN --after BIN [--pairs N]
#
# Each command below runs with the two builds alternately (before, after, before, after, ...;
# `--pairs` pairs, default 5) as a whole process, timed for CPU (user + system); the table gives
# the median of the pairs' ratios (after / before) and their range, and the median CPU of each
# build. The commands' outputs must be the same bytes with both builds (the script stops if not;
# wall times and stage times are left out of the comparison):
# - `bench missions --runs 16 --threads 1` (16 `duck-2003-st` missions);
# - `run --preset duck-2003-st --seed 7` (every default output);
# - a campaign of 20 coastal and 20 fault sites, two configurations (examples/campaigns/
#   amp-families.toml, `--seeds 20 --jobs 1`): the sites are built by the scenario crate;
# - `check` of that campaign file, 20 times (parsing, overrides, eight family sites built);
# - `family` of the coastal family, `--sample 100` (100 sites drawn, built and written);
# - `replay` of the seed-7 run's snapshot log (23,580 decisions).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/pairs_common.sh

before=""
after=""
pairs=5
while [ $# -gt 0 ]; do
    case "$1" in
        --before|--after|--pairs) needs_value runtime_pairs.sh "$1" $# ;;
    esac
    case "$1" in
        --before) before="$2"; shift 2 ;;
        --after) after="$2"; shift 2 ;;
        --pairs) pairs="$2"; shift 2 ;;
        -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
        *) echo "runtime_pairs.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
if [ -z "$before" ] || [ -z "$after" ]; then
    echo "runtime_pairs.sh: --before BIN and --after BIN are needed: the two builds (see --help)" >&2
    exit 2
fi
for b in "$before" "$after"; do
    if ! [ -x "$b" ] || ! "$b" --version 2>/dev/null | grep -q '^plumetrace '; then
        echo "runtime_pairs.sh: $b is not an executable plumetrace build" >&2
        exit 2
    fi
done
whole_count runtime_pairs.sh --pairs "$pairs"
before=$(realpath "$before")
after=$(realpath "$after")
root=$(pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The seed-7 log both builds replay (written once, by the before build).
"$before" run --preset duck-2003-st --seed 7 --out "$work/log" >/dev/null

# Command `$1` with build `$2` into directory `$3` (emptied first).
command_of() {
    local which="$1" bin="$2" out="$3"
    rm -rf "$out"
    mkdir -p "$out"
    case "$which" in
        bench) "$bin" bench missions --runs 16 --threads 1 >"$out/bench.json" ;;
        run) "$bin" run --preset duck-2003-st --seed 7 --out "$out/run" >/dev/null ;;
        campaign) "$bin" campaign "$root/examples/campaigns/amp-families.toml" --seeds 20 \
            --jobs 1 --out "$out/campaign" >/dev/null 2>&1 ;;
        check) for _ in $(seq 20); do
                "$bin" check "$root/examples/campaigns/amp-families.toml" >"$out/check.txt"
            done ;;
        family) "$bin" family "$root/examples/families/coastal.family.toml" --sample 100 \
            --out "$out/family" >/dev/null ;;
        replay) "$bin" replay "$work/log/snapshots.jsonl.gz" >"$out/replay.txt" ;;
    esac
}

# The outputs to compare: everything but timings.
fingerprint() {
    local which="$1" out="$2"
    case "$which" in
        bench) grep -E '"(preset|runs|threads|mean_mission_s|outcomes)"' "$out/bench.json" ;;
        run) (cd "$out/run" && for f in trajectory.csv events.jsonl plot.svg replay.html; do
                md5sum "$f"; done) ;;
        campaign) md5sum <"$out/campaign/runs.csv" ;;
        check) md5sum <"$out/check.txt" ;;
        family) (cd "$out/family" && find . -type f | sort | xargs md5sum) ;;
        replay) md5sum <"$out/replay.txt" ;;
    esac
}

export -f command_of
export root work
cpu_of() {
    if ! /usr/bin/time -o "$work/time" -f '%U %S' bash -c 'command_of "$@"' _ "$1" "$2" "$3"; then
        echo "runtime_pairs.sh: $1 failed with $2" >&2
        return 1
    fi
    tail -1 "$work/time" | awk '{ printf "%.3f", $1 + $2 }'
}

# A build is named by its directory when the file is `plumetrace` (`../at-COMMIT/target/release`
# names itself `release`: copy it to a directory named after its commit first).
name_of() {
    if [ "$(basename "$1")" = plumetrace ]; then basename "$(dirname "$1")"; else basename "$1"; fi
}
echo "\`$(name_of "$before")\` (before) against \`$(name_of "$after")\` (after), $pairs pairs,"
echo "alternately, on $(nproc) cores; $(date -u +%Y-%m-%d):"
echo
echo "| command | before: CPU, median | after: CPU, median | after / before: median (range) |"
echo "| --- | --- | --- | --- |"
for which in bench run campaign check family replay; do
    bs=() as=() rs=()
    for k in $(seq 1 "$pairs"); do
        b=$(cpu_of "$which" "$before" "$work/b")
        a=$(cpu_of "$which" "$after" "$work/a")
        fb=$(fingerprint "$which" "$work/b")
        fa=$(fingerprint "$which" "$work/a")
        if [ "$fb" != "$fa" ]; then
            echo "runtime_pairs.sh: $which: the two builds' outputs differ (pair $k)" >&2
            exit 1
        fi
        bs+=("$b")
        as+=("$a")
        rs+=("$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.3f", a / b }')")
    done
    echo "| $which | $(median "${bs[@]}") s | $(median "${as[@]}") s | $(median_range "${rs[@]}") |"
done
