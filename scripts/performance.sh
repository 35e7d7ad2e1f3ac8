#!/usr/bin/env bash
# Measures two builds side by side and writes the section "Outputs and campaign throughput, side by
# side" of docs/results/performance.md (between its begin and end marks; never edit its numbers
# by hand):
#
#   scripts/performance.sh --before BIN --before-commit HASH [--after BIN] [--pairs N] [--seeds N] [--jobs N]
#                          [--outputs-differ]
#
# BIN is a built plumetrace and HASH the commit it was built from (the page names it); `--after`
# defaults to this checkout's release build (built first).
# Build the commit to compare against beside this checkout (`git worktree add ../at-COMMIT COMMIT
# && cargo build --release --manifest-path ../at-COMMIT/Cargo.toml -p plumetrace-cli`).
#
# Every measurement runs the two builds alternately (before, after, before, after, ...; `--pairs`
# pairs, default 3), each as a whole process timed for wall and CPU (user + system):
# - a single run, `plumetrace run --preset duck-2003-st --seed 7 --stats` with every default
#   output, on one thread (`RAYON_NUM_THREADS=1`), so that the stage times (summary.json) are one
#   thread's time: the record stage's share is its time over the process's wall time;
# - a campaign of `--seeds` seeds (default 1000) of `duck-2003-st`, `plumetrace campaign --jobs
#   N` (default 2), whole process with runs.csv, summary and charts written;
# - `plumetrace bench missions --runs 48 --threads J` once per build;
# - the filament step, `plumetrace bench plume` in pompy's case (5 puffs/s), at 50 puffs/s
#   (`--release-rate 50`) and at field scale (`--case field`), once per build in each pair.
# The two campaigns' runs.csv must be the same (apart from any run-time column); the script stops
# if they are not. A change that alters the numbers the simulation computes (`--outputs-differ`)
# is compared by its statistics instead: the first pair's two campaigns go through
# scripts/two_sample.sh (Fisher's exact test for the rates, Kolmogorov-Smirnov and Mann-Whitney U
# for the errors and times, alpha 0.01), whose table the section then holds.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/pairs_common.sh

before=""
before_commit=""
after=""
pairs=3
seeds=1000
jobs=2
outputs_differ=""
while [ $# -gt 0 ]; do
    case "$1" in
        --before|--before-commit|--after|--pairs|--seeds|--jobs)
            needs_value performance.sh "$1" $# ;;
    esac
    case "$1" in
        --before) before="$2"; shift 2 ;;
        --before-commit) before_commit="$2"; shift 2 ;;
        --after) after="$2"; shift 2 ;;
        --pairs) pairs="$2"; shift 2 ;;
        --seeds) seeds="$2"; shift 2 ;;
        --jobs) jobs="$2"; shift 2 ;;
        --outputs-differ) outputs_differ=1; shift ;;
        -h|--help) sed -n '2,28p' "$0"; exit 0 ;;
        *) echo "performance.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
whole_count performance.sh --pairs "$pairs"
whole_count performance.sh --seeds "$seeds"
whole_count performance.sh --jobs "$jobs"
if [ -z "$before" ] || [ -z "$before_commit" ]; then
    echo "performance.sh: --before BIN and --before-commit HASH are needed: a build of the commit to compare against, and that commit (see --help)" >&2
    exit 2
fi
for b in "$before" "$after"; do
    if [ -n "$b" ] && [ ! -x "$b" ]; then
        echo "performance.sh: $b is not an executable plumetrace build" >&2
        exit 2
    fi
done
if [ ! -x /usr/bin/time ]; then
    echo "performance.sh: needs /usr/bin/time (GNU time) for the CPU times" >&2
    exit 2
fi
if [ -z "$after" ]; then
    cargo build --release --bin plumetrace
    after="target/release/plumetrace"
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
commit="$(git rev-parse --short=12 HEAD)"
if ! git diff --quiet HEAD -- crates Cargo.toml Cargo.lock; then
    commit="$commit (with uncommitted changes to the code)"
fi
cores="$(nproc)"
cpu="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"

cat > "$work/campaign.toml" <<EOF
name = "duck-throughput"
description = "duck-2003-st at $seeds seeds, one configuration"
seed = 1
seeds = $seeds
scenarios = ["duck-2003-st"]

[[configs]]
name = "amp"
EOF

# One timed process: "user sys wall" into $1, the command after it.
timed() {
    local out="$1"
    shift
    /usr/bin/time -f "%U %S %e" -o "$out" "$@" >/dev/null 2>"$out.err" || {
        echo "performance.sh: failed: $*" >&2
        cat "$out.err" >&2
        exit 1
    }
}

# The single run's numbers: "cpu wall record_s share" (share = record stage over the wall time).
single() {
    local bin="$1" tag="$2"
    rm -rf "$work/run-$tag"
    RAYON_NUM_THREADS=1 timed "$work/run-$tag.time" "$bin" run --preset duck-2003-st --seed 7 \
        --stats --out "$work/run-$tag"
    python3 - "$work/run-$tag.time" "$work/run-$tag/summary.json" <<'PY'
import json, sys
user, sys_, wall = (float(v) for v in open(sys.argv[1]).read().split()[-3:])
st = json.load(open(sys.argv[2]))["stage_times"]
record = st["record_s"]
print(f"{user + sys_:.3f} {wall:.3f} {record:.3f} {record / wall:.3f}")
PY
}

# The campaign's numbers: "cpu wall missions_per_s"; its runs.csv kept as runs-$tag.csv.
campaign() {
    local bin="$1" tag="$2"
    rm -rf "$work/camp-$tag"
    timed "$work/camp-$tag.time" "$bin" campaign "$work/campaign.toml" --out "$work/camp-$tag" \
        --jobs "$jobs"
    cp "$work/camp-$tag/runs.csv" "$work/runs-$tag.csv"
    read -r user sys_ wall < <(tail -1 "$work/camp-$tag.time")
    python3 -c "print(f'{$user + $sys_:.2f} {$wall:.2f} {$seeds / $wall:.2f}')"
}

# The filament step's cost in the three cases: "pompy rate50 field", ns per filament-step (the
# median of each call's blocks).
kernel() {
    local bin="$1" tag="$2" case
    for case in pompy rate50 field; do
        local args=()
        [ "$case" = rate50 ] && args=(--release-rate 50)
        [ "$case" = field ] && args=(--case field)
        "$bin" bench plume "${args[@]}" > "$work/plume-$tag-$case.json" 2>"$work/plume-$tag-$case.err" || {
            echo "performance.sh: failed: $bin bench plume ${args[*]}" >&2
            cat "$work/plume-$tag-$case.err" >&2
            exit 1
        }
    done
    python3 - "$work/plume-$tag" <<'PY'
import json, sys
print(" ".join(f"{json.load(open(f'{sys.argv[1]}-{c}.json'))['ns_per_filament_step']:.2f}"
               for c in ("pompy", "rate50", "field")))
PY
}

# runs.csv without its run-time columns.
strip_times() {
    python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
keep = [i for i, h in enumerate(rows[0]) if "wall" not in h and h != "cpu_s"]
for r in rows:
    print(",".join(r[i] for i in keep))
PY
}

echo "== $pairs pairs of single runs, of $seeds-seed campaigns and of filament steps, before and after" >&2
: > "$work/single"
: > "$work/camp"
: > "$work/kernel"
for k in $(seq 1 "$pairs"); do
    for side in before after; do
        bin="$before"
        [ "$side" = after ] && bin="$after"
        # Each result is taken into a variable first, so that a failed measurement stops the
        # script (`set -e`) instead of writing an empty row.
        row="$(single "$bin" "$side-$k")"
        echo "$side $row" >> "$work/single"
        row="$(campaign "$bin" "$side-$k")"
        echo "$side $row" >> "$work/camp"
        tail -1 "$work/camp" >&2
        row="$(kernel "$bin" "$side-$k")"
        echo "$side $row" >> "$work/kernel"
    done
    if [ -z "$outputs_differ" ] && ! cmp -s <(strip_times "$work/runs-before-$k.csv") <(strip_times "$work/runs-after-$k.csv"); then
        echo "performance.sh: the two builds' runs.csv differ (pair $k; --outputs-differ compares their statistics instead): $work kept" >&2
        trap - EXIT
        exit 1
    fi
    # Each build gives the same runs in every pair.
    for side in before after; do
        if ! cmp -s <(strip_times "$work/runs-$side-1.csv") <(strip_times "$work/runs-$side-$k.csv"); then
            echo "performance.sh: the $side build's runs.csv differ between pairs 1 and $k: $work kept" >&2
            trap - EXIT
            exit 1
        fi
    done
done
for side in before after; do
    bin="$before"
    [ "$side" = after ] && bin="$after"
    "$bin" bench missions --runs 48 --threads "$jobs" > "$work/bench-$side.json"
done
load="$(cut -d' ' -f1-3 /proc/loadavg)"

# With --outputs-differ: the first pair's campaigns, one configuration each, side by side.
two_sample=""
if [ -n "$outputs_differ" ]; then
    python3 - "$work/runs-before-1.csv" "$work/runs-after-1.csv" "$work/both.csv" <<'PY'
import csv, sys
rows, fields = [], None
for path, name in ((sys.argv[1], "before"), (sys.argv[2], "after")):
    with open(path, newline="") as f:
        r = csv.DictReader(f)
        fields = r.fieldnames
        for row in r:
            row["config"] = name
            rows.append(row)
with open(sys.argv[3], "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=fields)
    w.writeheader()
    w.writerows(rows)
PY
    # Its exit status is 1 when some p-value is below alpha (the table says which), 2 or more
    # when the comparison itself failed.
    status=0
    two_sample="$(bash scripts/two_sample.sh "$work/both.csv" before after --alpha 0.01)" || status=$?
    if [ "$status" -gt 1 ] || ! grep -q '^smallest p-value' <<<"$two_sample"; then
        echo "performance.sh: the two-sample comparison failed: $work kept" >&2
        trap - EXIT
        exit 1
    fi
    if [ "$status" = 1 ]; then
        echo "performance.sh: some p-value is below 0.01: the section says which" >&2
    fi
    # The seeds are shared, so the runs pair up: how many differ in outcome.
    paired="$(python3 - "$work/runs-before-1.csv" "$work/runs-after-1.csv" <<'PY'
import csv, sys
a, b = (list(csv.DictReader(open(p))) for p in sys.argv[1:3])
keys = ("outcome", "success", "declared", "declarations")
differ = sum(1 for x, y in zip(a, b) if any(x[k] != y[k] for k in keys))
print(f"{differ} of {len(a)}")
PY
)"
fi

section="$(python3 - "$work" "$pairs" "$seeds" "$jobs" <<'PY'
import json, statistics, sys
work, pairs, seeds, jobs = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
def table(name):
    rows = {"before": [], "after": []}
    for line in open(f"{work}/{name}"):
        side, *vals = line.split()
        rows[side].append([float(v) for v in vals])
    return rows
def med(rows, k):
    return statistics.median(r[k] for r in rows)
def span(rows, k, fmt):
    vals = sorted(r[k] for r in rows)
    return f"{fmt.format(statistics.median(vals))} ({fmt.format(vals[0])}-{fmt.format(vals[-1])})"
s, c, kern = table("single"), table("camp"), table("kernel")
bench = {side: json.load(open(f"{work}/bench-{side}.json")) for side in ("before", "after")}
def b(side, key):
    return bench[side]["results"][0][key]
out = []
out.append("| | before | after | after / before |")
out.append("| --- | --- | --- | --- |")
out.append(f"| single run: process CPU (user + system) | {span(s['before'], 0, '{:.3f}')} s | {span(s['after'], 0, '{:.3f}')} s | {med(s['after'], 0) / med(s['before'], 0):.2f} |")
out.append(f"| single run: record stage | {span(s['before'], 2, '{:.3f}')} s | {span(s['after'], 2, '{:.3f}')} s | {med(s['after'], 2) / med(s['before'], 2):.2f} |")
out.append(f"| single run: record stage's share of the run | {span(s['before'], 3, '{:.0%}')} | {span(s['after'], 3, '{:.0%}')} | |")
out.append(f"| campaign of {seeds} seeds, {jobs} jobs: wall time | {span(c['before'], 1, '{:.1f}')} s | {span(c['after'], 1, '{:.1f}')} s | {med(c['after'], 1) / med(c['before'], 1):.2f} |")
out.append(f"| campaign: CPU (user + system) | {span(c['before'], 0, '{:.1f}')} s | {span(c['after'], 0, '{:.1f}')} s | {med(c['after'], 0) / med(c['before'], 0):.2f} |")
out.append(f"| campaign: missions per second | {span(c['before'], 2, '{:.2f}')} | {span(c['after'], 2, '{:.2f}')} | {med(c['after'], 2) / med(c['before'], 2):.2f} |")
out.append(f"| campaign: CPU per mission | {med(c['before'], 0) / seeds:.3f} s | {med(c['after'], 0) / seeds:.3f} s | |")
out.append(f"| `bench missions --runs 48 --threads {jobs}`: CPU per mission | {b('before', 'cpu_per_mission_s'):.3f} s | {b('after', 'cpu_per_mission_s'):.3f} s | {b('after', 'cpu_per_mission_s') / b('before', 'cpu_per_mission_s'):.2f} |")
out.append(f"| `bench missions`: missions per second | {b('before', 'missions_per_s'):.2f} | {b('after', 'missions_per_s'):.2f} | {b('after', 'missions_per_s') / b('before', 'missions_per_s'):.2f} |")
for k, what in enumerate(["`bench plume` (pompy's case, 5 puffs/s)", "`bench plume --release-rate 50`", "`bench plume --case field`"]):
    out.append(f"| {what}: ns per filament-step | {span(kern['before'], k, '{:.2f}')} | {span(kern['after'], k, '{:.2f}')} | {med(kern['after'], k) / med(kern['before'], k):.2f} |")
stages = bench["after"]["stages_s_per_mission"]
total = sum(stages.values())
split = ", ".join(f"{k.replace('_', ' ')} {v / total:.0%}" for k, v in stages.items() if v / total >= 0.005)
out.append("")
out.append(f"Medians over {pairs} pairs, the range in brackets. Where a campaign mission's time goes "
           f"after (`bench missions`' split by stage, share of the stages' total): {split}.")
print("\n".join(out))
PY
)"

# The vector unit the after build's filament step ran on (its `bench plume` says).
unit="$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1])).get("vector_unit", "unknown"))' "$work/plume-after-1-pompy.json")"
page="docs/results/performance.md"
begin="<!-- performance.sh begin -->"
end="<!-- performance.sh end -->"
{
    echo "$begin"
    echo
    echo "**Measured** by \`scripts/performance.sh --before BIN --before-commit $before_commit --pairs $pairs"
    echo "--seeds $seeds --jobs $jobs${outputs_differ:+ --outputs-differ}\` at commit \`$commit\` (after) against the build of \`$before_commit\`"
    echo "(before) on $(date -u +%Y-%m-%d) ($cores cores, $cpu, vector unit $unit; load average $load at the end). The single run is \`plumetrace run --preset"
    echo "duck-2003-st --seed 7 --stats\` on one thread (\`RAYON_NUM_THREADS=1\`) with every default"
    echo "output; the campaign is \`plumetrace campaign FILE --out DIR --jobs $jobs\` over \`scenarios ="
    echo "[\"duck-2003-st\"]\`, \`seeds = $seeds\`, one configuration, timed as a whole process with"
    if [ -n "$outputs_differ" ]; then
        echo "its files written; the change alters the numbers the simulation computes, so the two builds'"
        echo "runs.csv differ (\`--outputs-differ\`), and the first pair's two campaigns are compared by"
        echo "their statistics below. The filament step is \`plumetrace bench"
    else
        echo "its files written; the two builds' runs.csv are the same (the script compares them, any"
        echo "column of run times set aside, and stops if they differ). The filament step is \`plumetrace bench"
    fi
    echo "plume\` in its three cases, once per build in each pair (each call's figure the median of its"
    echo "five blocks)."
    echo
    echo "$section"
    echo
    if [ -n "$two_sample" ]; then
        echo "The first pair's two campaigns ($seeds seeds each, the same seeds), before against after"
        echo "(\`scripts/two_sample.sh\`; its tests take the two campaigns as independent samples, which,"
        echo "the seeds being the same, makes them conservative; run by run, $paired runs differ in"
        echo "outcome, success or declarations):"
        echo
        echo "$two_sample"
        echo
    fi
    echo "$end"
} > "$work/section"
write_section "$page" "$work/section" "$begin" "$end" "Outputs and campaign throughput, side by side"
echo "wrote the section of $page" >&2
