#!/usr/bin/env python3
"""One cell per config and scenario of a campaign's runs.csv: the median error of the declaring
runs, how many runs declared within 10 m and within 20 m, the median signed along-flow error
(positive: downflow), and how many runs did not declare. Used by docs/planners.md (infotaxis's
tuning tables); standard library only.

    python3 scripts/campaign_cells.py out/infotaxis-tuning/runs.csv
    python3 scripts/campaign_cells.py out/infotaxis-along/runs.csv --against default
    python3 scripts/campaign_cells.py target/results/infotaxis-field-scale/runs.csv --beyond 50

With `--beyond M` each cell also counts the declarations more than M metres from the source.

With `--against CONFIG` a second table pairs every other config's runs with CONFIG's runs of the
same scenario and seed (a campaign's configs fly the same plumes, seed for seed): per cell, the
runs whose error is smaller and larger than CONFIG's, and the median of the differences (negative:
closer to the source), over the pairs in which both declared.
"""

import argparse
import csv
import sys
from collections import defaultdict


def median(values):
    v = sorted(values)
    n = len(v)
    if n == 0:
        return None
    return v[n // 2] if n % 2 else (v[n // 2 - 1] + v[n // 2]) / 2


def short(scenario):
    return scenario.split("/")[-1].replace(".family.toml", "")


def paired(groups, scenarios, configs, base):
    """The second table: each config against `base`, run by run."""
    print()
    print(f"| config against {base} | " + " | ".join(short(s) for s in scenarios) + " |")
    print("| --- " * (len(scenarios) + 1) + "|")
    for c in configs:
        if c == base:
            continue
        cells = []
        for s in scenarios:
            ours = {r["seed_index"]: r for r in groups[(c, s)] if r["declared"] == "true"}
            theirs = {r["seed_index"]: r for r in groups[(base, s)] if r["declared"] == "true"}
            diffs = [float(ours[k]["error_m"]) - float(theirs[k]["error_m"]) for k in ours if k in theirs]
            if not diffs:
                cells.append("no pair declared")
                continue
            closer = sum(d < 0 for d in diffs)
            further = sum(d > 0 for d in diffs)
            cells.append(f"{closer} closer, {further} further of {len(diffs)}, {median(diffs):+.1f} m")
        print(f"| {c} | " + " | ".join(cells) + " |")


def main():
    ap = argparse.ArgumentParser(
        description=__doc__.strip(), formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("runs_csv", help="a campaign's runs.csv")
    ap.add_argument("--against", metavar="CONFIG",
                    help="pair every other config's runs with this config's, seed for seed")
    ap.add_argument("--beyond", metavar="M", type=float,
                    help="also count the declarations more than M metres from the source")
    a = ap.parse_args()
    path, base = a.runs_csv, a.against
    try:
        with open(path) as f:
            rows = list(csv.DictReader(f))
        if not rows:
            sys.exit(f"error: {path}: no runs in it (a campaign's runs.csv has a row per run)")
        groups, scenarios, configs = defaultdict(list), [], []
        for r in rows:
            groups[(r["config"], r["scenario"])].append(r)
            if r["scenario"] not in scenarios:
                scenarios.append(r["scenario"])
            if r["config"] not in configs:
                configs.append(r["config"])
        if base is not None and base not in configs:
            sys.exit(f"error: --against {base}: no such config in {path} (its configs: {', '.join(configs)})")
        print("| config | " + " | ".join(short(s) for s in scenarios) + " |")
        print("| --- " * (len(scenarios) + 1) + "|")
        for c in configs:
            cells = []
            for s in scenarios:
                runs = groups[(c, s)]
                declared = [r for r in runs if r["declared"] == "true"]
                errors = [float(r["error_m"]) for r in declared]
                if not errors:
                    cells.append(f"no declaration in {len(runs)}")
                    continue
                along = median(float(r["error_along_m"]) for r in declared)
                n = len(runs)
                cell = (f"{median(errors):.1f} m, {sum(e <= 10 for e in errors)}/{n}, "
                        f"{sum(e <= 20 for e in errors)}/{n}, {along:+.1f} m")
                if a.beyond is not None:
                    cell += f", {sum(e > a.beyond for e in errors)} beyond {a.beyond:g} m"
                if n > len(errors):
                    cell += f" ({n - len(errors)} undeclared)"
                cells.append(cell)
            print(f"| {c} | " + " | ".join(cells) + " |")
        if base is not None:
            paired(groups, scenarios, configs, base)
    except OSError as e:
        sys.exit(f"error: {path}: cannot read it ({e.strerror})")
    except UnicodeDecodeError:
        sys.exit(f"error: {path}: not a text file (a campaign's runs.csv is CSV text)")
    except (KeyError, ValueError, csv.Error) as e:
        sys.exit(f"error: {path}: not a campaign's runs.csv (no or bad column {e})")


if __name__ == "__main__":
    main()
