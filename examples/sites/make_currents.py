#!/usr/bin/env python3
"""Writes currents.nc and seabed.nc: a small synthetic ocean-model forecast and bathymetry for
the example site, in CF-1.8 NetCDF classic (CDF-1), with the standard library only.

A tidal coastal current off a coast to the north: eastward 0.15 m/s on average, swinging by
0.05 m/s over the M2 tide (12.42 h) with a small cross-shore part, slower towards the coast
and with depth. Longitude/latitude grid (about 55 m between nodes), four depth levels (0, 4, 8,
12 m), hourly frames over six hours from 2026-06-01 00:00 UTC, velocities packed as shorts
(scale_factor 0.001 m/s) with a fill value on the land row at the north edge: what a
Copernicus-style product holds, only smaller. The output is the same, byte for byte, on every
run.

The seabed (seabed.nc) slopes down away from the coast, from 10 m deep along the north edge to
18 m along the south edge (1.8 %), with a channel 3 m deep and about 60 m wide cut along the
current south of the source, on a finer longitude/latitude grid (about 21 m) than the currents.
It is stored as GEBCO stores its grids: an elevation, negative below sea level, as floats. Both
files are the same, byte for byte, on every run.

    python3 make_currents.py [DIR]      (default: beside this script)
"""

import math
import os
import struct
import sys

LAT = [50.3480 + 0.0005 * k for k in range(9)]  # about -222 m to +222 m around 50.35 N
LON = [-4.1510 + 0.0008 * k for k in range(12)]  # about -71 m to +570 m around 4.15 W
DEPTH = [0.0, 4.0, 8.0, 12.0]
HOURS = [float(h) for h in range(7)]
FILL = -32767
SCALE = 0.001
M2_H = 12.42


# The seabed's grid: finer than the currents', over the same area.
SEABED_LAT = [50.3480 + 0.0002 * k for k in range(21)]
SEABED_LON = [-4.1510 + 0.0003 * k for k in range(31)]
CHANNEL_LAT = 50.34964  # about 40 m south of the origin
CHANNEL_HALF_WIDTH_DEG = 0.00027  # about 30 m


def elevation(lat, lon):
    """The seabed's height above mean sea level, m (negative: under water), to a centimetre."""
    offshore = (LAT[-1] - lat) / (LAT[-1] - LAT[0])
    channel = 3.0 * math.exp(-(((lat - CHANNEL_LAT) / CHANNEL_HALF_WIDTH_DEG) ** 2))
    wobble = 0.5 * math.sin(2.0 * math.pi * (lon - LON[0]) / 0.004)
    return round(-(10.0 + 8.0 * offshore + channel + wobble), 2)


def current(hour, depth, lat):
    """(u, v) in m/s: the tide, slowed towards the coast (north) and with depth."""
    phase = 2.0 * math.pi * (hour - 1.0) / M2_H
    coast = 1.0 - 0.3 * (lat - LAT[0]) / (LAT[-1] - LAT[0])
    shear = 1.0 - 0.15 * depth / DEPTH[-1]
    u = (0.15 + 0.05 * math.cos(phase)) * coast * shear
    v = 0.02 * math.sin(phase) * shear
    return u, v


def packed(component):
    values = []
    for hour in HOURS:
        for depth in DEPTH:
            for j, lat in enumerate(LAT):
                for _lon in LON:
                    if j == len(LAT) - 1:  # land along the north edge
                        values.append(FILL)
                    else:
                        values.append(round(current(hour, depth, lat)[component] / SCALE))
    return values


def name(s):
    b = s.encode()
    return struct.pack(">i", len(b)) + b + b"\0" * (-len(b) % 4)


def attr(key, value):
    if isinstance(value, str):
        b = value.encode()
        return name(key) + struct.pack(">ii", 2, len(b)) + b + b"\0" * (-len(b) % 4)
    if isinstance(value, float):
        return name(key) + struct.pack(">iid", 6, 1, value)
    if isinstance(value, int):
        return name(key) + struct.pack(">iih", 3, 1, value) + b"\0\0"  # a short
    raise TypeError(value)


def attrs(pairs):
    if not pairs:
        return struct.pack(">ii", 0, 0)
    return struct.pack(">ii", 0x0C, len(pairs)) + b"".join(attr(k, v) for k, v in pairs)


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    write_currents(os.path.join(out_dir, "currents.nc"))
    write_seabed(os.path.join(out_dir, "seabed.nc"))


def write_seabed(out):
    dims = [("lat", len(SEABED_LAT)), ("lon", len(SEABED_LON))]
    values = [elevation(lat, lon) for lat in SEABED_LAT for lon in SEABED_LON]
    variables = [
        ("lat", [0], [("standard_name", "latitude"), ("units", "degrees_north")], 6, "d", SEABED_LAT),
        ("lon", [1], [("standard_name", "longitude"), ("units", "degrees_east")], 6, "d", SEABED_LON),
        ("elevation", [0, 1], [("standard_name", "height_above_mean_sea_level"), ("units", "m"), ("positive", "up")], 5, "f", values),
    ]
    title = "synthetic sloping, channelled seabed for the plumetrace site example"
    write_classic(out, dims, variables, 0, title)


def write_currents(out):
    dims = [("time", 0), ("depth", len(DEPTH)), ("lat", len(LAT)), ("lon", len(LON))]
    # (name, dim ids, attributes, type tag, struct code, values)
    variables = [
        ("depth", [1], [("standard_name", "depth"), ("units", "m"), ("positive", "down"), ("axis", "Z")], 6, "d", DEPTH),
        ("lat", [2], [("standard_name", "latitude"), ("units", "degrees_north")], 6, "d", LAT),
        ("lon", [3], [("standard_name", "longitude"), ("units", "degrees_east")], 6, "d", LON),
        ("time", [0], [("standard_name", "time"), ("units", "hours since 2026-06-01 00:00:00"), ("calendar", "standard")], 6, "d", HOURS),
        ("uo", [0, 1, 2, 3], [("standard_name", "eastward_sea_water_velocity"), ("units", "m s-1"), ("scale_factor", SCALE), ("add_offset", 0.0), ("_FillValue", FILL)], 3, "h", packed(0)),
        ("vo", [0, 1, 2, 3], [("standard_name", "northward_sea_water_velocity"), ("units", "m s-1"), ("scale_factor", SCALE), ("add_offset", 0.0), ("_FillValue", FILL)], 3, "h", packed(1)),
    ]
    title = "synthetic tidal coastal current for the plumetrace site example"
    write_classic(out, dims, variables, len(HOURS), title)


def write_classic(out, dims, variables, n_rec, title):
    """Writes a CDF-1 file: dims as (name, length; 0 for the record dimension), variables as
    (name, dim ids, attributes, type tag, struct code, values)."""
    size = {"d": 8, "f": 4, "h": 2}

    def slab(v):  # bytes of one record (record variables) or of the whole variable
        n = size[v[4]]
        for d in v[1]:
            if dims[d][1]:
                n *= dims[d][1]
        return n

    def header(begins):
        h = b"CDF\x01" + struct.pack(">i", n_rec)
        h += struct.pack(">ii", 0x0A, len(dims)) + b"".join(name(n) + struct.pack(">i", l) for n, l in dims)
        h += attrs([
            ("Conventions", "CF-1.8"),
            ("title", title),
            ("source", "examples/sites/make_currents.py"),
        ])
        h += struct.pack(">ii", 0x0B, len(variables))
        for v, begin in zip(variables, begins):
            h += name(v[0]) + struct.pack(">i", len(v[1])) + b"".join(struct.pack(">i", d) for d in v[1])
            h += attrs(v[2]) + struct.pack(">iii", v[3], (slab(v) + 3) // 4 * 4, begin)
        return h

    is_rec = [bool(v[1]) and dims[v[1][0]][1] == 0 for v in variables]
    length = len(header([0] * len(variables)))
    begins, at = [], length
    for v, r in zip(variables, is_rec):
        if not r:
            begins.append(at)
            at += (slab(v) + 3) // 4 * 4
        else:
            begins.append(None)
    rec_start = at
    for i, (v, r) in enumerate(zip(variables, is_rec)):
        if r:
            begins[i] = at
            at += (slab(v) + 3) // 4 * 4
    rec_size = at - rec_start
    body = bytearray(header(begins))
    for v, r in zip(variables, is_rec):
        if not r:
            body += struct.pack(">%d%s" % (len(v[5]), v[4]), *v[5])
            body += b"\0" * (-len(body) % 4)
    for rec in range(n_rec):
        for v, r in zip(variables, is_rec):
            if r:
                per = len(v[5]) // n_rec
                body += struct.pack(">%d%s" % (per, v[4]), *v[5][rec * per:(rec + 1) * per])
                body += b"\0" * (-len(body) % 4)
    assert len(body) == rec_start + n_rec * rec_size
    with open(out, "wb") as f:
        f.write(bytes(body))
    print("wrote %s (%d bytes)" % (out, len(body)))


if __name__ == "__main__":
    main()
