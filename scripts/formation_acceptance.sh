#!/usr/bin/env bash
# Writes docs/results/formation-acceptance.md: the formation family's and soares-freshwater's
# acceptance counts on the test seed (from the runs.csv of `scripts/results.sh formation-family`,
# run first unless target/results/formation-family/runs.csv exists), and the declaration's
# confidence against its error on the family's 200 test sites (each written by `plumetrace family`
# and flown by `plumetrace run` with RTK leaders, as the campaign's `confirmed` configuration).
#
# Usage: scripts/formation_acceptance.sh [--bin PATH] [--jobs N]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=""
jobs=$(nproc)
while [ $# -gt 0 ]; do
    case "$1" in
        --bin) bin="$2"; shift 2 ;;
        --jobs) jobs="$2"; shift 2 ;;
        *) echo "formation_acceptance.sh: unknown argument '$1' (expected --bin PATH or --jobs N)" >&2; exit 2 ;;
    esac
done
if [ -z "$bin" ]; then
    cargo build --release --quiet --bin plumetrace
    bin=target/release/plumetrace
fi
runs=target/results/formation-family/runs.csv
if [ ! -s "$runs" ]; then
    bash scripts/results.sh formation-family --bin "$bin" --jobs "$jobs"
fi
work=target/results/formation-acceptance
rm -rf "$work"
mkdir -p "$work"
"$bin" family examples/families/formation.family.toml --sample 200 --seed 3102 --out "$work/sites" >/dev/null
rtk="--set vehicles.1.nav.fix_sigma_m=0.02 --set vehicles.1.nav.fix_interval_s=0.2 --set vehicles.2.nav.fix_sigma_m=0.02 --set vehicles.2.nav.fix_interval_s=0.2"
# shellcheck disable=SC2086 # the sets are words
ls "$work"/sites/site-*.toml | xargs -P "$jobs" -I{} sh -c \
    'f="$1"; n=$(basename "$f" .toml); "$2" run "$f" --out "$3/flown/$n" $4 >/dev/null' _ {} "$bin" "$work" "$rtk"
commit=$(git rev-parse --short=12 HEAD)
python3 - "$runs" "$work/flown" "$commit" "$rtk" > docs/results/formation-acceptance.md <<'PY'
import csv, datetime, json, os, statistics, sys

runs, flown, commit, rtk = sys.argv[1:5]
rows = list(csv.DictReader(open(runs)))
print("# Results: formation acceptance counts\n")
print("The formation family's and `soares-freshwater`'s acceptance counts on the test seed, and the "
      "declaration's confidence against its error.\n")
print(f"Measured at commit `{commit}` on {datetime.date.today()} by `scripts/formation_acceptance.sh`. "
      "The first table is counted from the `runs.csv` of\n`scripts/results.sh formation-family` "
      "(page [formation-family](formation-family.md); 200 sites per\nscenario, test seed 3102; every "
      "default was chosen on the tuning seed 3101). Early: declared more\nthan 10 m down-flow of the "
      "outlet (`error_along_m` > 10); late: more than 10 m up-flow of it.\n")
print("| scenario | config | runs | within 10 m | median error (m) | early by > 10 m | late by > 10 m | no declaration |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
groups = {}
for r in rows:
    groups.setdefault((os.path.basename(r["scenario"]), r["config"]), []).append(r)
pct = lambda k, n: f"{k} ({100.0 * k / n:.1f} %)"
for (scenario, config), rs in groups.items():
    n = len(rs)
    err = [float(r["error_m"]) for r in rs if r["error_m"]]
    along = [float(r["error_along_m"]) for r in rs if r["error_along_m"]]
    within = sum(1 for e in err if e <= 10.0)
    med = f"{statistics.median(err):.1f}" if err else "-"
    print(f"| {scenario} | {config} | {n} | {pct(within, n)} | {med} | "
          f"{pct(sum(1 for a in along if a > 10), n)} | {pct(sum(1 for a in along if a < -10), n)} | {n - len(err)} |")
print("\nConfidence: the same 200 family sites on the test seed with RTK leaders, each\nwritten by "
      "`plumetrace family examples/families/formation.family.toml --sample 200 --seed 3102 --out DIR`\n"
      f"and flown by `plumetrace run DIR/site-K.toml {rtk}`;\nthe confidence is the first declaring "
      "leader's `declaration_confidence` in `events.jsonl`, the error the first declaration's "
      "(`summary.json`).\n")
bins = [(0.0, 0.5), (0.5, 0.8), (0.8, 0.9), (0.9, 1.0)]
got = {b: [] for b in bins}
missing = 0
for name in sorted(os.listdir(flown)):
    d = os.path.join(flown, name)
    first = json.load(open(os.path.join(d, "summary.json"))).get("first_declaration")
    if not first:
        missing += 1
        continue
    conf = None
    for line in open(os.path.join(d, "events.jsonl")):
        e = json.loads(line)
        if e.get("vehicle") == first["vehicle"] and e.get("declaration_confidence") is not None:
            conf = e["declaration_confidence"]
            break
    if conf is None:
        missing += 1
        continue
    for lo, hi in bins:
        if lo <= conf < hi or (hi == 1.0 and conf == 1.0):
            got[(lo, hi)].append(first["error_m"])
            break
print("| confidence | runs | within 10 m | median error (m) |")
print("| --- | --- | --- | --- |")
for (lo, hi), errs in got.items():
    if errs:
        w = sum(1 for e in errs if e <= 10)
        print(f"| {lo:.1f}-{hi:.1f} | {len(errs)} | {w} ({100 * w / len(errs):.0f} %) | {statistics.median(errs):.1f} |")
    else:
        print(f"| {lo:.1f}-{hi:.1f} | 0 | - | - |")
print(f"\n{missing} of the 200 runs declared without a confidence or not at all.")
PY
echo "wrote docs/results/formation-acceptance.md"
