#!/usr/bin/env python3
"""Two-sample comparison of two configurations of a campaign's runs.csv, per scenario.

    python3 scripts/two_sample.py RUNS_CSV CONFIG_A CONFIG_B [--alpha 0.01]

For every scenario that has both configurations: the declared and success rates with Fisher's
exact test, and for the declaration error, its along- and across-flow parts, the time to first
detection and the declaration time: medians, the two-sample Kolmogorov-Smirnov test and the
Mann-Whitney U test (runs without a value are left out of that metric). Prints a Markdown table
and exits with status 1 when any p-value is below --alpha. Needs scipy
(scripts/two_sample.sh makes a virtual environment with it).
"""
import argparse
import csv
import statistics
import sys
from collections import defaultdict

from scipy import stats

METRICS = [
    ("error_m", "error (m)"),
    ("error_along_m", "along-flow error (m)"),
    ("error_cross_m", "cross-flow error (m)"),
    ("first_detection_s", "first detection (s)"),
    ("declaration_s", "declaration time (s)"),
]


def values(rows, key):
    out = []
    for r in rows:
        v = r.get(key, "")
        if v not in ("", None):
            out.append(abs(float(v)) if key.startswith("error_") else float(v))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs")
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--alpha", type=float, default=0.01)
    args = ap.parse_args()
    groups = defaultdict(list)
    with open(args.runs, newline="") as f:
        for r in csv.DictReader(f):
            groups[(r["scenario"], r["config"])].append(r)
    scenarios = sorted({s for s, _ in groups})
    worst = 1.0
    print(f"| scenario | metric | {args.a} | {args.b} | test | p |")
    print("| --- | --- | --- | --- | --- | --- |")
    for s in scenarios:
        ra, rb = groups.get((s, args.a)), groups.get((s, args.b))
        if not ra or not rb:
            continue
        for key, name in [("declared", "declared"), ("success", "success")]:
            ka = sum(r[key] == "true" for r in ra)
            kb = sum(r[key] == "true" for r in rb)
            p = stats.fisher_exact([[ka, len(ra) - ka], [kb, len(rb) - kb]]).pvalue
            worst = min(worst, p)
            print(f"| {s} | {name} | {ka}/{len(ra)} | {kb}/{len(rb)} | Fisher | {p:.3f} |")
        for key, name in METRICS:
            va, vb = values(ra, key), values(rb, key)
            if len(va) < 5 or len(vb) < 5:
                continue
            ks = stats.ks_2samp(va, vb).pvalue
            mw = stats.mannwhitneyu(va, vb, alternative="two-sided").pvalue
            worst = min(worst, ks, mw)
            ma, mb = statistics.median(va), statistics.median(vb)
            print(f"| {s} | {name}, median | {ma:.1f} (n {len(va)}) | {mb:.1f} (n {len(vb)}) "
                  f"| KS / Mann-Whitney | {ks:.3f} / {mw:.3f} |")
    print(f"\nsmallest p-value: {worst:.3f} (alpha {args.alpha})")
    sys.exit(1 if worst < args.alpha else 0)


if __name__ == "__main__":
    main()
