#!/usr/bin/env bash
# Splits the filament step of pompy's case into what every step costs whatever the number of
# filaments and what each filament adds, and writes the section "The filament step's fixed and
# per-filament parts" of docs/results/performance.md (between its begin and end marks; never
# edit its numbers by hand):
#
#   scripts/plume_step_parts.sh [--bin BIN --commit HASH] [--rates R,R,...] [--repeats N] [--duration S]
#
# For each release rate R (puffs per second; default 1,2.5,5,10, around pompy's case's 5), it
# runs `BIN bench plume --release-rate R --duration S --queries 1000` N times (default 3; S
# default 500 simulated seconds) and takes the medians of the nanoseconds per step, of the
# filaments alive on average, of the nanoseconds per filament-step and of the flow grid's share
# of a step. A least-squares line of the nanoseconds per step against the filaments alive gives
# the fixed part (its intercept) and each filament's part (its slope); from them, what each
# filament could cost for the step at 5 puffs/s to take 5 ns a filament. BIN defaults to this
# checkout's release build (built first), HASH (the commit BIN was built from, which the page
# names) to this checkout's.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/pairs_common.sh

bin=""
commit=""
rates="1,2.5,5,10"
repeats=3
duration=500
while [ $# -gt 0 ]; do
    case "$1" in
        --bin|--commit|--rates|--repeats|--duration) needs_value plume_step_parts.sh "$1" $# ;;
    esac
    case "$1" in
        --bin) bin="$2"; shift 2 ;;
        --commit) commit="$2"; shift 2 ;;
        --rates) rates="$2"; shift 2 ;;
        --repeats) whole_count plume_step_parts.sh --repeats "$2"; repeats="$2"; shift 2 ;;
        --duration) duration="$2"; shift 2 ;;
        -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
        *) echo "plume_step_parts.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    esac
done
number='^[0-9]+([.][0-9]+)?$'
IFS=, read -r -a rate_list <<<"$rates"
for r in "${rate_list[@]}"; do
    if ! [[ "$r" =~ $number ]] || [ "$(awk -v r="$r" 'BEGIN { print (r > 0) }')" != 1 ]; then
        echo "plume_step_parts.sh: --rates takes puffs per second above 0, comma-separated, not '$r'" >&2
        exit 2
    fi
done
if [ "$(printf '%s\n' "${rate_list[@]}" | sort -gu | wc -l)" -lt 2 ]; then
    echo "plume_step_parts.sh: --rates needs two rates or more to fit a line, not '$rates'" >&2
    exit 2
fi
if ! [[ "$duration" =~ $number ]] || [ "$(awk -v d="$duration" 'BEGIN { print (d > 0) }')" != 1 ]; then
    echo "plume_step_parts.sh: --duration takes simulated seconds above 0, not '$duration'" >&2
    exit 2
fi
if [ -n "$bin" ] && [ -z "$commit" ]; then
    echo "plume_step_parts.sh: --bin needs --commit, the commit the program was built from" >&2
    exit 2
fi
if [ -z "$bin" ]; then
    cargo build --release --bin plumetrace >&2
    bin=target/release/plumetrace
    commit=$(git rev-parse --short HEAD)
fi
if [ ! -x "$bin" ]; then
    echo "plume_step_parts.sh: no program at '$bin' (--bin takes a built plumetrace)" >&2
    exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for r in "${rate_list[@]}"; do
    for k in $(seq "$repeats"); do
        echo "rate $r, run $k of $repeats" >&2
        "$bin" bench plume --release-rate "$r" --duration "$duration" --queries 1000 >"$work/$r-$k.json"
    done
done
cpu="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"
section="$(python3 - "$work" "$repeats" "${rate_list[@]}" <<'PY'
import json, statistics, sys

work, repeats, rates = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
rows = []
for r in rates:
    runs = [json.load(open(f"{work}/{r}-{k}.json")) for k in range(1, repeats + 1)]
    med = lambda key: statistics.median(run[key] for run in runs)
    rows.append((r, med("mean_live_filaments"), med("ns_per_step"), med("ns_per_filament_step"),
                 med("flow_ns_per_step")))
n = [row[1] for row in rows]
t = [row[2] for row in rows]
mn, mt = statistics.fmean(n), statistics.fmean(t)
sxx = sum((a - mn) ** 2 for a in n)
if sxx <= 0:
    sys.exit("plume_step_parts.sh: every rate left the same number of filaments alive: no line to fit")
slope = sum((a - mn) * (b - mt) for a, b in zip(n, t)) / sxx
fixed = mt - slope * mn
flow = statistics.median(row[4] for row in rows)
out = ["| puffs/s | filaments alive | ns a step | ns a filament-step | flow grid, ns a step |",
       "| --- | --- | --- | --- | --- |"]
for r, live, step, per, fl in rows:
    out.append(f"| {r} | {live:.0f} | {step:.0f} | {per:.2f} | {fl:.0f} |")
out.append("")
out.append("Each figure is the median of the calls; a call's nanoseconds per filament-step are "
           "the median of its five timed blocks, so they are not quite its nanoseconds per step "
           "over its filaments alive.")
out.append("")
out.append(f"The least-squares line over these {len(rows)} rates: **{fixed:.0f} ns a step whatever "
           f"the number of filaments, and {slope:.2f} ns for each filament**. The flow grid's step "
           f"(every fifth plume step in pompy's case, its cost spread over the five) is "
           f"{flow:.0f} ns of the fixed part.")
pompy = [row for row in rows if float(row[0]) == 5.0]
if pompy:
    live = pompy[0][1]
    allowed = 5.0 * live
    per = (allowed - fixed) / live
    out.append("")
    out.append(f"In pompy's case (5 puffs/s, {live:.0f} filaments alive), 5 ns a filament-step "
               f"is {allowed:.0f} ns a step; with the fixed part as it is, each filament could "
               f"cost {per:.2f} ns, against the line's {slope:.2f} ns ({per / slope - 1:+.0%}).")
print("\n".join(out))
PY
)"
# The vector unit the filament step ran on (its `bench plume` says).
first_rate="${rates%%,*}"
unit="$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1])).get("vector_unit", "unknown"))' "$work/$first_rate-1.json")"
page="docs/results/performance.md"
begin="<!-- plume_step_parts.sh begin -->"
end="<!-- plume_step_parts.sh end -->"
{
    echo "$begin"
    echo
    echo "**Measured** by \`scripts/plume_step_parts.sh --rates $rates --repeats $repeats --duration"
    echo "$duration\` at commit \`$commit\` on $(date -u +%Y-%m-%d) ($(nproc) cores, $cpu, vector unit $unit): \`plumetrace"
    echo "bench plume --release-rate R --duration $duration --queries 1000\` in pompy's case at each rate,"
    echo "$repeats times."
    echo
    echo "$section"
    echo
    echo "$end"
} >"$work/section"
write_section "$page" "$work/section" "$begin" "$end" "The filament step's fixed and per-filament parts"
echo "wrote the section of $page" >&2
