"""Plots a mission's track over the time-averaged plume with matplotlib (optional: without it,
the example says so and stops).

    python plot_trajectory.py [--seed 7] [--out track.png]
"""

import argparse
import sys

import numpy as np

import plumetrace


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--out", default="track.png")
    args = ap.parse_args()
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed (pip install matplotlib); nothing plotted")
        return

    r = plumetrace.run("demo", seed=args.seed, outputs=False)
    tr = r.trajectory
    p = plumetrace.Plume("demo", seed=args.seed)
    p.spin_up(1800.0)
    x0, x1, y0, y1 = p.domain
    x, y = np.linspace(x0, x1, 120), np.linspace(y0, y1, 80)
    mean, _ = p.mean_maps(x, y, p.z_m, duration_s=300.0, every_s=10.0)

    fig, ax = plt.subplots(figsize=(8, 5))
    ax.pcolormesh(x, y, mean, shading="auto", cmap="Blues")
    for k, name in enumerate(r.vehicles):
        mine = tr["vehicle"] == k
        ax.plot(tr["true_x_m"][mine], tr["true_y_m"][mine], lw=1, label=name)
        hit = mine & tr["detection"]
        ax.plot(tr["true_x_m"][hit], tr["true_y_m"][hit], ".", ms=3, color="orange")
    d = r.summary["first_declaration"]
    if d:
        ax.plot(d["x_m"], d["y_m"], "rx", ms=10, label=f"declared ({d['error_m']:.1f} m off)")
    ax.set_xlabel("x (m, east)")
    ax.set_ylabel("y (m, north)")
    ax.set_aspect("equal")
    ax.set_title(f"demo, seed {args.seed}: {r.outcome}")
    ax.legend(loc="upper right")
    fig.savefig(args.out, dpi=100, bbox_inches="tight")
    print("wrote", args.out)


if __name__ == "__main__":
    sys.exit(main())
