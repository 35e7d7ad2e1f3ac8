#!/usr/bin/env bash
# Renders the README's picture, docs/images/demo.png: the demo mission's figure (plot.svg of
# `plumetrace run --preset demo`, its own seed) drawn by headless Chromium at its own size.
#
# Usage: scripts/readme_picture.sh [--bin PATH]   (default: builds the release binary)
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
find_browser readme_picture.sh
out="target/readme-picture"
rm -rf "$out"
"$bin" run --preset demo --out "$out" --no-snapshot-log >/dev/null
svg="$out/plot.svg"
# The figure's size from its root element.
w=$(sed -n 's/.*<svg[^>]* width="\([0-9.]*\)".*/\1/p' "$svg" | head -1)
h=$(sed -n 's/.*<svg[^>]* height="\([0-9.]*\)".*/\1/p' "$svg" | head -1)
w=${w%.*}
h=${h%.*}
mkdir -p docs/images
"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --window-size="${w},${h}" --screenshot="$root/docs/images/demo.png" "file://$root/$svg" \
    >/dev/null 2>&1
echo "wrote docs/images/demo.png (${w} x ${h})"
