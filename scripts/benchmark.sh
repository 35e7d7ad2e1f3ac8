#!/usr/bin/env bash
# Regenerates the benchmark's leaderboard in the guide, docs/results/benchmark.md: every task of
# the shipped task set (benchmarks/tasks-v1.toml) flown on its test seeds by every planner that
# enters it (each at its defaults; the team task by the formation), written whole from the
# command's own leaderboard.md with the commit, the command, the machine and the time it took.
#
#   scripts/benchmark.sh                  the whole benchmark (each task's default test seeds)
#   scripts/benchmark.sh --smoke          2 test seeds per task, into target/benchmark-smoke; checks
#                                         the leaderboard and does not touch the guide (for CI)
#
# Options: --jobs N (worker threads, default: one per core), --bin PATH (a built plumetrace,
# default: builds the release binary of this checkout), --seeds-per-task N, --keep (resume into
# target/benchmark instead of starting afresh), --ppo FILE (the learned baseline, added unranked
# to the coastal table: a trained policy, ppo_coastal.zip from scripts/ppo_baseline.sh, flown
# here on the task's test seeds by `scripts/ppo_baseline.sh --evaluate FILE` into target/ppo-eval;
# or the row such a call wrote, its ppo.md beside its ppo.json).
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=""
bin=""
keep=0
smoke=0
seeds=""
ppo=""
while [ $# -gt 0 ]; do
    case "$1" in
        --jobs) jobs="$2"; shift 2 ;;
        --bin) bin="$2"; shift 2 ;;
        --seeds-per-task) seeds="$2"; shift 2 ;;
        --keep) keep=1; shift ;;
        --smoke) smoke=1; shift ;;
        --ppo) ppo="$2"; shift 2 ;;
        -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
        *) echo "benchmark.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done

case "$ppo" in
    ""|*.md|*.zip) ;;
    *) echo "benchmark.sh: --ppo $ppo: give the policy (.zip) or its row (ppo.md)" >&2; exit 2 ;;
esac
if [ -n "$ppo" ] && [ ! -f "$ppo" ]; then
    echo "benchmark.sh: --ppo $ppo: no such file" >&2
    exit 2
fi

if [ -z "$bin" ]; then
    cargo build --release --bin plumetrace
    bin="target/release/plumetrace"
fi

out="target/benchmark"
if [ "$smoke" -eq 1 ]; then
    out="target/benchmark-smoke"
    seeds="${seeds:-2}"
fi
if [ "$keep" -eq 0 ]; then rm -rf "$out"; fi
mkdir -p "$(dirname "$out")"

cmd=("$bin" benchmark --out "$out")
shown="plumetrace benchmark --out $out"
if [ -n "$seeds" ]; then cmd+=(--seeds-per-task "$seeds"); shown="$shown --seeds-per-task $seeds"; fi
if [ -n "$jobs" ]; then cmd+=(--jobs "$jobs"); shown="$shown --jobs $jobs"; fi
echo "== ${cmd[*]}" >&2
log="$out.log"
# CPU time (user + system) of the script's finished children, s, from bash's `times`.
# (`times` runs in this shell, not in a pipe's subshell, which has no finished children.)
times_file="$(mktemp)"
trap 'rm -f "$times_file"' EXIT
children_cpu() {
    tail -1 "$times_file" | awk '{ split($1, u, "m"); split($2, s, "m"); sub("s", "", u[2]); sub("s", "", s[2]); print u[1] * 60 + u[2] + s[1] * 60 + s[2] }'
}
times > "$times_file"
cpu0=$(children_cpu)
start=$(date +%s.%N)
"${cmd[@]}" 2>&1 | tee "$log" >&2
wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
times > "$times_file"
cpu=$(awk -v a="$cpu0" -v b="$(children_cpu)" 'BEGIN { print b - a }')

board="$out/leaderboard.md"
version="$(sed -n 's/^version *= *"\(.*\)"$/\1/p' benchmarks/tasks-v1.toml)"
for t in $(sed -n 's/^name *= *"\(.*\)"$/\1/p' benchmarks/tasks-v1.toml); do
    if ! grep -q "^## \`$t\`" "$board"; then
        echo "benchmark.sh: $board has no section for task $t" >&2
        exit 1
    fi
done
if ! head -1 "$board" | grep -q "task set $version"; then
    echo "benchmark.sh: $board does not name task set $version" >&2
    exit 1
fi
if [ "$smoke" -eq 1 ]; then
    printf 'benchmark smoke: %s tasks, task set %s, %.0f s wall, %.0f s CPU; %s\n' \
        "$(grep -c '^## ' "$board")" "$version" "$wall" "$cpu" "$board" >&2
    exit 0
fi

commit="$(git rev-parse --short=12 HEAD)"
if ! git diff --quiet HEAD -- crates examples benchmarks Cargo.toml Cargo.lock; then
    commit="$commit (with uncommitted changes to the code)"
fi
cores="$(nproc)"
cpu_model="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"
page="docs/results/benchmark.md"
images="docs/images/benchmark"
rm -rf "$images"
mkdir -p "$images"
{
    echo "# Results: \`benchmark\`"
    echo
    echo "The benchmark's leaderboard, task set $version: every planner at its defaults on every task's test seeds."
    echo
    echo "Produced at commit \`$commit\` on $(date -u +%Y-%m-%d) by \`scripts/benchmark.sh\`,"
    printf 'which ran (release build, %s cores, %s; %.0f s of wall time, %.0f s of CPU time):\n' \
        "$cores" "$cpu_model" "$wall" "$cpu"
    echo
    echo "    $shown"
    echo
    echo "The tasks are [\`benchmarks/tasks-v1.toml\`](../../benchmarks/tasks-v1.toml), described in"
    echo "[the benchmark](../benchmark.md). Everything below is the command's own \`leaderboard.md\`,"
    echo "copied whole (its success charts copied to \`docs/images/benchmark/\`; the error charts are in"
    echo "each task's directory); run the script again to"
    echo "regenerate it."
    echo
    # The leaderboard's title becomes a section; its task headings move down one level; its charts
    # point at the copies.
    sed -e '1s/^# /## /' -e '2,$s/^## /### /' \
        -e 's# !\[errors of each planner on `[a-z0-9_-]*`\]([a-z0-9_-]*/errors\.svg)##' \
        -e 's#](\([a-z0-9_-]*\)/success\.svg)#](../images/benchmark/\1-success.svg)#g' "$board"
    echo
    echo "Time per task (this call):"
    echo
    sed -n 's/^\([a-z0-9_-]*\): \([0-9]*\) planners x \([0-9]*\) test seeds: \([0-9]*\) runs.* in \([0-9.]*\) s$/- `\1`: \2 planners x \3 test seeds, \4 runs, \5 s/p' "$log"
} > "$page.tmp"
ppo_given="$(basename "$ppo")"
if [ "${ppo%.zip}" != "$ppo" ]; then
    # The policy flies the coastal task's test seeds (as many as the table's) through Python.
    ppo_seeds="$(sed -n 's/^- `coastal`: [0-9]* planners x \([0-9]*\) test seeds.*/\1/p' "$page.tmp")"
    policy="$(cd "$(dirname "$ppo")" && pwd)/$(basename "$ppo")"
    echo "== scripts/ppo_baseline.sh --evaluate $policy --test-seeds $ppo_seeds" >&2
    bash scripts/ppo_baseline.sh --evaluate "$policy" --test-seeds "$ppo_seeds" \
        --out target/ppo-eval >&2
    ppo="target/ppo-eval/ppo.md"
fi
if [ -n "$ppo" ]; then
    # The learned baseline flew apart (through Python): its row joins the coastal table unranked.
    ppo_json="$(dirname "$ppo")/ppo.json"
    steps="$(sed -n 's/^ *"timesteps": \([0-9]*\),$/\1/p' "$ppo_json")"
    note="\`ppo\` (unranked): the learned baseline, PPO trained for $steps environment steps on the task's tuning seeds by \`scripts/ppo_baseline.sh\` and flown on the same test seeds by \`plumetrace.benchmark\` through the Python planner seam (\`scripts/benchmark.sh --ppo $ppo_given\`; [the benchmark](../benchmark.md#a-learned-baseline-ppo))."
    awk -v row="$(cat "$ppo")" -v note="$note" '
        /^### `coastal`/ { c = 1 }
        /^### / && !/`coastal`/ { c = 0 }
        {
            if (c && intable && $0 !~ /^\|/) { print row; print ""; print note; intable = 0 }
            if (c && $0 ~ /^\| [0-9]+ \|/) intable = 1
            print
        }' "$page.tmp" > "$page.ppo"
    mv "$page.ppo" "$page.tmp"
fi
for d in "$out"/*/; do
    t="$(basename "$d")"
    [ "$t" = "tasks" ] && continue
    if [ -f "$d/success.svg" ]; then cp "$d/success.svg" "$images/$t-success.svg"; fi
done
mv "$page.tmp" "$page"
bash scripts/results.sh --index
echo "wrote $page" >&2
