#!/usr/bin/env bash
# Measures what a fresh release build costs at two commits, side by side, and prints the table of
# docs/results/performance.md's "Set-up: building" sections (paste it whole; never edit its
# numbers by hand):
#
#   scripts/build_pairs.sh --before COMMIT [--after COMMIT] [--pairs N] [--what binary|python|both]
#
# Each commit is checked out in a worktree of its own (under a temporary directory, removed at the
# end), and the two are built alternately (before, after, before, after, ...; `--pairs` pairs,
# default 3), each build in an empty target directory, timed by `/usr/bin/time -f '%U %S %e'`:
# - `binary`: `cargo build --release --bin plumetrace` (the README's first command's build);
# - `python`: `cargo build --release --manifest-path crates/plumetrace-py/Cargo.toml` (the build
#   `pip install` runs).
# `--after` defaults to HEAD; `--what` to both. Run it on an otherwise idle machine: the two
# commits share the machine's state of the moment only if nothing else is running. Every crate
# must already be in cargo's download cache (run a build of each commit once first, or
# `cargo fetch` in a checkout of each), so that no download is timed.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/pairs_common.sh

before=""
after="HEAD"
pairs=3
what=both
while [ $# -gt 0 ]; do
    case "$1" in
        --before|--after|--pairs|--what) needs_value build_pairs.sh "$1" $# ;;
    esac
    case "$1" in
        --before) before="$2"; shift 2 ;;
        --after) after="$2"; shift 2 ;;
        --pairs) pairs="$2"; shift 2 ;;
        --what) what="$2"; shift 2 ;;
        -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
        *) echo "build_pairs.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
if [ -z "$before" ]; then
    echo "build_pairs.sh: --before COMMIT is needed: the commit to compare against (see --help)" >&2
    exit 2
fi
whole_count build_pairs.sh --pairs "$pairs"
case "$what" in
    binary) kinds=(binary) ;;
    python) kinds=(python) ;;
    both) kinds=(binary python) ;;
    *) echo "build_pairs.sh: --what is binary, python or both, not '$what'" >&2; exit 2 ;;
esac
b=$(git rev-parse --short "$before^{commit}") || {
    echo "build_pairs.sh: --before: no commit '$before' here" >&2
    exit 2
}
a=$(git rev-parse --short "$after^{commit}") || {
    echo "build_pairs.sh: --after: no commit '$after' here" >&2
    exit 2
}

work=$(mktemp -d)
cleanup() {
    git worktree remove --force "$work/before" 2>/dev/null || true
    git worktree remove --force "$work/after" 2>/dev/null || true
    rm -rf "$work"
    git worktree prune
}
trap cleanup EXIT
git worktree add --detach --quiet "$work/before" "$b"
git worktree add --detach --quiet "$work/after" "$a"

# One fresh build of `$2` in worktree `$1`: prints "user system wall".
build() {
    local tree="$1" kind="$2" target="$work/target"
    rm -rf "$target"
    # `--locked`: each commit builds what its lockfile names.
    local args=(build --locked --release --bin plumetrace)
    if [ "$kind" = python ]; then
        args=(build --locked --release --manifest-path crates/plumetrace-py/Cargo.toml)
    fi
    (cd "$tree" && CARGO_TARGET_DIR="$target" /usr/bin/time -o "$work/time" -f '%U %S %e' \
        cargo "${args[@]}" >"$work/log" 2>&1) || {
        echo "build_pairs.sh: the $kind build in $tree failed:" >&2
        tail -20 "$work/log" >&2
        exit 1
    }
    rm -rf "$target"
    tail -1 "$work/time"
}

echo "Fresh release builds on $(nproc) cores ($(uname -m)), \`$b\` (before) against \`$a\` (after),"
echo "alternately, each in an empty target directory; $(date -u +%Y-%m-%d):"
echo
echo "| build | pair | before: CPU (user + system), wall | after: CPU, wall | CPU after / before |"
echo "| --- | --- | --- | --- | --- |"
for kind in "${kinds[@]}"; do
    ratios=()
    label="the binary"
    [ "$kind" = python ] && label="the Python extension"
    for k in $(seq 1 "$pairs"); do
        t=$(build "$work/before" "$kind")
        read -r bu bs bw <<<"$t"
        t=$(build "$work/after" "$kind")
        read -r au as aw <<<"$t"
        r=$(awk -v bu="$bu" -v bs="$bs" -v au="$au" -v as="$as" \
            'BEGIN { printf "%.3f", (au + as) / (bu + bs) }')
        ratios+=("$r")
        awk -v l="$label" -v k="$k" -v bu="$bu" -v bs="$bs" -v bw="$bw" -v au="$au" -v as="$as" \
            -v aw="$aw" -v r="$r" 'BEGIN {
                printf "| %s | %d | %.1f s (%.1f + %.1f), %.0f s | %.1f s (%.1f + %.1f), %.0f s | %s |\n",
                    (k == 1 ? l : ""), k, bu + bs, bu, bs, bw, au + as, au, as, aw, r }'
    done
    read -r median range <<<"$(median_range "${ratios[@]}")"
    echo "| $label: median | | | | **$median** $range |"
done
