#!/usr/bin/env python3
"""The navigation error at a run's lost points, as saved and as a fix would move them.

For each run directory (the output of `plumetrace run`: `trajectory.csv` and `events.jsonl`),
finds the position fixes in the trajectory (the estimate's error steps by more than 0.3 m between
two rows), and for every lost point saved between two fixes prints nothing but adds to the
totals: its navigation error as saved (estimate less truth at its time), and after moving it by
the share of the next fix's jump that the AMP's smoothing gives it (`fix_error_m`,
`fix_drift_mps`). The trajectory does not say when the planner held flow readings back, so the
share here leaves out the held-back term (`held_back_drift_mps`): on a stretch with held-back
readings the planner moves points by more of the jump. Lost points after the last fix are left
out. Standard library only.

    plumetrace family examples/families/faults.family.toml --sample 24 --seed 3211 --out out/sites
    for f in out/sites/*.toml; do
        plumetrace run "$f" --set mapping=false --out "out/runs/$(basename "$f" .toml)"
    done
    python3 scripts/lost_point_nav_error.py out/runs/*
    python3 scripts/lost_point_nav_error.py --fix-error 2 --drift 0.005 out/runs/*
"""

import argparse
import bisect
import csv
import json
import math
import os
import sys


def stretches(path):
    """Times, errors and the indices where each fix's stretch starts."""
    t, e = [], []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["vehicle"] != "0":
                continue
            t.append(float(row["t_s"]))
            e.append((float(row["est_x_m"]) - float(row["true_x_m"]),
                      float(row["est_y_m"]) - float(row["true_y_m"])))
    starts = [0] + [i for i in range(1, len(e))
                    if math.hypot(e[i][0] - e[i - 1][0], e[i][1] - e[i - 1][1]) > 0.3]
    return t, e, starts


def share(t_in, span, after_fix, fix_m, drift_mps):
    """The AMP's share of a jump for a point `t_in` into a stretch of `span` (no held-back term)."""
    fix_var = fix_m * fix_m
    start_var = fix_var if after_fix else 0.0
    cov = start_var + drift_mps * drift_mps * t_in * span
    var = start_var + fix_var + drift_mps * drift_mps * span * span
    return min(max(cov / var, 0.0), 1.0) if var > 0 else 0.0


def median(v):
    v = sorted(v)
    n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", help="run directories")
    ap.add_argument("--fix-error", type=float, default=4.0, help="fix_error_m (default 4)")
    ap.add_argument("--drift", type=float, default=0.01, help="fix_drift_mps (default 0.01)")
    a = ap.parse_args()
    saved, moved = [], []
    for d in a.runs:
        traj, events = os.path.join(d, "trajectory.csv"), os.path.join(d, "events.jsonl")
        if not (os.path.isfile(traj) and os.path.isfile(events)):
            sys.exit(f"{d}: not a run directory (no trajectory.csv and events.jsonl)")
        t, e, starts = stretches(traj)
        if not t:
            sys.exit(f"{traj}: no rows of vehicle 0")
        with open(events) as f:
            lost = [json.loads(line)["t_s"] for line in f
                    if line.strip() and json.loads(line).get("event") == "lost_point"]
        for tl in lost:
            i = min(bisect.bisect_left(t, tl - 1e-6), len(t) - 1)
            k = bisect.bisect_right(starts, i) - 1
            if k + 1 >= len(starts):
                continue
            a0, b = starts[k], starts[k + 1]
            jump = (e[b][0] - e[b - 1][0], e[b][1] - e[b - 1][1])
            s = share(t[i] - t[a0], t[b] - t[a0], a0 > 0, a.fix_error, a.drift)
            saved.append(math.hypot(*e[i]))
            moved.append(math.hypot(e[i][0] + s * jump[0], e[i][1] + s * jump[1]))
    if not saved:
        sys.exit("no lost point saved between two fixes in these runs")
    p90 = lambda v: sorted(v)[int(0.9 * (len(v) - 1))]
    print(f"{len(saved)} lost points in {len(a.runs)} runs; navigation error median / p90: "
          f"as saved {median(saved):.1f} / {p90(saved):.1f} m, as moved "
          f"(fix_error_m {a.fix_error:g}, fix_drift_mps {a.drift:g}) "
          f"{median(moved):.1f} / {p90(moved):.1f} m")


if __name__ == "__main__":
    main()
