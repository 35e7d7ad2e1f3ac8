#!/usr/bin/env bash
# The fault table of the vehicle rehearsal: the demo and five coastal-family sites, each flown over
# the simulated front seat in lock-step without a fault and with each of five link faults, run
# seeds 1 to 10; counts the declarations within 20 m of the source and writes
# docs/results/fault-table.md (the command, the commit, the table).
#
#   scripts/fault_table.sh                  build the release binary, fly everything, write the page
#   scripts/fault_table.sh --bin PATH       a built plumetrace instead
#   scripts/fault_table.sh --jobs N         rehearsals at once (default: the number of cores)
#   scripts/fault_table.sh --runs N         run seeds 1..N (default 10)
#   scripts/fault_table.sh --sites N        coastal sites 0..N-1 (default 5)
#   scripts/fault_table.sh --site K         only coastal site K (no demo), e.g. with --out elsewhere
#   scripts/fault_table.sh --family-seed S  the coastal sites of campaign seed S (default 3202, the
#                                           benchmark's test seed of the coastal task)
#   scripts/fault_table.sh --out FILE       the page (default docs/results/fault-table.md)
#   scripts/fault_table.sh --table-only     only rewrite the page from the flights in target/fault-table/
#
# The faults (flags of `plumetrace frontseat`): 30 s without navigation from 305 s, 0.1 % of the
# front seat's lines dropped (fault seed = run seed), no current meter (`--no-flow`: the planner
# estimates the current from its track, from the prior on), a 10 s front-seat restart at 300 s,
# and the Iver remote helm with depths in feet (remote helm 4, on a pseudo-terminal). Work files
# go to target/fault-table/.
set -euo pipefail
cd "$(dirname "$0")/.."

bin=""
jobs="$(nproc)"
runs=10
sites=5
family_seed=3202
page="docs/results/fault-table.md"
table_only=0
only_site=""
while [ $# -gt 0 ]; do
    case "$1" in
        --bin) bin="$2"; shift 2 ;;
        --jobs) jobs="$2"; shift 2 ;;
        --runs) runs="$2"; shift 2 ;;
        --sites) sites="$2"; shift 2 ;;
        --site) only_site="$2"; shift 2 ;;
        --family-seed) family_seed="$2"; shift 2 ;;
        --out) page="$2"; shift 2 ;;
        --table-only) table_only=1; shift ;;
        -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
        *) echo "fault_table.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done

work="target/fault-table"
if [ "$table_only" -eq 0 ]; then
    if [ -z "$bin" ]; then
        cargo build --release --bin plumetrace
        bin="target/release/plumetrace"
    fi
    bin="$(realpath "$bin")"
    rm -rf "$work"
    mkdir -p "$work/sites"
    test_flag=()
    if [ "$family_seed" = 3202 ]; then test_flag=(--test-seeds); fi
    if [ -n "$only_site" ] && [ "$sites" -le "$only_site" ]; then sites=$((only_site + 1)); fi
    "$bin" family examples/families/coastal.family.toml --sample "$sites" --seed "$family_seed" \
        --out "$work/sites" "${test_flag[@]}" >/dev/null
fi

# name|fault flags
faults=(
    "none|"
    "silence|--silent-at 305 --silent-for 30"
    "drop|--drop 0.001 --fault-seed SEED"
    "no-flow|--no-flow"
    "restart|--restart-at 300 --restart-for 10"
    "iver-feet|--protocol iver --remote-helm-major 4"
)

# One rehearsal: $1 scenario key (demo or a site file), $2 fault name, $3 run seed.
fly_one() {
    local scenario="$1" fault="$2" seed="$3" flags="" f dir src
    for f in "${faults[@]}"; do
        if [ "${f%%|*}" = "$fault" ]; then flags="${f#*|}"; fi
    done
    flags="${flags//SEED/$seed}"
    dir="$work/runs/$(basename "$scenario" .toml)/$fault/$seed"
    mkdir -p "$dir"
    if [ "$scenario" = demo ]; then src=(--preset demo); else src=("$scenario"); fi
    # shellcheck disable=SC2086
    "$bin" frontseat "${src[@]}" --seed "$seed" --listen 127.0.0.1:0 --lock-step \
        --write-onboard "$dir/onboard.toml" --out "$dir" $flags >"$dir/frontseat.log" 2>&1 &
    local fs=$!
    for _ in $(seq 1 600); do
        [ -f "$dir/onboard.toml" ] && break
        kill -0 "$fs" 2>/dev/null || break
        sleep 0.1
    done
    if [ -f "$dir/onboard.toml" ]; then
        "$bin" onboard "$dir/onboard.toml" --out "$dir/out" >"$dir/onboard.log" 2>&1 || true
    fi
    wait "$fs" || true
}
export -f fly_one
export bin work
export FAULTS="$(printf '%s\n' "${faults[@]}")"

if [ -n "$only_site" ]; then
    scenarios=("$work/sites/site-$(printf '%03d' "$only_site").toml")
else
    scenarios=(demo)
    for k in $(seq 0 $((sites - 1))); do scenarios+=("$work/sites/site-$(printf '%03d' "$k").toml"); done
fi

start=$(date +%s)
if [ "$table_only" -eq 0 ]; then
for s in "${scenarios[@]}"; do
    for f in "${faults[@]}"; do
        for seed in $(seq 1 "$runs"); do echo "$s ${f%%|*} $seed"; done
    done
done | xargs -P "$jobs" -L 1 bash -c 'faults=(); while IFS= read -r l; do faults+=("$l"); done <<< "$FAULTS"; fly_one "$0" "$1" "$2"'
secs=$(( $(date +%s) - start ))
echo "$secs" > "$work/seconds"
fi
secs="$(cat "$work/seconds" 2>/dev/null || echo "?")"

commit="$(git rev-parse --short=12 HEAD)"
if ! git diff --quiet HEAD -- crates Cargo.toml Cargo.lock; then
    commit="$commit (with uncommitted changes to the code)"
fi
python3 - "$work" "$page" "$runs" "$commit" "$secs" "$family_seed" "$sites" "$(nproc)" \
    "$(printf '%s\n' "${faults[@]}")" "${scenarios[@]}" <<'EOF'
import json, math, sys, tomllib, datetime, os
work, page, runs, commit, secs, family_seed, nsites, cores, faults = sys.argv[1:10]
scenarios = sys.argv[10:]
runs = int(runs)
faults = [l.split("|", 1) for l in faults.splitlines() if l]

def source_of(s):
    if s == "demo":
        return (100.0, 0.0)
    with open(s, "rb") as f:
        t = tomllib.load(f)
    src = t["sources"][0]
    return (src["x_m"], src["y_m"])

def outcome(s, fault, seed):
    d = os.path.join(work, "runs", os.path.basename(s).removesuffix(".toml"), fault, str(seed))
    try:
        with open(os.path.join(d, "out", "onboard.json")) as f:
            j = json.load(f)
    except (OSError, ValueError):
        return None, "failed"
    decl = j.get("declarations") or []
    if not decl:
        return None, "none"
    sx, sy = source_of(s)
    x, y = decl[0]
    return math.hypot(x - sx, y - sy), None

rows = []
cells_ok = 0
totals = {name: [0, 0] for name, _ in faults}
for s in scenarios:
    name = "demo" if s == "demo" else os.path.basename(s).removesuffix(".toml")
    cells = []
    for fault, _ in faults:
        good, misses = 0, []
        for seed in range(1, runs + 1):
            err, why = outcome(s, fault, seed)
            if err is not None and err <= 20.0:
                good += 1
            else:
                misses.append(f"{seed} ({why if why else f'{err:.1f} m'})")
        totals[fault][0] += good
        totals[fault][1] += runs
        if good * 10 >= 9 * runs:
            cells_ok += 1
        cell = f"{good}/{runs}"
        if misses:
            cell += ": " + ", ".join(misses)
        cells.append(cell)
    rows.append((name, cells))

def site_line(s):
    if s == "demo":
        return None
    drawn = {}
    with open(s) as f:
        for line in f:
            if line.startswith("#   ") and "=" in line:
                k, v = line[4:].split("=", 1)
                drawn[k.strip()] = v.strip()
    return (f"flow toward {drawn.get('flow_toward_deg')} deg at {drawn.get('flow_speed_mps')} m/s, "
            f"start {drawn.get('start')}, source {drawn.get('source_edge_m')} m inside, "
            f"a fix every {drawn.get('fix_interval_s')} s")

out = []
out.append("# Results: `fault-table`\n")
out.append("The AMP's declaration on a vehicle under ordinary link faults, rehearsed with `frontseat`.\n")
out.append(("The demo and five coastal-family sites are" if "demo" in scenarios
            else "Coastal-family sites only (`--site`) are")
           + " flown over the simulated front seat in lock-step,")
out.append(f"run seeds 1 to {runs}, each without a fault and with each of five faults; a cell counts the")
out.append("runs declaring within 20 m of the source (the first declaration) and names the others")
out.append("(`none`: no declaration before the time limit).\n")
out.append(f"Produced at commit `{commit}` on {datetime.date.today()} by `scripts/fault_table.sh` "
           f"({cores} cores, {secs} s of wall time).")
site_names = [os.path.basename(s).removesuffix(".toml") for s in scenarios if s != "demo"]
site_range = (f"sites 0 to {int(nsites) - 1}" if "demo" in scenarios
              else ", ".join(site_names))
out.append(f"The coastal sites are {site_range} of `plumetrace family "
           f"examples/families/coastal.family.toml --seed {family_seed}`"
           + (" (the coastal task's test seed)" if family_seed == "3202" else "") + ".")
out.append("Each rehearsal is")
out.append("")
out.append("    plumetrace frontseat SCENARIO --seed S --listen 127.0.0.1:0 --lock-step --write-onboard onboard.toml FAULT")
out.append("    plumetrace onboard onboard.toml --out out")
out.append("")
out.append("with FAULT one of:\n")
out.append("| fault | flags |")
out.append("| --- | --- |")
for fault, flags in faults:
    out.append(f"| {fault} | `{flags.replace('SEED', 'S')}` |" if flags else f"| {fault} | (none) |")
out.append("")
out.append(f"{cells_ok} of {len(scenarios) * len(faults)} cells have at least 9 of {runs} runs "
           "within 20 m.\n")
out.append("| site | " + " | ".join(f for f, _ in faults) + " |")
out.append("| --- |" + " --- |" * len(faults))
for name, cells in rows:
    out.append(f"| {name} | " + " | ".join(cells) + " |")
out.append("| all | " + " | ".join(f"{g}/{n}" for g, n in totals.values()) + " |")
out.append("")
out.append("The sites:\n")
for s in scenarios:
    line = site_line(s)
    if line:
        out.append(f"- `{os.path.basename(s).removesuffix('.toml')}`: {line}")
with open(page, "w") as f:
    f.write("\n".join(out) + "\n")
print(f"fault_table.sh: wrote {page}: {cells_ok} of {len(scenarios) * len(faults)} cells at 9/{runs} or better")
EOF
