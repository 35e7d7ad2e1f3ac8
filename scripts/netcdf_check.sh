#!/usr/bin/env bash
# Reads a plume run's plume.nc (feature `netcdf`) with an independent reader of the NetCDF
# classic format, scipy.io.netcdf_file, and compares it with the same run's probes.csv and
# snapshot.csv: dimensions, CF attributes, probe positions, times, every concentration and the
# time-averaged map. Then the other way round: currents and a seabed written by xarray (its scipy
# engine, datetime64 times encoded by xarray) are read by the command line, the currents flying
# the same mission, bit for bit, as the same numbers in a CSV grid, and the seabed put under it.
# Exits non-zero on any mismatch.
#
# Uses numpy, scipy and xarray in the virtual environment scripts/venvs.sh makes (scripts/.venv-netcdf), runs the
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

"$venv/bin/python" - "$run" <<'PY'
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

# xarray-written files read by the command line.
plumetrace() {
    if [ -n "$bin" ]; then
        "$bin" "$@"
    else
        cargo run --quiet --manifest-path "$root/Cargo.toml" -p plumetrace-cli --features netcdf -- "$@"
    fi
}
xr_dir="${CARGO_TARGET_DIR:-$root/target}/netcdf-check/xarray"
rm -rf "$xr_dir"
mkdir -p "$xr_dir"
"$venv/bin/python" - "$xr_dir" "$root/crates/plumetrace-scenario/presets/demo.toml" \
    "$root/crates/plumetrace-py/python/plumetrace/sites.py" <<'PY'
import importlib.util
import os
import sys

import numpy as np
import pandas as pd
import xarray as xr

out, demo = sys.argv[1], sys.argv[2]
# The Python package's writer (a module of plain Python, loaded without the native part).
spec = importlib.util.spec_from_file_location("sites", sys.argv[3])
sites = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sites)
xs = np.arange(0.0, 521.0, 40.0)
ys = np.arange(-150.0, 151.0, 30.0)
seconds = np.arange(0.0, 1201.0, 300.0)
times = pd.Timestamp("2026-06-01T04:00:00") + pd.to_timedelta(seconds, unit="s")
T, Y, X = np.meshgrid(seconds, ys, xs, indexing="ij")
phase = 2.0 * np.pi * T / 44712.0
u = 0.15 + 0.03 * np.cos(phase) + 0.0001 * Y
v = 0.02 * np.sin(phase) + 0.01 * np.sin(X / 97.0)
coords = {
    "time": ("time", times, {"standard_name": "time"}),
    "y": ("y", ys, {"standard_name": "projection_y_coordinate", "units": "m"}),
    "x": ("x", xs, {"standard_name": "projection_x_coordinate", "units": "m"}),
}
currents = xr.Dataset(
    {
        "u": (("time", "y", "x"), u, {"standard_name": "sea_water_x_velocity", "units": "m s-1"}),
        "v": (("time", "y", "x"), v, {"standard_name": "sea_water_y_velocity", "units": "m s-1"}),
    },
    coords=coords,
    attrs={"Conventions": "CF-1.8"},
)
currents.to_netcdf(f"{out}/currents.nc", format="NETCDF3_64BIT", engine="scipy")
with open(f"{out}/flow.csv", "w") as f:
    f.write("t_s,x_m,y_m,u_mps,v_mps\n")
    for k, t in enumerate(seconds):
        for j, yy in enumerate(ys):
            for i, xx in enumerate(xs):
                row = (t, xx, yy, u[k, j, i], v[k, j, i])
                f.write(",".join(repr(float(c)) for c in row) + "\n")
# (xarray's own call above; the package's plumetrace.sites below.)
# The seabed as GEBCO stores it: an elevation, negative below sea level, a 4 % slope up to the
# north, as 32-bit floats.
sy = np.arange(-200.0, 201.0, 20.0)
sx = np.arange(-40.0, 561.0, 20.0)
elevation = (-16.0 + 0.04 * sy)[:, None] + 0.0 * sx[None, :]
seabed = xr.Dataset(
    {"elevation": (("y", "x"), elevation.astype("float32"),
                   {"standard_name": "height_above_mean_sea_level", "units": "m"})},
    coords={
        "y": ("y", sy, {"standard_name": "projection_y_coordinate", "units": "m"}),
        "x": ("x", sx, {"standard_name": "projection_x_coordinate", "units": "m"}),
    },
)
keys = sites.site_set(bathymetry=seabed, directory=out)
assert keys == {"bathymetry.file": os.path.join(os.path.abspath(out), "seabed.nc")}, keys
# The demo, shorter, over the gridded flow (as the command line's site test builds it).
text = open(demo).read()
text = text.replace('model = "farrell"', 'model = "gridded"\nfile = "FILE"', 1)
text = text.replace("[flow.mean]\nspeed_mps = 0.15\ntoward_deg = 90.0\n", "", 1)
text = text.replace("time_limit_s = 2400.0", "time_limit_s = 600.0", 1)
text = text.replace("duration_s = 2400.0", "duration_s = 600.0", 1)
text = text.replace("spinup_s = 3500.0", "spinup_s = 600.0", 1)
text = text[: text.index("[flow.farrell]")] + text[text.index("[plume]"):]
for name, file in (("csv", "flow.csv"), ("xarray", "currents.nc")):
    with open(f"{out}/{name}.toml", "w") as f:
        f.write(text.replace("FILE", file, 1))
with open(f"{out}/seabed.toml", "w") as f:
    f.write(text.replace("FILE", "currents.nc", 1).replace("depth_m = 8.0\n", "\n[bathymetry]\nfile = \"seabed.nc\"\n", 1))
print(f"xarray {xr.__version__} wrote currents.nc and seabed.nc ({out})")
PY
for name in csv xarray seabed; do
    plumetrace run "$xr_dir/$name.toml" --seed 5 --out "$xr_dir/$name" >/dev/null
done
if ! cmp -s "$xr_dir/csv/trajectory.csv" "$xr_dir/xarray/trajectory.csv"; then
    echo "currents written by xarray fly another mission than the same numbers in a CSV grid" >&2
    exit 1
fi
grep -q '"outcome"' "$xr_dir/seabed/summary.json"
echo "xarray's currents fly the CSV grid's mission bit for bit; its seabed is read ($xr_dir)"
