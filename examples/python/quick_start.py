"""Quick start: fly the demo mission, look at the result, write the command line's files, and
query a plume.

    python quick_start.py [--seed 7] [--out OUT_DIR]
"""

import argparse

import numpy as np

import plumetrace


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--out", default="quick-start-out", help="where save() writes the files")
    args = ap.parse_args()

    print("presets:", ", ".join(name for name, _ in plumetrace.presets()))
    r = plumetrace.run("demo", seed=args.seed)
    print("outcome:", r.outcome)
    d = r.summary["first_declaration"]
    if d:
        print(f"declared at {d['t_s']:.0f} s, {d['error_m']:.1f} m from the source")
    print("steps recorded:", len(r.trajectory["t_s"]))
    written = r.save(args.out)  # the files of `plumetrace run --preset demo --out OUT_DIR`
    print("wrote", ", ".join(written), "into", args.out)

    p = plumetrace.Plume("demo", seed=args.seed)
    p.spin_up(600.0)
    centre = p.filaments()[:, :3].mean(axis=0)  # x, y, z of the plume's filaments' centroid
    print("concentration at the filaments' centroid:", p.concentrations(centre))
    xy = np.column_stack([np.linspace(100, 400, 7), np.zeros(7)])  # x, y: at height p.z_m
    print(f"along y = 0 at z = {p.z_m} m:", np.round(p.concentrations(xy), 4))


if __name__ == "__main__":
    main()
