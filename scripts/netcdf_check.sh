#!/usr/bin/env bash
# Reads a plume run's plume.nc (feature `netcdf`) with an independent reader of the NetCDF
# classic format, scipy.io.netcdf_file, and compares it with the same run's probes.csv and
# snapshot.csv: dimensions, CF attributes, probe positions, times, every concentration and the
# time-averaged map. Exits non-zero on any mismatch.
#
# Uses numpy and scipy in the virtual environment scripts/venvs.sh makes (scripts/.venv-netcdf), runs the
# plume-demo preset with five probes (in its last table, [output]) unless --run names the output
# directory of a run already made, and compares.
#
# Usage: scripts/netcdf_check.sh [--run DIR] [--bin PLUMETRACE]
#   --bin   a plumetrace built with the feature (default: `cargo run --features netcdf`)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
run=""
bin=""
while [ $# -gt 0 ]; do
    case "$1" in
        --run) run=$2; shift 2 ;;
        --bin) bin=$2; shift 2 ;;
        *) echo "unknown argument: $1" >&2; exit 2 ;;
    esac
done
venv=$(bash "$here/venvs.sh" netcdf)

if [ -z "$run" ]; then
    out="${CARGO_TARGET_DIR:-$root/target}/netcdf-check"
    mkdir -p "$out"
    preset="$root/crates/plumetrace-scenario/presets/plume-demo.toml"
    tail -n 1 "$preset" | grep -q '^threshold' || { echo "[output] is not the preset's last table" >&2; exit 1; }
    {
        cat "$preset"
        echo 'probes = [[20.0, 0.0, 2.0], [50.0, 0.0, 2.0], [100.0, 5.0, 2.0], [150.0, -10.0, 1.0], [190.0, 0.0, 0.0]]'
        echo 'probe_interval_s = 1.0'
    } > "$out/scenario.toml"
    run="$out/run"
    if [ -n "$bin" ]; then
        "$bin" run "$out/scenario.toml" --out "$run"
    else
        cargo run --quiet --manifest-path "$root/Cargo.toml" -p plumetrace-cli --features netcdf -- \
            run "$out/scenario.toml" --out "$run"
    fi
fi

exec "$venv/bin/python" - "$run" <<'PY'
import json
import sys

import numpy as np
from scipy.io import netcdf_file

run = sys.argv[1]
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def close(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.allclose(a, b, rtol=2e-6, atol=1e-12)


probes = np.loadtxt(f"{run}/probes.csv", delimiter=",", skiprows=1, ndmin=2)
snapshot = np.loadtxt(f"{run}/snapshot.csv", delimiter=",", skiprows=1, ndmin=2)
stats = json.load(open(f"{run}/stats.json"))
with netcdf_file(f"{run}/plume.nc", "r", mmap=False) as f:
    check(f.version_byte in (1, 2), f"version byte {f.version_byte}")
    check(text(f.Conventions) == "CF-1.8", f"Conventions = {f.Conventions!r}")
    check(text(f.scenario) == stats["scenario"], f"scenario = {f.scenario!r}")
    check(text(f.seed) == str(stats["seed"]), f"seed = {f.seed!r}, stats.json {stats['seed']}")
    check(text(f.title) != "", "no title")
    nt, npr = f.dimensions["time"], f.dimensions["probe"]
    check(nt == stats["probe_samples"] and npr == stats["probes"], f"dimensions {nt} x {npr}")
    v = f.variables
    t = v["time"]
    check(text(t.standard_name) == "time", "time.standard_name")
    check(text(t.units).startswith("seconds since "), f"time.units = {t.units!r}")
    c = v["concentration"]
    check(c.dimensions == ("time", "probe"), f"concentration{c.dimensions}")
    check(text(c.coordinates) == "x y z", "concentration.coordinates")
    check(text(c.units) != "" and text(c.long_name) != "", "concentration units, long_name")
    for name in ("x", "y", "z"):
        check(v[name].dimensions == ("probe",) and text(v[name].units) == "m", f"{name}")
    check(probes.shape == (nt * npr, 6), f"probes.csv has shape {probes.shape}")
    if probes.shape == (nt * npr, 6):
        rows = probes.reshape(nt, npr, 6)
        check(close(rows[:, 0, 0], t.data), "time against probes.csv t_s")
        check((rows[:, :, 1] == np.arange(npr)).all(), "probe indices in probes.csv")
        for k, name in ((2, "x"), (3, "y"), (4, "z")):
            check(close(rows[0, :, k], v[name].data), f"{name} against probes.csv")
        check(close(rows[:, :, 5], c.data), "concentration against probes.csv")
        print(f"probes: {nt} samples x {npr} probes, largest {c.data.max():.4g}")
    m = v["mean_concentration"]
    check(m.dimensions == ("grid_y", "grid_x"), f"mean_concentration{m.dimensions}")
    check(int(m.samples) == stats["mean_samples"], "mean_concentration.samples")
    gx, gy = v["grid_x"].data, v["grid_y"].data
    if snapshot.shape[0] == gx.size * gy.size:
        check(close(snapshot[:, 0], np.tile(gx, gy.size)), "grid_x against snapshot.csv")
        check(close(snapshot[:, 1], np.repeat(gy, gx.size)), "grid_y against snapshot.csv")
        check(close(snapshot[:, 3], m.data.ravel()), "mean_concentration against snapshot.csv")
    else:
        check(False, f"snapshot.csv has {snapshot.shape[0]} rows for {gx.size} x {gy.size}")
    check(close(v["grid_z"].getValue(), stats["snapshot_z_m"]), "grid_z")

if failures:
    print("plume.nc does not match the run's CSV files:", file=sys.stderr)
    for f in failures:
        print(f"  {f}", file=sys.stderr)
    sys.exit(1)
print(f"plume.nc matches probes.csv and snapshot.csv ({run})")
PY
