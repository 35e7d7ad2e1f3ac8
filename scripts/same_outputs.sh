#!/usr/bin/env bash
# Writes every output a fixed-seed set of runs produces, to show that a change of structure changed
# no behaviour: every mission and plume preset at seed 7 (with `--alog`), a replay page of the demo's
# snapshot log, a small campaign over every planner and the coastal family, and family sites.
#
#   scripts/same_outputs.sh write DIR [BIN]   # outputs into DIR (BIN: target/release/plumetrace)
#   scripts/same_outputs.sh compare A B       # exit 1 when any file differs
#
# Run `write` on the commit before a change and on the commit after it, then `compare`. Wall times
# (summary.json's wall_s, real_time_factor, spinup_wall_s and stage times; campaign run times) and
# the `.alog` header's file path and opening time are left out of the comparison; every other byte
# counts.
set -euo pipefail
# paths given relative to where the script is called from
args=()
for a in "$@"; do
    case "$a" in write|compare) args+=("$a") ;; *) args+=("$(realpath -m "$a")") ;; esac
done
set -- "${args[@]}"
cd "$(dirname "$0")/.."

presets=(demo demo-survey demo-infotaxis demo-surge-cast duck-2003-st duck-2003-mt li-zhang-open li-zhang-kelp
    soares-freshwater soares-filaments plume-demo pompy freshwater)

write() {
    local out="$1" bin="${2:-target/release/plumetrace}"
    rm -rf "$out"
    mkdir -p "$out"
    for p in "${presets[@]}"; do
        "$bin" run --preset "$p" --seed 7 --out "$out/$p" --alog >"$out/$p.txt"
    done
    "$bin" replay "$out/demo/snapshots.jsonl.gz" --page "$out/demo-replayed.html" >"$out/demo-replay.txt"
    cat >"$out/campaign.toml" <<'TOML'
name = "same-outputs"
seed = 11
seeds = 2
success_radius_m = 10.0
scenarios = ["demo", "coastal.family.toml"]
[[configs]]
name = "amp"
[configs.set]
mapping = false
[[configs]]
name = "amp-map"
[configs.planner]
kind = "amp"
mapping = false
map_declaration = "instead"
[[configs]]
name = "infotaxis"
[configs.planner]
kind = "infotaxis"
[[configs]]
name = "moth"
[configs.planner]
kind = "moth"
[[configs]]
name = "lawnmower"
[configs.planner]
kind = "lawnmower"
[[configs]]
name = "surge_cast"
[configs.planner]
kind = "surge_cast"
TOML
    # the family sits next to the campaign file, so the outputs do not depend on the checkout's path
    cp examples/families/coastal.family.toml "$out/coastal.family.toml"
    "$bin" campaign "$out/campaign.toml" --out "$out/campaign" --jobs 2 >/dev/null 2>&1
    cat >"$out/team-campaign.toml" <<'TOML'
name = "same-outputs-team"
seed = 12
seeds = 2
scenarios = ["soares-freshwater", "soares-filaments"]
[[configs]]
name = "formation"
TOML
    "$bin" campaign "$out/team-campaign.toml" --out "$out/team-campaign" --jobs 2 >/dev/null 2>&1
    "$bin" family examples/families/faults.family.toml --sample 3 --out "$out/family" >/dev/null
}

compare() {
    python3 - "$1" "$2" <<'PY'
import gzip, json, os, re, sys

a_root, b_root = sys.argv[1], sys.argv[2]
WALL = {"real_time_factor", "stage_times"}


def strip(value):
    if isinstance(value, dict):
        return {k: strip(v) for k, v in value.items() if k not in WALL and "wall" not in k}
    if isinstance(value, list):
        return [strip(v) for v in value]
    return value


def normal(path, data):
    name = os.path.basename(path)
    if name == "summary.json" or name == "stats.json":
        return json.dumps(strip(json.loads(data)), sort_keys=True).encode()
    if name.endswith(".alog"):
        # the file path and the opening time (the wall clock, as pLogger's) are left out
        skip = (b"%% LOG FILE", b"%% FILE OPENED ON", b"%% LOGSTART")
        return b"\n".join(l for l in data.split(b"\n") if not l.startswith(skip))
    if name == "runs.csv":
        lines = data.decode().split("\n")
        head = lines[0].split(",")
        drop = [i for i, h in enumerate(head) if "wall" in h or h == "cpu_s"]
        return "\n".join(",".join(c for i, c in enumerate(l.split(",")) if i not in drop)
                         for l in lines).encode()
    if name.endswith(".txt"):
        # printed summaries: the wall time and speed-up figures masked
        text = data.decode()
        text = re.sub(r"[0-9.]+ s of wall time", "W s of wall time", text)
        text = re.sub(r"in [0-9.]+ s \([0-9]+x real time\)", "in W", text)
        return text.encode()
    return data


differ = 0
files = 0
for root, _, names in os.walk(a_root):
    for n in sorted(names):
        pa = os.path.join(root, n)
        rel = os.path.relpath(pa, a_root)
        pb = os.path.join(b_root, rel)
        files += 1
        if not os.path.exists(pb):
            print(f"only in {a_root}: {rel}")
            differ += 1
            continue
        da, db = open(pa, "rb").read(), open(pb, "rb").read()
        if n.endswith(".gz"):
            da, db = gzip.decompress(da), gzip.decompress(db)
        # paths under the output directory are written into some files
        da = da.replace(os.path.abspath(a_root).encode(), b"ROOT").replace(a_root.encode(), b"ROOT")
        db = db.replace(os.path.abspath(b_root).encode(), b"ROOT").replace(b_root.encode(), b"ROOT")
        if normal(pa, da) != normal(pb, db):
            print(f"differs: {rel}")
            differ += 1
for root, _, names in os.walk(b_root):
    for n in names:
        rel = os.path.relpath(os.path.join(root, n), b_root)
        if not os.path.exists(os.path.join(a_root, rel)):
            print(f"only in {b_root}: {rel}")
            differ += 1
if files == 0:
    print(f"no files in {a_root}")
    sys.exit(1)
print(f"{files} files compared, {differ} differ")
sys.exit(1 if differ else 0)
PY
}

case "${1:-}" in
write) shift; write "$@" ;;
compare) shift; compare "$@" ;;
*) echo "usage: scripts/same_outputs.sh write DIR [BIN] | compare A B" >&2; exit 2 ;;
esac
