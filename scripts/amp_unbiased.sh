#!/usr/bin/env bash
# The AMP's declaration on the test seeds of the coastal, faults and duck-like families: flies the
# three campaigns benchmarks/campaigns/amp-unbiased-{coastal,faults,duck-like}.toml (test seeds of
# the benchmark's tasks, so they live beside the task set, not among the example campaigns, and
# fly with --test-seeds) and writes docs/results/amp-unbiased.md: the acceptance table read from
# their runs.csv (per family and configuration the share within 10 m, the median and largest
# error, the median signed along-flow error, and the weak-current (<= 0.08 m/s) and sparse-fix (a
# fix every 10 minutes or less often) sites apart), then each campaign's own summary.
#
#   scripts/amp_unbiased.sh                 build, fly the three campaigns, write the page
#   scripts/amp_unbiased.sh --bin PATH      a built plumetrace instead
#   scripts/amp_unbiased.sh --jobs N        worker threads (default: one per core)
#   scripts/amp_unbiased.sh --table-only    only rewrite the page from target/results/
set -euo pipefail
cd "$(dirname "$0")/.."

bin=""
jobs=""
table_only=0
while [ $# -gt 0 ]; do
    case "$1" in
        --bin) bin="$2"; shift 2 ;;
        --jobs) jobs="$2"; shift 2 ;;
        --table-only) table_only=1; shift ;;
        -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
        *) echo "amp_unbiased.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done

names=(amp-unbiased-coastal amp-unbiased-faults amp-unbiased-duck-like)
mkdir -p target/results
if [ "$table_only" -eq 0 ]; then
    if [ -z "$bin" ]; then
        cargo build --release --bin plumetrace
        bin="target/release/plumetrace"
    fi
    start=$(date +%s)
    for n in "${names[@]}"; do
        rm -rf "target/results/$n"
        cmd=("$bin" campaign "benchmarks/campaigns/$n.toml" --out "target/results/$n" --test-seeds)
        if [ -n "$jobs" ]; then cmd+=(--jobs "$jobs"); fi
        echo "== $n: ${cmd[*]}" >&2
        "${cmd[@]}" >&2
    done
    echo $(( $(date +%s) - start )) > target/results/amp-unbiased.seconds
fi

commit="$(git rev-parse --short=12 HEAD)"
if ! git diff --quiet HEAD -- crates benchmarks Cargo.toml Cargo.lock; then
    commit="$commit (with uncommitted changes to the code)"
fi
secs="$(cat target/results/amp-unbiased.seconds 2>/dev/null || echo "?")"
python3 - "$commit" "$secs" "$(nproc)" "${jobs:-one per core}" "${names[@]}" <<'EOF'
import csv, sys, statistics as st, datetime
commit, secs, cores, jobs, names = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:]

def line(label, rows):
    if not rows:
        return None
    errs = [float(r["error_m"]) for r in rows if r["error_m"]]
    along = [float(r["error_along_m"]) for r in rows if r["error_along_m"]]
    ok = sum(1 for r in rows if r["success"] == "true")
    far = sum(1 for e in errs if e > 50.0) + sum(1 for r in rows if not r["error_m"])
    med = f"{st.median(errs):.1f}" if errs else "-"
    big = f"{max(errs):.1f}" if errs else "-"
    sal = f"{st.median(along):+.1f}" if along else "-"
    return (f"| {label} | {len(rows)} | {ok}/{len(rows)} = {100 * ok / len(rows):.1f} % | {med} | "
            f"{big} | {far} | {sal} |")

out = ["# Results: `amp-unbiased`", "",
       "The AMP's declaration on the test seeds of the coastal, faults and duck-like families.", "",
       "200 sites each (common random numbers): `field`, the lost-point rule as flown in the field;",
       "`map`, the source map's declaration instead; `default`, the AMP as it ships. Every default",
       "was chosen on the families' tuning seeds (`examples/campaigns/amp-unbiased-tuning-*.toml`,",
       "`amp-fix-frames.toml` and `amp-fix-smoothing.toml`).",
       "On the faults family two more rows say what the navigation leaves (no choice was made on",
       "them): `exact-fixes`, the default with fixes that carry no error (the estimate still drifts",
       "between them), and `exact-nav`, the default with no navigation error at all (the flow",
       "reading's fault stays).", "",
       f"Produced at commit `{commit}` on {datetime.date.today()} by `scripts/amp_unbiased.sh` "
       f"(release build, {cores} cores; {secs} s of wall time), which ran", ""]
for n in names:
    out.append(f"    plumetrace campaign benchmarks/campaigns/{n}.toml --out target/results/{n} --test-seeds")
out += ["", "Within 10 m: the first declaration within 10 m of the source; errors in metres over the",
        "declaring runs; \"over 50 m\" counts declarations further than 50 m and runs without one;",
        "signed along: the median along-flow error (positive: declared downflow of the source).", ""]
head = ["| sites | runs | within 10 m | median | largest | over 50 m | signed along |",
        "| --- | --- | --- | --- | --- | --- | --- |"]
for n in names:
    rows = list(csv.DictReader(open(f"target/results/{n}/runs.csv")))
    family = n.removeprefix("amp-unbiased-")
    out += [f"## {family}", ""]
    for cfg in dict.fromkeys(r["config"] for r in rows):
        rr = [r for r in rows if r["config"] == cfg]
        out += [f"**{cfg}**", ""] + head
        for label, sub in (("all", rr),
                           ("current <= 0.08 m/s", [r for r in rr if float(r["site_flow_speed_mps"]) <= 0.08]),
                           ("a fix every >= 600 s", [r for r in rr if float(r["site_fix_interval_s"]) >= 600])):
            l = line(label, sub)
            if l:
                out.append(l)
        out.append("")
out += ["## The campaigns' own summaries", "",
        "Each copied whole from the campaign's `summary.md`.", ""]
for n in names:
    text = open(f"target/results/{n}/summary.md").read()
    # one level down: the page has its own title
    text = "\n".join(("#" + l) if l.startswith("#") else l for l in text.splitlines())
    out += [text, ""]
open("docs/results/amp-unbiased.md", "w").write("\n".join(out).rstrip("\n") + "\n")
print("amp_unbiased.sh: wrote docs/results/amp-unbiased.md")
EOF
