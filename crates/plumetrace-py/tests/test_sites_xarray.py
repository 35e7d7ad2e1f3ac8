"""`plumetrace.sites` with curvilinear and terrain-following currents built in xarray: the Python
route (``site_set``) gives the field the data say, and the same mission as the command line
reading the dataset written to NetCDF by xarray itself."""

import json

import numpy as np
import pytest

import plumetrace
from conftest import REPO, run_cli
from plumetrace.sites import site_set

xr = pytest.importorskip("xarray")
pytest.importorskip("scipy")

SITE = REPO / "examples" / "sites" / "site.toml"
LAT0, LON0 = 50.35, -4.15
WALL_CLOCK = {"wall_s", "real_time_factor", "spinup_wall_s", "stage_times"}
# A short mission without the meander, so the field is the file's alone.
SHORT = {
    "flow.meander": 0.0,
    "mission.time_limit_s": 300.0,
    "sim.duration_s": 300.0,
    "mission.spinup_s": 300.0,
}
# Hourly frames over the mission (which starts at 02:00, after its spin-up).
TIMES = np.array(["2026-06-01T00:00", "2026-06-01T01:00", "2026-06-01T02:00",
                  "2026-06-01T03:00", "2026-06-01T04:00"], dtype="datetime64[ns]")


def lon_lat(x, y):
    """Longitude and latitude of local east and north (a sphere's: the file's own values,
    which both routes read alike)."""
    lat = LAT0 + np.asarray(y) / 111_200.0
    lon = LON0 + np.asarray(x) / (111_200.0 * np.cos(np.radians(LAT0)))
    return lon, lat


def local(lon, lat):
    return ((lon - LON0) * 111_200.0 * np.cos(np.radians(LAT0)), (lat - LAT0) * 111_200.0)


def field(x, y, depth):
    """The current the datasets hold, east and north, m/s: steady, linear in depth below the
    surface (so a level's or a depth's interpolation is exact) and in position."""
    u = 0.12 + 0.0001 * y + 0.004 * depth
    v = -0.03 + 0.00008 * x - 0.002 * depth
    return u, v


def curvilinear():
    """A ROMS-like grid turned 20 deg about the site's origin (2-D lon_rho, lat_rho, no 1-D
    coordinates), 41 x 41 nodes 40 m apart, four depth levels."""
    a = np.radians(20.0)
    i, j = np.meshgrid(np.arange(41) * 40.0 - 800.0, np.arange(41) * 40.0 - 800.0)
    x, y = i * np.cos(a) - j * np.sin(a), i * np.sin(a) + j * np.cos(a)
    lon, lat = lon_lat(x, y)
    depths = np.array([2.0, 6.0, 10.0, 14.0])
    u, v = field(x[None, None], y[None, None], depths[None, :, None, None])
    shape = (TIMES.size, depths.size, 41, 41)
    u, v = np.broadcast_to(u, shape), np.broadcast_to(v, shape)
    dims = ("time", "depth", "eta_rho", "xi_rho")
    return xr.Dataset(
        {
            "u": (dims, u, {"standard_name": "eastward_sea_water_velocity", "units": "m s-1"}),
            "v": (dims, v, {"standard_name": "northward_sea_water_velocity", "units": "m s-1"}),
        },
        coords={
            "time": ("time", TIMES, {"standard_name": "time"}),
            "depth": ("depth", depths, {"standard_name": "depth", "units": "m",
                                        "positive": "down"}),
            "lon_rho": (("eta_rho", "xi_rho"), lon, {"standard_name": "longitude",
                                                     "units": "degrees_east"}),
            "lat_rho": (("eta_rho", "xi_rho"), lat, {"standard_name": "latitude",
                                                     "units": "degrees_north"}),
        },
        attrs={"Conventions": "CF-1.8"},
    )


def terrain_following():
    """ROMS's s-levels (ocean_s_coordinate_g2 with Cs_r, h, zeta, hc as formula terms) on a
    longitude/latitude grid: the water 20 m deep at the origin deepening 1 m per 100 m east,
    the surface 0.4 m up; each level's velocity is the field at its depth below the surface."""
    x = np.arange(-400.0, 961.0, 40.0)
    y = np.arange(-400.0, 401.0, 40.0)
    lon, _ = lon_lat(x, 0.0)
    _, lat = lon_lat(0.0, y)
    s = (np.arange(8) + 0.5) / 8.0 - 1.0
    cs = -(s ** 2)
    hc, eta = 5.0, 0.4
    h = np.broadcast_to(20.0 + 0.01 * x[None, :], (y.size, x.size))
    # CF g2: S = (hc s + h C) / (hc + h), z = eta + (eta + h) S; depth below the surface eta - z.
    S = (hc * s[:, None, None] + h[None] * cs[:, None, None]) / (hc + h[None])
    depth = -(eta + h[None]) * S
    X, Y = np.meshgrid(x, y)
    u, v = field(X[None], Y[None], depth)
    shape = (TIMES.size, s.size, y.size, x.size)
    u, v = np.broadcast_to(u, shape), np.broadcast_to(v, shape)
    dims = ("time", "s_rho", "lat", "lon")
    return xr.Dataset(
        {
            "u": (dims, u, {"standard_name": "eastward_sea_water_velocity", "units": "m s-1"}),
            "v": (dims, v, {"standard_name": "northward_sea_water_velocity", "units": "m s-1"}),
            "Cs_r": (("s_rho",), cs),
            "hc": ((), hc, {"units": "m"}),
            "h": (("lat", "lon"), np.array(h), {"units": "m"}),
            "zeta": (("time", "lat", "lon"), np.full((TIMES.size, y.size, x.size), eta),
                     {"units": "m"}),
        },
        coords={
            "time": ("time", TIMES, {"standard_name": "time"}),
            "s_rho": ("s_rho", s, {"standard_name": "ocean_s_coordinate_g2", "positive": "up",
                                   "formula_terms": "s: s_rho C: Cs_r eta: zeta depth: h "
                                                    "depth_c: hc"}),
            "lat": ("lat", lat, {"standard_name": "latitude", "units": "degrees_north"}),
            "lon": ("lon", lon, {"standard_name": "longitude", "units": "degrees_east"}),
        },
        attrs={"Conventions": "CF-1.8"},
    )


DATASETS = {"curvilinear": curvilinear, "terrain_following": terrain_following}


@pytest.mark.parametrize("kind", sorted(DATASETS))
def test_the_python_route_gives_the_field_the_dataset_holds(kind, tmp_path):
    keys = site_set(DATASETS[kind](), directory=tmp_path)
    assert keys == {"flow.model": "gridded", "flow.file": str(tmp_path / "currents.nc")}
    plume = plumetrace.Plume(str(SITE), seed=1, set={**SHORT, **keys})
    # Over the op-area and the domain around it, at the scenario's 8 m (flow.netcdf.depth_m).
    px, py = np.meshgrid(np.arange(0.0, 521.0, 65.0), np.arange(-150.0, 151.0, 50.0))
    pts = np.column_stack([px.ravel(), py.ravel()])
    got = plume.flow(pts)
    # Where each point is in the dataset's own (spherical) frame: within a metre of the
    # reader's geodesy over the domain: 1.3e-4 m/s measured on a field this gentle.
    lon, lat = lon_lat(pts[:, 0], pts[:, 1])
    want = np.column_stack(field(*local(lon, lat), 8.0))
    assert got.shape == (pts.shape[0], 2)
    assert np.abs(got - want).max() < 5e-4, np.abs(got - want).max()
    # The field varies over the domain by far more than the tolerance.
    assert np.ptp(got[:, 0]) > 0.02 and np.ptp(got[:, 1]) > 0.03


@pytest.mark.parametrize("kind", sorted(DATASETS))
def test_the_python_route_flies_the_command_lines_mission_on_xarrays_file(kind, cli, tmp_path):
    ds = DATASETS[kind]()
    r = plumetrace.run(str(SITE), seed=4,
                       set={**SHORT, **site_set(ds, directory=tmp_path / "py")})
    # The same dataset written by xarray itself (not the package's writer) and read by the
    # command line.
    (tmp_path / "cli").mkdir()
    nc = tmp_path / "cli" / "currents.nc"
    ds.to_netcdf(nc, format="NETCDF3_64BIT", engine="scipy")
    sets = [f"--set={k}={json.dumps(v)}" for k, v in SHORT.items()]
    sets += ["--set=flow.model=\"gridded\"", f"--set=flow.file={json.dumps(str(nc))}"]
    out = tmp_path / "cli" / "run"
    run_cli(cli, "run", str(SITE), "--seed", "4", "--out", str(out), *sets)
    summary = json.loads((out / "summary.json").read_text())
    for k in WALL_CLOCK:
        summary.pop(k, None)
    assert r.summary == summary
    csv = np.genfromtxt(out / "trajectory.csv", delimiter=",", names=True, dtype=None,
                        encoding="utf-8")
    assert len(csv) == len(r.trajectory["t_s"])
    assert np.allclose(csv["true_x_m"], r.trajectory["true_x_m"], atol=0.006)
    assert np.allclose(csv["true_y_m"], r.trajectory["true_y_m"], atol=0.006)
