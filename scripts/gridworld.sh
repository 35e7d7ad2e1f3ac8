#!/usr/bin/env bash
# Regenerates docs/results/infotaxis-grid-world.md: infotaxis in the windy grid world against the
# numbers published with otto-benchmark, written whole from `plumetrace bench infotaxis` (never
# edit a number by hand). About 5 minutes of CPU on one core.
#
#   scripts/gridworld.sh [--bin PATH] [--jobs N] [--reuse]
#
# --bin: a built plumetrace (default: builds the release binary of this checkout);
# --jobs: worker threads (default: one per core; the results do not depend on it);
# --reuse: write the page from the results in target/gridworld/ of an earlier call.
set -euo pipefail
cd "$(dirname "$0")/.."

bin=""
jobs=()
reuse=0
while [ $# -gt 0 ]; do
    case "$1" in
        --bin) bin="$2"; shift 2 ;;
        --jobs) jobs=(--jobs "$2"); shift 2 ;;
        --reuse) reuse=1; shift ;;
        -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
        *) echo "gridworld.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
if [ -z "$bin" ] && [ "$reuse" = 0 ]; then
    cargo build --release --bin plumetrace
    bin=target/release/plumetrace
fi

out=target/gridworld
mkdir -p "$out"
# name | arguments
cases=(
    "r25-infotaxis|--episodes 1000 --rate 2.5 --seed 1"
    "r25-space-aware|--episodes 1000 --rate 2.5 --policy space-aware --seed 1"
    "r025-infotaxis|--episodes 5000 --rate 0.25 --seed 3"
)
for c in "${cases[@]}"; do
    name="${c%%|*}"
    args="${c#*|}"
    if [ "$reuse" = 1 ]; then
        [ -f "$out/$name.json" ] || { echo "gridworld.sh: no $out/$name.json to reuse" >&2; exit 1; }
        continue
    fi
    echo "plumetrace bench infotaxis $args" >&2
    # shellcheck disable=SC2086
    "$bin" bench infotaxis $args "${jobs[@]}" > "$out/$name.json"
done

commit="$(git rev-parse --short HEAD)"
if ! git diff --quiet HEAD -- crates; then commit="$commit (with uncommitted changes)"; fi
machine="$(nproc) cores, $(uname -m), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
python3 - "$out" "$commit" "$machine" "${cases[@]}" > docs/results/infotaxis-grid-world.md <<'PY'
import json, sys
out, commit, machine, *cases = sys.argv[1:]
runs = {c.split("|")[0]: (c.split("|")[1], json.load(open(f"{out}/{c.split('|')[0]}.json"))) for c in cases}
# Published with otto-benchmark (Loisy & Heinonen 2023): mean, the printed half-width (1.96
# standard errors), median, failures.
published = {
    "r25-infotaxis": ("R = 2.5, infotaxis", 74.4, 2.0, "52", "0.1 %"),
    "r25-space-aware": ("R = 2.5, space-aware infotaxis", 64.5, 2.2, "49", ""),
    "r025-infotaxis": ("R = 0.25, infotaxis", 266.0, 14.0, "132", "0.1 %"),
}
print("# Infotaxis on the grid world\n")
print(f"Infotaxis in plumetrace against the windy grid-world results published with otto-benchmark (at commit {commit}).\n")
print("""`plumetrace bench infotaxis` runs the move choice of the infotaxis planner (the same code,
`estimate/infotaxis.rs`) on the windy case of otto-benchmark (Loisy & Heinonen 2023, the
benchmark of the olfactory search POMDP; the original OTTO of Loisy & Eloy 2022 has the isotropic
case only): 81 x 41 cells, wind along +x, start (65, 20) after a first hit, `V = 2`, `tau = 150`
(`lambda = 0.987`), binary hits, four moves of one cell, success on stepping onto the source,
failure at 10,000 steps (see
[the planner](../planners.md#probabilistic-planners-the-source-likelihood-map-and-infotaxis)).
Each episode draws its source from the prior and runs from its own seed, so the result does not
depend on the thread count.
""")
print(f"Written by `scripts/gridworld.sh` at commit `{commit}` on {machine}, from:\n")
for name, (args, _) in runs.items():
    print(f"    plumetrace bench infotaxis {args}")
print()
print("""Reading the reference column: otto-benchmark prints its mean with `+-` 1.96 standard errors of
the mean (so the standard error is that half-width over 1.96), and its evaluation files for the
windy cases run 10,000 episodes in its Bayesian setting (each episode runs until the source is
almost surely found, averaging over the searcher's belief rather than drawing one source). The
failures column counts episodes that reach the step limit.
""")
print("| case | plumetrace: mean +- s.e. (episodes) | median | failures | otto-benchmark: mean +- 1.96 s.e. (s.e.), median, failures | difference / combined s.e. |")
print("| --- | --- | --- | --- | --- | --- |")
for name, (args, r) in runs.items():
    label, mean, half, median, fail = published[name]
    se = half / 1.96
    z = (r["mean_steps"] - mean) / (r["standard_error"] ** 2 + se ** 2) ** 0.5
    ref = f"{mean:g} +- {half:g} ({se:.1f}), median {median}" + (f", {fail}" if fail else "")
    print(f"| {label}, seed {r['seed']} | {r['mean_steps']:.1f} +- {r['standard_error']:.1f} ({r['episodes']}) | {r['median_steps']:g} | {100 * r['failure_rate']:.2f} % | {ref} | {z:+.1f} |")
print()
worst = max(abs((r["mean_steps"] - published[n][1]) / (r["standard_error"] ** 2 + (published[n][2] / 1.96) ** 2) ** 0.5) for n, (_, r) in runs.items())
print(f"Every mean lies within {worst:.1f} combined standard errors of the published one. The R = 0.25")
print("distribution has a long tail (its 99th percentile is several times its median), so its mean")
print("moves by more than one standard error between seeds at 1,000 episodes; hence 5,000 here.\n")
cpu = ", ".join(f"{runs[n][1]['cpu_us_per_decision']:.0f} us ({published[n][0]})" for n in runs)
print(f"CPU time per move choice (the process's CPU time over the decisions made): {cpu}.")
PY
echo "wrote docs/results/infotaxis-grid-world.md" >&2
