#!/usr/bin/env bash
# Renders the guide's pictures (docs/figures.md): one mission figure per planner, each from the
# preset that flies it at the preset's own seed, and the demo's replay page mid-mission, drawn by
# headless Chromium into docs/images/. Run it after a change to the figures, so that the pictures
# never go stale.
#
# Usage: scripts/figure_pictures.sh [--bin PATH]   (default: builds the release binary)
# Needs Debian's chromium-headless-shell (or a Chromium in PLUMETRACE_BROWSER).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bin=""
if [ "${1:-}" = "--bin" ]; then bin="$2"; fi
if [ -z "$bin" ]; then
    cargo build --release --bin plumetrace
    bin="target/release/plumetrace"
fi
# shellcheck source=scripts/browser.sh
. "$root/scripts/browser.sh"
find_browser figure_pictures.sh
out="target/figure-pictures"
rm -rf "$out"
mkdir -p "$out" docs/images
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
shot() { # FILE PNG WIDTH HEIGHT [FRAGMENT]
    timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
        --user-data-dir="$profile" --virtual-time-budget=5000 \
        --window-size="$3,$4" --screenshot="$root/$2" "file://$root/$1${5:-}" >/dev/null 2>&1
    test -s "$2"
    echo "wrote $2 ($3 x $4)"
}
# planner: the preset that flies it
for pair in amp:demo moth:li-zhang-open infotaxis:demo-infotaxis lawnmower:demo-survey \
    surge_cast:demo-surge-cast formation:soares-freshwater; do
    planner=${pair%%:*}
    preset=${pair#*:}
    "$bin" run --preset "$preset" --out "$out/$preset" --no-snapshot-log >/dev/null
    svg="$out/$preset/plot.svg"
    w=$(sed -n 's/.*<svg[^>]* width="\([0-9.]*\)".*/\1/p' "$svg" | head -1)
    h=$(sed -n 's/.*<svg[^>]* height="\([0-9.]*\)".*/\1/p' "$svg" | head -1)
    shot "$svg" "docs/images/figure-$planner.png" "${w%.*}" "${h%.*}"
done
shot "$out/demo/replay.html" docs/images/page.png 1400 1000 "#t=600&paused"
