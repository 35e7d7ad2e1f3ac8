#!/usr/bin/env bash
# Regenerates the measured results under docs/results/: one page per campaign of
# examples/campaigns/, written whole from the campaign's own summary (never edit a number by hand).
#
#   scripts/results.sh NAME...          run examples/campaigns/NAME.toml (or, for a campaign that flies
#                                       test seeds, benchmarks/campaigns/NAME.toml) and write
#                                       docs/results/NAME.md
#   scripts/results.sh --all            every campaign with a page under docs/results/
#   scripts/results.sh --index          rewrite docs/results/README.md (the index) only
#
# Options: --jobs N (worker threads, default: one per core), --bin PATH (a built plumetrace,
# default: builds the release binary of this checkout), --keep (resume into target/results/NAME
# instead of starting afresh; the page then says how many runs this call flew), --test-seeds
# (passed to `plumetrace campaign`: a campaign that flies a benchmark task's test seeds). Each
# page names the commit, the command, the machine and the time.
#
# Two-sample comparisons: every line `# two-sample: A B` of the campaign file appends to its page
# the comparison of configurations A and B over the campaign's runs.csv, per scenario
# (scripts/two_sample.sh: Fisher's exact test for the rates, Kolmogorov-Smirnov and Mann-Whitney U
# for the errors and times; it makes a virtual environment with scipy on first use).
# Lines `# beside the benchmark: TEXT` of a campaign file (joined) say, under the page's
# description, what it measures that the benchmark's leaderboard (docs/results/benchmark.md)
# does not, where the two report the same planners.
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=""
bin=""
keep=0
test_seeds=0
names=()
while [ $# -gt 0 ]; do
    case "$1" in
        --jobs) jobs="$2"; shift 2 ;;
        --bin) bin="$2"; shift 2 ;;
        --keep) keep=1; shift ;;
        --test-seeds) test_seeds=1; shift ;;
        --all)
            for page in docs/results/*.md; do
                n="$(basename "$page" .md)"
                if [ -f "examples/campaigns/$n.toml" ]; then names+=("$n"); fi
            done
            shift ;;
        --index) shift ;;
        -h|--help) sed -n '2,21p' "$0"; exit 0 ;;
        -*) echo "results.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
        *) names+=("$1"); shift ;;
    esac
done

# The campaign file of NAME: an example campaign, else one beside the benchmark's task set.
campaign_file() {
    if [ -f "examples/campaigns/$1.toml" ]; then echo "examples/campaigns/$1.toml"; else echo "benchmarks/campaigns/$1.toml"; fi
}

for n in "${names[@]}"; do
    if [ ! -f "$(campaign_file "$n")" ]; then
        echo "results.sh: no campaign examples/campaigns/$n.toml; the campaigns are:" >&2
        ls examples/campaigns/ | sed 's/\.toml$//; s/^/  /' >&2
        exit 2
    fi
done

if [ -z "$bin" ] && [ "${#names[@]}" -gt 0 ]; then
    cargo build --release --bin plumetrace
    bin="target/release/plumetrace"
fi

commit="$(git rev-parse --short=12 HEAD)"
if ! git diff --quiet HEAD -- crates examples Cargo.toml Cargo.lock; then
    commit="$commit (with uncommitted changes to the code)"
fi
cores="$(nproc)"
cpu="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)"

# The `# two-sample: A B` lines of campaign file $1, one "LINE A B" per line.
two_sample_pairs() {
    awk '/^# two-sample:/ { if (NF == 4) print NR, $3, $4; else print NR, "-", "-" }' "$1"
}

# Refuses a two-sample line naming a configuration the campaign file $1 does not have (before
# anything runs: a typo would otherwise show only after the whole campaign).
check_two_sample() {
    local file="$1" line a b c configs
    configs="$(sed -n 's/^name *= *"\(.*\)"$/\1/p' "$file" | tail -n +2 | tr '\n' ' ')"
    while read -r line a b; do
        [ -n "$line" ] || continue
        if [ "$a" = "-" ]; then
            echo "results.sh: $file:$line: a two-sample line names two configurations: # two-sample: A B" >&2
            exit 2
        fi
        for c in "$a" "$b"; do
            if ! grep -qx "name *= *\"$c\"" "$file"; then
                echo "results.sh: $file:$line: two-sample names configuration '$c', which the campaign does not have (its configurations: ${configs% })" >&2
                exit 2
            fi
        done
    done <<< "$(two_sample_pairs "$file")"
}

# Appends a section per `# two-sample: A B` line of the campaign file $1, over its runs.csv $2.
two_sample() {
    local file="$1" runs="$2" line a b table
    while read -r line a b; do
        [ -n "$line" ] || continue
        table="$(bash scripts/two_sample.sh "$runs" "$a" "$b" </dev/null)" || true
        if ! grep -q '^smallest p-value' <<< "$table" || ! grep -q "^| [^|]* | declared |" <<< "$table"; then
            echo "results.sh: bash scripts/two_sample.sh $runs $a $b gave no comparison (see its errors above)" >&2
            exit 2
        fi
        echo
        echo "### Two-sample comparison: \`$a\` against \`$b\`"
        echo
        echo "The same seeds in both configurations; per scenario, Fisher's exact test for the rates and"
        echo "the two-sample Kolmogorov-Smirnov and Mann-Whitney U tests for the rest (runs without a"
        echo "value left out), by \`bash scripts/two_sample.sh $runs $a $b\`:"
        echo
        echo "$table"
    done <<< "$(two_sample_pairs "$file")"
}

for n in "${names[@]}"; do
    check_two_sample "$(campaign_file "$n")"
done

for n in "${names[@]}"; do
    file="$(campaign_file "$n")"
    out="target/results/$n"
    mkdir -p target/results
    if [ "$keep" -eq 0 ]; then rm -rf "$out"; fi
    cmd=("$bin" campaign "$file" --out "$out")
    if [ -n "$jobs" ]; then cmd+=(--jobs "$jobs"); fi
    if [ "$test_seeds" -eq 1 ]; then cmd+=(--test-seeds); fi
    echo "== $n: ${cmd[*]}" >&2
    start=$(date +%s)
    "${cmd[@]}" 2>&1 | tee "$out.log" >&2
    secs=$(( $(date +%s) - start ))
    # The campaign's own count line: "NAME: P runs planned, R already recorded, F run now ...".
    resumed="$(sed -n 's/^.*: \([0-9]*\) runs planned, \([1-9][0-9]*\) already recorded, \([0-9]*\) run now.*$/; \3 of its \1 runs flown in this call, \2 resumed from an earlier one/p' "$out.log" | tail -1)"
    desc="$(sed -n 's/^description *= *"\(.*\)"$/\1/p' "$file" | head -1)"
    shown="plumetrace campaign $file --out $out"
    if [ -n "$jobs" ]; then shown="$shown --jobs $jobs"; fi
    if [ "$test_seeds" -eq 1 ]; then shown="$shown --test-seeds"; fi
    page="docs/results/$n.md"
    {
        echo "# Results: \`$n\`"
        echo
        if [ -n "$desc" ]; then echo "${desc^}."; echo; fi
        beside="$(sed -n 's/^# beside the benchmark: //p' "$file" | paste -sd ' ' -)"
        if [ -n "$beside" ]; then echo "**Beside the benchmark.** $beside"; echo; fi
        echo "Produced at commit \`$commit\` on $(date -u +%Y-%m-%d) by \`scripts/results.sh $n\`,"
        echo "which ran (release build, $cores cores, $cpu; ${secs} s of wall time$resumed):"
        echo
        echo "    $shown"
        echo
        echo "The campaign file is [\`$file\`](../../$file). Everything below is the campaign's own"
        echo "\`summary.md\`, copied whole; run the script again to regenerate it."
        echo
        # The summary's own title becomes a section; its other headings move down one level.
        sed -e '1s/^# /## /' -e '2,$s/^## /### /' "$out/summary.md"
        two_sample "$file" "$out/runs.csv"
    } > "$page.tmp"
    mv "$page.tmp" "$page"
    echo "wrote $page" >&2
done

# The index: every results page with its first line of description.
{
    echo "# Results"
    echo
    echo "A campaign's page is written whole by \`scripts/results.sh NAME\` (\`--all\` for every one),"
    echo "from a campaign anyone can run again; each names the commit, the command and the machine"
    echo "that produced it. \`scripts/gridworld.sh\` writes the grid-world page the same way, and"
    echo "\`scripts/formation_acceptance.sh\` and \`scripts/formation_comparison.sh\` the formation"
    echo "acceptance and comparison pages. The other pages are records of measurements no script"
    echo "regenerates (timings, and campaigns flown at older code to choose a default), each table with"
    echo "its commit and command."
    echo
    echo "| page | what it measures |"
    echo "| --- | --- |"
    for page in docs/results/*.md; do
        n="$(basename "$page" .md)"
        [ "$n" = "README" ] && continue
        what="$(sed -n '3p' "$page")"
        echo "| [$n]($n.md) | $what |"
    done
} > docs/results/README.md.tmp
mv docs/results/README.md.tmp docs/results/README.md
