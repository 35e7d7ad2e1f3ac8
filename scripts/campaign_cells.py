#!/usr/bin/env python3
"""One cell per config and scenario of a campaign's runs.csv: the median error of the declaring
runs, how many runs declared within 10 m and within 20 m, the median signed along-flow error
(positive: downflow), and how many runs did not declare. Used by docs/planners.md (infotaxis's
tuning table); standard library only.

    python3 scripts/campaign_cells.py out/infotaxis-tuning/runs.csv
"""

import csv
import sys
from collections import defaultdict


def median(values):
    v = sorted(values)
    n = len(v)
    if n == 0:
        return None
    return v[n // 2] if n % 2 else (v[n // 2 - 1] + v[n // 2]) / 2


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip(), file=sys.stderr)
        sys.exit(0 if sys.argv[1:] in (["-h"], ["--help"]) else 2)
    try:
        with open(sys.argv[1]) as f:
            rows = list(csv.DictReader(f))
        if not rows:
            sys.exit(f"error: {sys.argv[1]}: no runs in it (a campaign's runs.csv has a row per run)")
        groups, scenarios, configs = defaultdict(list), [], []
        for r in rows:
            groups[(r["config"], r["scenario"])].append(r)
            if r["scenario"] not in scenarios:
                scenarios.append(r["scenario"])
            if r["config"] not in configs:
                configs.append(r["config"])
        print("| config | " + " | ".join(s.split("/")[-1].replace(".family.toml", "") for s in scenarios) + " |")
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
                if n > len(errors):
                    cell += f" ({n - len(errors)} undeclared)"
                cells.append(cell)
            print(f"| {c} | " + " | ".join(cells) + " |")
    except OSError as e:
        sys.exit(f"error: {sys.argv[1]}: cannot read it ({e.strerror})")
    except (KeyError, ValueError, UnicodeDecodeError, csv.Error) as e:
        sys.exit(f"error: {sys.argv[1]}: not a campaign's runs.csv (no or bad column {e})")


if __name__ == "__main__":
    main()
