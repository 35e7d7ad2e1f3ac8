#!/usr/bin/env python3
"""Writes the single-AUV twin of a formation site (a site file of
examples/families/formation.family.toml written by `plumetrace family`): the same basin, outlet,
current, medium, time limit and run seed, with the team replaced by one AUV that starts where the
team's centre starts (the leaders' midpoint), heading as the team heads, `--depth` metres below
the surface (the planner's `altitude_m`, and the AMP's tracing altitude, are set to hold it), with
the follower's dynamics, the AUV's default navigation and a salinity probe
read as its contrast (`model = "salinity_deficit"`, the site's medium salinity), flying the
planner table in `--planner` (a TOML file, copied as `[planners.single]`).

    scripts/formation_single.py SITE.toml --out TWIN.toml --planner amp.toml --depth 0.5
    scripts/formation_single.py DIR/site-*.toml --out TWINS/ --planner amp.toml --depth 0.5

(several sites: OUT is a directory, each twin named as its site).

Only the standard library: the site is read with tomllib and the twin written by a small TOML
writer for the tables, arrays of tables, numbers, strings, booleans and arrays a site holds.
"""

import argparse
import os
import sys
import tomllib


def value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(value(x) for x in v) + "]"
    raise TypeError(f"no TOML for {v!r}")


def is_tables(v):
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def body(t, path, out):
    """The keys of table `t` (at `path`), then its sub-tables and arrays of tables."""
    for k, v in t.items():
        if not isinstance(v, dict) and not is_tables(v):
            out.append(f"{k} = {value(v)}")
    for k, v in t.items():
        p = f"{path}.{k}" if path else k
        if isinstance(v, dict):
            if any(not isinstance(x, dict) and not is_tables(x) for x in v.values()):
                out.append(f"\n[{p}]")
            body(v, p, out)
        elif is_tables(v):
            for item in v:
                out.append(f"\n[[{p}]]")
                body(item, p, out)


def single(site, planner, depth_m):
    """The single-AUV twin of `site` (a parsed site table)."""
    twin = {k: v for k, v in site.items() if k not in ("vehicles", "planners", "comms")}
    vehicles = site.get("vehicles", [])
    leaders = [v for v in vehicles if v.get("kind") == "surface"]
    follower = next((v for v in vehicles if v.get("kind") == "auv"), None)
    if len(leaders) != 2 or follower is None:
        raise ValueError("not a formation site: it needs two surface leaders and an AUV follower")
    depth = site.get("domain", {}).get("depth_m")
    if depth is None or not 0.0 <= depth_m < depth:
        raise ValueError(f"--depth {depth_m} is not inside the site's {depth} m of water")
    sensor = follower.get("chem_sensor", {})
    auv = {
        "kind": "auv",
        "name": "auv",
        "x_m": round(sum(v["x_m"] for v in leaders) / 2.0, 3),
        "y_m": round(sum(v["y_m"] for v in leaders) / 2.0, 3),
        "heading_deg": follower.get("heading_deg", 0.0),
        "altitude_m": round(depth - depth_m, 3),
        "planner": "single",
    }
    if "dynamics" in follower:
        auv["dynamics"] = dict(follower["dynamics"])
    auv["chem_sensor"] = {
        "model": "salinity_deficit",
        "medium_salinity_ppt": sensor.get("medium_salinity_ppt", 35.0),
    }
    twin["vehicles"] = [auv]
    # The planner holds the AUV at the depth asked for (its altitude command), tracing too.
    planner = dict(planner, altitude_m=auv["altitude_m"])
    if planner.get("kind") == "amp":
        planner["track_altitude_m"] = 0.0
    twin["planners"] = {"single": planner}
    return twin


def write_twin(path, out, planner, depth):
    with open(path, "rb") as f:
        twin = single(tomllib.load(f), planner, depth)
    with open(path) as f:
        head = [line for line in f if line.startswith("#")]
    lines = []
    body(twin, "", lines)
    with open(out, "w") as f:
        f.write(f"# The single-AUV twin of {path} (scripts/formation_single.py, "
                f"{depth} m down, planner {planner.get('kind', '?')}); the site as drawn:\n")
        f.writelines(head[2:])
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sites", nargs="+")
    ap.add_argument("--out", required=True, help="the twin's file, or a directory for several sites")
    ap.add_argument("--planner", required=True, help="TOML file of the planner table")
    ap.add_argument("--depth", type=float, default=0.5, help="depth below the surface, m")
    a = ap.parse_args()
    try:
        with open(a.planner, "rb") as f:
            planner = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        sys.exit(f"formation_single.py: --planner {a.planner}: {e}")
    if len(a.sites) > 1 or os.path.isdir(a.out):
        os.makedirs(a.out, exist_ok=True)
        outs = [os.path.join(a.out, os.path.basename(p)) for p in a.sites]
    else:
        outs = [a.out]
    for path, out in zip(a.sites, outs):
        try:
            write_twin(path, out, planner, a.depth)
        except (OSError, tomllib.TOMLDecodeError, ValueError, KeyError) as e:
            sys.exit(f"formation_single.py: {path}: {e}")


if __name__ == "__main__":
    main()
