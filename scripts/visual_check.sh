#!/usr/bin/env bash
# The visual check: every preset's figures and replay page, a replay of the demo's log with another
# planner, and a campaign over every planner, rendered to PNG in headless Chromium and checked by
# measurable properties (no two labels overlap, no label over a marker, every axis's tick labels
# distinct and increasing, the page's timeline rows labelled, its legend keyed by marker, the first
# divergence marked on a replayed page).
#
#   scripts/visual_check.sh [--bin PATH] [--out DIR]   (defaults: builds the release binary;
#                                                       target/visual)
#
# The PNGs of the last run stay in DIR/png (1400 x 1000; the pages also at a phone's 390 x 844).
# Needs Debian's chromium-headless-shell (or a Chromium in PLUMETRACE_BROWSER).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bin=""
out="target/visual"
while [ $# -gt 0 ]; do
    case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "usage: scripts/visual_check.sh [--bin PATH] [--out DIR]" >&2; exit 2 ;;
    esac
done
if [ -z "$bin" ]; then
    cargo build --release --bin plumetrace
    bin="target/release/plumetrace"
fi
if [ ! -x "$bin" ]; then
    echo "visual_check.sh: no plumetrace binary at $bin (build it: cargo build --release --bin plumetrace)" >&2
    exit 1
fi
bin=$(realpath "$bin")
# shellcheck source=scripts/browser.sh
. "$root/scripts/browser.sh"
find_browser visual_check.sh
rm -rf "$out"
mkdir -p "$out/png"
out=$(realpath "$out")
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT

shot() { # FILE PNG WIDTH HEIGHT [FRAGMENT]
    timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
        --user-data-dir="$profile" --virtual-time-budget=5000 \
        --window-size="$3,$4" --screenshot="$2" "file://$1${5:-}" >/dev/null 2>&1
    test -s "$2"
}
state() { # PAGE FRAGMENT -> the page's <body> attributes, as the browser left them
    timeout 120 "$browser" --headless --no-sandbox --disable-gpu --user-data-dir="$profile" \
        --virtual-time-budget=5000 --dump-dom "file://$1$2" 2>/dev/null | grep -o '<body[^>]*>' | head -1
}
page() { # NAME PAGE: screenshots mid-mission and at the end, wide and narrow; the state at the end
    local name="$1" html="$2"
    shot "$html" "$out/png/$name-page-mid.png" 1400 1000 "#t=600&paused"
    shot "$html" "$out/png/$name-page-end.png" 1400 1000 "#t=1e9&paused"
    shot "$html" "$out/png/$name-page-phone.png" 390 844 "#t=1e9&paused"
    state "$html" "#t=1e9&paused" >"$out/$name.state.txt"
    grep -q 'data-loaded="1"' "$out/$name.state.txt"
}

missions=(demo demo-survey demo-infotaxis demo-surge-cast duck-2003-st duck-2003-mt li-zhang-open li-zhang-kelp
    soares-freshwater soares-filaments)
plumes=(plume-demo pompy freshwater)
for p in "${missions[@]}" "${plumes[@]}"; do
    echo "== $p"
    "$bin" run --preset "$p" --out "$out/$p" >/dev/null
    for f in plot team plume; do
        if [ -f "$out/$p/$f.svg" ]; then shot "$out/$p/$f.svg" "$out/png/$p-$f.png" 1400 1000; fi
    done
    if [ -f "$out/$p/replay.html" ]; then page "$p" "$out/$p/replay.html"; fi
done

echo "== the demo's log replayed with the lawnmower"
printf 'kind = "lawnmower"\n' >"$out/lawnmower.toml"
"$bin" replay "$out/demo/snapshots.jsonl.gz" --planner-file "$out/lawnmower.toml" \
    --page "$out/demo-replayed-lawnmower.html" >/dev/null || test $? -eq 3
page demo-replayed-lawnmower "$out/demo-replayed-lawnmower.html"
grep -q 'data-replayed="true"' "$out/demo-replayed-lawnmower.state.txt"
grep -q 'data-divergence="' "$out/demo-replayed-lawnmower.state.txt"

echo "== a campaign over every planner"
# Every planner of `plumetrace planners`: one config each (and the AMP declaring from its source
# map) over the demo for those the demo's one vehicle can fly; the others (a team's) as the presets
# that fly them have them, over those presets.
planners=$("$bin" planners | sed -n 's/^\([a-z_][a-z_0-9]*\): .*/\1/p')
if [ -z "$planners" ]; then
    echo "visual_check.sh: \`plumetrace planners\` listed no planner" >&2
    exit 1
fi
config() { # NAME KIND [KEY = VALUE]
    printf '[[configs]]\nname = "%s"\n[configs.planner]\nkind = "%s"\n%s' "$1" "$2" "${3:+$3
}"
}
single="" teams=""
for k in $planners; do
    if "$bin" check --preset demo --planner "$k" >/dev/null 2>&1; then
        single="$single$(config "$k" "$k")"$'\n'
        if [ "$k" = amp ]; then
            single="$single$(config amp-map amp 'map_declaration = "instead"')"$'\n'
        fi
        continue
    fi
    found=""
    for p in "${missions[@]}"; do
        if "$bin" presets --show "$p" | grep -q "^kind = \"$k\""; then
            found=1
            case " $teams " in *" \"$p\" "*) ;; *) teams="$teams \"$p\"" ;; esac
        fi
    done
    if [ -z "$found" ]; then
        echo "visual_check.sh: no preset flies the planner $k (and the demo cannot): add one" >&2
        exit 1
    fi
done
printf 'name = "visual"\nseed = 5\nseeds = 3\nscenarios = ["demo"]\n%s' "$single" >"$out/campaign.toml"
"$bin" campaign "$out/campaign.toml" --out "$out/campaign" --jobs 2 >/dev/null
printf 'name = "visual-team"\nseed = 5\nseeds = 2\nscenarios = [%s]\n[[configs]]\nname = "team"\n' \
    "$(echo $teams | sed 's/" "/", "/g')" >"$out/team-campaign.toml"
"$bin" campaign "$out/team-campaign.toml" --out "$out/team-campaign" --jobs 2 >/dev/null
for c in campaign team-campaign; do
    for f in success errors trajectories; do
        shot "$out/$c/$f.svg" "$out/png/$c-$f.png" 1400 1000
    done
done

echo "== the properties"
# The whole workspace selected, as `.ci/run` builds its release tests, so the two share one build.
PLUMETRACE_VISUAL_DIR="$out" cargo test --release -q --workspace --test visual -- --ignored
echo "visual check: $(ls "$out/png" | wc -l) pictures in $out/png, every property holds"
