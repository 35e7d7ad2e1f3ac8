#!/usr/bin/env python3
"""How often a vehicle's sensor detects, by where it is relative to the source.

Reads the `trajectory.csv` and `summary.json` of one or more run directories (single-source
missions; the samples of one vehicle, `--vehicle`, 0 unless given) and prints the share of samples (one per second of mission time) that detected, binned by the
distance along the mean flow from the source (positive: downflow) and the distance across it.
Used by docs/planners.md (infotaxis, its plume model); standard library only.

    python3 scripts/detection_profile.py --toward-deg 128 out/lm1 out/lm2
"""

import argparse
import csv
import json
import math
import sys
from pathlib import Path

ALONG = [-50, 0, 10, 25, 50, 100, 200, 400, 800]
ACROSS = [0, 10, 25, 50, 100]


def bin_of(edges, v):
    for i in range(len(edges) - 1):
        if edges[i] <= v < edges[i + 1]:
            return i
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--toward-deg", type=float, required=True,
                    help="the mean flow's direction, degrees clockwise from North (toward)")
    ap.add_argument("--vehicle", type=int, default=0, help="the vehicle whose samples count (default 0)")
    ap.add_argument("runs", nargs="+", help="run directories (plumetrace run --out)")
    a = ap.parse_args()
    th = math.radians(a.toward_deg)
    u = (math.sin(th), math.cos(th))
    counts = {}
    for d in a.runs:
        d = Path(d)
        try:
            summary = json.loads((d / "summary.json").read_text())
            if len(summary["sources"]) != 1:
                sys.exit(f"error: {d}: {len(summary['sources'])} sources; this profile is of a single-source mission")
            src = summary["sources"][0]
            sx, sy = src["x_m"], src["y_m"]
            rows = csv.DictReader(open(d / "trajectory.csv"))
            last = -1e9
            for r in rows:
                if int(r["vehicle"]) != a.vehicle:
                    continue
                t = float(r["t_s"])
                if t - last < 1.0:
                    continue
                last = t
                x, y = float(r["true_x_m"]) - sx, float(r["true_y_m"]) - sy
                along, across = x * u[0] + y * u[1], abs(-x * u[1] + y * u[0])
                i, j = bin_of(ALONG, along), bin_of(ACROSS, across)
                if i is None or j is None:
                    continue
                n, h = counts.get((i, j), (0, 0))
                counts[(i, j)] = (n + 1, h + int(r["detection"]))
        except (OSError, KeyError, IndexError, ValueError) as e:
            sys.exit(f"error: {d}: cannot read its summary.json and trajectory.csv ({e})")
    head = " | ".join(f"across {ACROSS[j]}-{ACROSS[j + 1]} m" for j in range(len(ACROSS) - 1))
    print(f"| along (m) | {head} |")
    print("| --- " * len(ACROSS) + "|")
    for i in range(len(ALONG) - 1):
        cells = []
        for j in range(len(ACROSS) - 1):
            n, h = counts.get((i, j), (0, 0))
            cells.append(f"{h / n:.2f} ({n})" if n else "-")
        print(f"| {ALONG[i]} to {ALONG[i + 1]} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
