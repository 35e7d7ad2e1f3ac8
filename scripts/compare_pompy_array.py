"""pompy's `concentration_array_demo` against plumetrace's plume in the same set-up.

Run through compare_pompy_array.sh, which prepares the environment (pompy 0.1.1, numpy < 2.4,
scipy) and finds the plumetrace binary.

The set-up is pompy's own demo (pompy/demos.py, `concentration_array_demo`, read from the
installed package and checked at start): region x 0-100 m along a 1 m/s mean flow, y -25-25 m
across, a 21 x 11 wind grid, the source at (5, 0, 0), pompy's PlumeModel and WindModel defaults
(10 puffs/s of one unit each, 10 puffs at the start, at most 1000 live puffs, centre-relative
dispersion scale 2 in x, y and z, puff radius 0.0316 m growing as r^2 += 0.001 dt, corner noise
gain 2, damping 0.1, bandwidth 0.2 rad/s by Euler-Maruyama, diffusivities 20 m^2/s), dt 0.01 s,
a 10 s warm-up of wind and puffs together, then 200 frames of 50 steps (0.5 s) and on each the
concentration array at z = 0.01 m, 500 x 250 points (0.2 m) from pompy's
ConcentrationArrayGenerator (kernel cut at 3 radii). plumetrace runs its `pompy` preset with
`--set` overrides that give every one of these numbers (the list is printed; built from pompy's
own defaults), its time average over the same 200 frames, and filament snapshots at every frame.

Per seed (the seeds are the independent units; every statistic is a mean over seeds with its
standard error from the spread between seeds), for both models:
  (a) the width (standard deviation over y of the profile) of the time-averaged concentration
      profile across the flow at x = 25, 50 and 75 m;
  (b) the mean of the time-averaged concentration over the array region;
  (c) the cross-flow spread (standard deviation of y) of all live puffs at t = 20, 40, 60, 80,
      100 s (t from the start of the warm-up), and, as diagnostics, the spread of puffs within
      +-2.5 m of x = 25, 50, 75 m split into the spread about each frame's centre of those puffs
      (relative dispersion) and the spread of that centre between frames (meander);
  (d) the time average computed three ways: pompy's array generator (pompy only), plumetrace's
      own output grid (plumetrace only; points on the nodes 0, 0.2, ..., 100 m, a tenth of a
      metre from pompy's), and the exact sum of the puffs' Gaussians at pompy's array points
      (cell centres (i + 1/2) 0.2 m), the same code for both models' puffs. Model against model
      is compared on the exact sums; each display (generator, own grid) against its exact sum
      tells how much of a difference is rasterisation.

pompy's PlumeModel.update loops over puffs in Python (about a minute of CPU per 110 s seed).
`--pompy-update vectorised` (the default) replaces only that loop with numpy operations on the
same numbers in the same order (same random draws: the Poisson count, then three normals per
puff in puff order; the same cubic-spline wind; the same Euler update and region test); the
wind model, the array generator and everything else are pompy's own. `--verify-seeds K` steps
pompy's own loop alongside for the first K seeds and stops unless the puff arrays are the same
bits at every frame. `--pompy-update pompy` uses pompy's loop throughout.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import inspect
import json
import math
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import matplotlib

matplotlib.use("Agg")
from pompy import demos, models, processors  # noqa: E402

SLABS = (25.0, 50.0, 75.0)
SPREAD_TIMES = (20.0, 40.0, 60.0, 80.0, 100.0)
SLAB_HALF_WIDTH = 2.5
# The lines of pompy's concentration_array_demo whose numbers are copied below (checked at start).
DEMO_LINES = (
    "sim_region = models.Rectangle(x_min=0., x_max=100, y_min=-25., y_max=25.)",
    "wind_model = models.WindModel(sim_region, 21, 11, rng=rng)",
    "sim_region, (5., 0., 0.), wind_model, rng=rng)",
    "for t in np.arange(0, 10, dt):",
    "sim_region, 0.01, 500, 250, 1.)",
    "n_frame = int(t_max / (dt * steps_per_frame) + 0.5)",
)
REGION = (0.0, 100.0, -25.0, 25.0)
WIND_NX, WIND_NY = 21, 11
SOURCE = (5.0, 0.0, 0.0)
WARMUP_S = 10.0
ARRAY_Z, ARRAY_NX, ARRAY_NY, PUFF_AMOUNT = 0.01, 500, 250, 1.0


def defaults(f):
    return {k: p.default for k, p in inspect.signature(f).parameters.items()
            if p.default is not inspect.Parameter.empty}


def demo_setup():
    """The demo's numbers: its keyword defaults and the literals of its body (checked)."""
    src = inspect.getsource(demos.concentration_array_demo)
    missing = [line for line in DEMO_LINES if line not in src]
    if missing:
        sys.exit(f"pompy's concentration_array_demo is not the one this script copies: {missing}")
    d = defaults(demos.concentration_array_demo)
    dt, t_max, spf = d["dt"], d["t_max"], d["steps_per_frame"]
    return {
        "dt": dt, "t_max": t_max, "steps_per_frame": spf, "default_seed": d["seed"],
        "warmup_steps": len(np.arange(0, WARMUP_S, dt)),
        "frames": int(t_max / (dt * spf) + 0.5),
        "plume": defaults(models.PlumeModel.__init__),
        "wind": defaults(models.WindModel.__init__),
    }


# --- pompy -------------------------------------------------------------------------------------

def build_pompy(seed):
    """The demo's models, built exactly as the demo builds them."""
    rng = np.random.RandomState(seed)
    region = models.Rectangle(x_min=REGION[0], x_max=REGION[1], y_min=REGION[2], y_max=REGION[3])
    wind = models.WindModel(region, WIND_NX, WIND_NY, rng=rng)
    plume = models.PlumeModel(region, SOURCE, wind, rng=rng)
    return wind, plume


class VectorisedPlume:
    """pompy's PlumeModel.update with the per-puff loop done on arrays (see the module doc)."""

    def __init__(self, plume):
        self.rng = plume.rng
        self.wind = plume.wind_model
        self.region = plume.sim_region
        self.scale = plume.centre_rel_diff_scale
        self.new = tuple(float(v) for v in plume._new_puff_params)
        self.spread = plume.puff_spread_rate
        self.rate = plume.puff_release_rate
        self.max = plume.max_num_puffs
        assert plume.model_z_disp
        arr = np.array([tuple(p) for p in plume.puffs], dtype=float).reshape(-1, 4)
        self.x, self.y, self.z, self.r = (arr[:, k].copy() for k in range(4))

    def update(self, dt):
        n = len(self.x)
        if n < self.max:
            k = min(self.rng.poisson(self.rate * dt), self.max - n)
            if k:
                cols = (self.x, self.y, self.z, self.r)
                self.x, self.y, self.z, self.r = (np.concatenate([c, np.full(k, v)])
                                                  for c, v in zip(cols, self.new))
        n = len(self.x)
        if n == 0:
            return
        w = self.wind
        if not w._interp_set:
            w._set_interpolators()
        u = w._interp_u(self.x, self.y, grid=False)
        v = w._interp_v(self.x, self.y, grid=False)
        noise = self.rng.normal(size=(n, 3)) * self.scale
        self.x = self.x + (u + noise[:, 0]) * dt
        self.y = self.y + (v + noise[:, 1]) * dt
        self.z = self.z + (0.0 + noise[:, 2]) * dt
        self.r = self.r + self.spread * dt
        g = self.region
        keep = (self.x >= g.x_min) & (self.x <= g.x_max) & (self.y >= g.y_min) & (self.y <= g.y_max)
        if not keep.all():
            self.x, self.y, self.z, self.r = self.x[keep], self.y[keep], self.z[keep], self.r[keep]

    @property
    def puff_array(self):
        return np.column_stack([self.x, self.y, self.z, self.r])


def puffs_of(plume):
    """(n, 4) puff array of either model (pompy's own returns shape (0,) when empty)."""
    return np.asarray(plume.puff_array, dtype=float).reshape(-1, 4)


def pompy_seed(seed, setup, update, verify):
    """One seed of the demo: the per-seed statistics, the generator's time average and the
    exact sums; with `verify`, pompy's own update is stepped alongside and compared."""
    dt, spf = setup["dt"], setup["steps_per_frame"]
    wind, plume = build_pompy(seed)
    model = VectorisedPlume(plume) if update == "vectorised" else plume
    twin = build_pompy(seed) if verify else None
    cpu = {"step": 0.0, "generator": 0.0, "exact": 0.0, "verify": 0.0}
    region = models.Rectangle(*REGION)
    gen = processors.ConcentrationArrayGenerator(region, ARRAY_Z, ARRAY_NX, ARRAY_NY, PUFF_AMOUNT)
    acc = Accumulator(setup)
    gen_sum = np.zeros((ARRAY_NX, ARRAY_NY))

    def step():
        t0 = time.process_time()
        wind.update(dt)
        model.update(dt)
        cpu["step"] += time.process_time() - t0
        if twin:
            t0 = time.process_time()
            twin[0].update(dt)
            twin[1].update(dt)
            cpu["verify"] += time.process_time() - t0

    for _ in range(setup["warmup_steps"]):
        step()
    for i in range(setup["frames"]):
        for _ in range(spf):
            step()
        arr = puffs_of(model)
        if twin is not None:
            ref = puffs_of(twin[1])
            if arr.shape != ref.shape or not np.array_equal(arr, ref):
                sys.exit(f"seed {seed}: the vectorised update differs from pompy's at frame {i}")
        t_s = WARMUP_S + (i + 1) * spf * dt
        t0 = time.process_time()
        gen_sum += gen.generate_single_array(arr)
        cpu["generator"] += time.process_time() - t0
        t0 = time.process_time()
        acc.add(t_s, arr)
        cpu["exact"] += time.process_time() - t0
    out = acc.result()
    gen_mean = gen_sum / setup["frames"]
    out["generator"] = array_stats(gen_mean, array_x(), array_y())
    out["cpu_s"] = cpu
    out["seed"] = seed
    out["verified"] = bool(verify)
    return out


# --- the array and the exact sums --------------------------------------------------------------

def array_x():
    """pompy's array points along x: cell centres (i + 1/2) dx (see the module doc)."""
    dx = (REGION[1] - REGION[0]) / ARRAY_NX
    return REGION[0] + (np.arange(ARRAY_NX) + 0.5) * dx


def array_y():
    dy = (REGION[3] - REGION[2]) / ARRAY_NY
    return REGION[2] + (np.arange(ARRAY_NY) + 0.5) * dy


def slab_columns(xs, x):
    """Indices of the array columns whose average is the profile at x: the nearest column, or
    the two equally near (pompy's cell centres straddle 25, 50 and 75 m)."""
    d = np.abs(xs - x)
    near = np.flatnonzero(d <= d.min() + 1e-9)
    return near


def profile_width(prof, ys):
    """Standard deviation over y of a non-negative profile."""
    s = prof.sum()
    if s <= 0:
        return float("nan")
    m = (prof * ys).sum() / s
    return float(np.sqrt(max((prof * (ys - m) ** 2).sum() / s, 0.0)))


def array_stats(mean_array, xs, ys):
    """Profiles, widths and region mean of a time-averaged array indexed [ix, iy]."""
    out = {"region_mean": float(mean_array.mean()), "profiles": {}, "widths": {}}
    for x in SLABS:
        cols = slab_columns(xs, x)
        prof = mean_array[cols, :].mean(axis=0)
        out["profiles"][str(x)] = prof.tolist()
        out["widths"][str(x)] = profile_width(prof, ys)
    return out


class Accumulator:
    """Per-seed statistics from the frames' puff arrays: exact sums at pompy's array points
    (profile columns and region mean), puff spreads at fixed times, slab moments, live puffs."""

    A = 1.0 / (8 * np.pi ** 3) ** 0.5

    def __init__(self, setup):
        self.xs, self.ys = array_x(), array_y()
        self.cols = {x: slab_columns(self.xs, x) for x in SLABS}
        self.col_x = np.concatenate([self.xs[self.cols[x]] for x in SLABS])
        self.col_sum = np.zeros((len(self.col_x), ARRAY_NY))
        self.region_sum = 0.0
        self.frames = 0
        self.live = []
        self.spread_at = {}
        # Per slab: within-frame spread about the frame's slab centre (pooled) and the frame
        # centres (for the meander), weighted by the puffs in the slab.
        self.slab = {x: {"n": 0, "ss_within": 0.0, "centres": [], "weights": []} for x in SLABS}

    def add(self, t_s, arr):
        self.frames += 1
        self.live.append(len(arr))
        for t in SPREAD_TIMES:
            if abs(t_s - t) < 1e-6:
                self.spread_at[str(t)] = float(arr[:, 1].std()) if len(arr) > 1 else float("nan")
        if len(arr) == 0:
            return
        px, py, pz, r2 = arr.T
        for x in SLABS:
            ys = py[np.abs(px - x) <= SLAB_HALF_WIDTH]
            if len(ys) >= 2:
                s = self.slab[x]
                c = ys.mean()
                s["n"] += len(ys)
                s["ss_within"] += float(((ys - c) ** 2).sum())
                s["centres"].append(float(c))
                s["weights"].append(len(ys))
        amp = self.A / r2 ** 1.5 * np.exp(-(ARRAY_Z - pz) ** 2 / (2 * r2))
        inv = -0.5 / r2
        gy = np.exp((self.ys[:, None] - py[None, :]) ** 2 * inv[None, :])  # (ny, n)
        gx_cols = np.exp((self.col_x[:, None] - px[None, :]) ** 2 * inv[None, :])  # (cols, n)
        self.col_sum += (gx_cols * amp[None, :]) @ gy.T
        # The region sum is separable: sum_p amp_p (sum_i gx_pi) (sum_j gy_pj). Only the array
        # points within 12 radii of a puff contribute above 1e-31 of its peak; summing all is
        # simpler and still cheap.
        gx_all = np.exp((self.xs[:, None] - px[None, :]) ** 2 * inv[None, :])
        self.region_sum += float((amp * gx_all.sum(axis=0) * gy.sum(axis=0)).sum())

    def result(self):
        n = max(self.frames, 1)
        out = {"live_mean": float(np.mean(self.live)) if self.live else 0.0,
               "spread_at": self.spread_at}
        col_mean = self.col_sum / n
        exact = {"region_mean": self.region_sum / n / (ARRAY_NX * ARRAY_NY),
                 "profiles": {}, "widths": {}}
        k = 0
        for x in SLABS:
            m = len(self.cols[x])
            prof = col_mean[k:k + m].mean(axis=0)
            k += m
            exact["profiles"][str(x)] = prof.tolist()
            exact["widths"][str(x)] = profile_width(prof, self.ys)
        out["exact"] = exact
        slab = {}
        for x in SLABS:
            s = self.slab[x]
            if s["n"] == 0:
                continue
            w = np.asarray(s["weights"], float)
            c = np.asarray(s["centres"])
            cm = (w * c).sum() / w.sum()
            slab[str(x)] = {"relative": math.sqrt(s["ss_within"] / s["n"]),
                            "meander": float(np.sqrt((w * (c - cm) ** 2).sum() / w.sum())),
                            "puffs_per_frame": s["n"] / n}
        out["slab"] = slab
        return out


# --- plumetrace --------------------------------------------------------------------------------

def compass_toward_deg(u, v):
    return math.degrees(math.atan2(u, v)) % 360.0


def plumetrace_overrides(setup):
    """`--set` overrides of the `pompy` preset that give the demo's set-up, from pompy's own
    defaults."""
    p, w = setup["plume"], setup["wind"]
    dt = setup["dt"]
    scale = p["centre_rel_diff_scale"]
    if hasattr(scale, "__len__"):
        sys.exit("an anisotropic centre_rel_diff_scale has no plumetrace key")
    if not p["model_z_disp"]:
        sys.exit("model_z_disp = False has no plumetrace key")
    rate = float(p["puff_release_rate"])
    sets = [
        ("sim.dt_s", dt),
        ("sim.duration_s", WARMUP_S + setup["frames"] * setup["steps_per_frame"] * dt),
        ("domain.x_min_m", REGION[0]), ("domain.x_max_m", REGION[1]),
        ("domain.y_min_m", REGION[2]), ("domain.y_max_m", REGION[3]),
        ("flow.mean.speed_mps", math.hypot(w["u_av"], w["v_av"])),
        ("flow.mean.toward_deg", compass_toward_deg(w["u_av"], w["v_av"])),
        ("flow.farrell.nx", WIND_NX), ("flow.farrell.ny", WIND_NY),
        ("flow.farrell.diffusivity_x_m2ps", w["k_x"]), ("flow.farrell.diffusivity_y_m2ps", w["k_y"]),
        ("flow.farrell.noise_gain", w["noise_gain"]),
        ("flow.farrell.noise_damping", w["noise_damp"]),
        ("flow.farrell.noise_bandwidth_radps", w["noise_bandwidth"]),
        ("flow.farrell.original_noise_updates", bool(w["use_original_noise_updates"])),
        ("flow.farrell.noise_scheme", "euler"),
        ("flow.farrell.step_s", 0.0),
        ("plume.model", "filaments"),
        ("plume.pompy_compatible", True),
        ("plume.pompy_diff_scale_mps", float(scale)),
        ("plume.init_radius_m", p["puff_init_rad"]),
        ("plume.growth_rate_m2ps", p["puff_spread_rate"]),
        ("plume.initial_filaments", p["init_num_puffs"]),
        ("plume.max_filaments", p["max_num_puffs"]),
        ("plume.seabed", "none"),
        ("sources.0.x_m", SOURCE[0]), ("sources.0.y_m", SOURCE[1]), ("sources.0.z_m", SOURCE[2]),
        ("sources.0.mass_rate_per_s", rate * PUFF_AMOUNT),
        ("sources.0.filament_rate_hz", rate),
        ("output.nx", ARRAY_NX + 1), ("output.ny", ARRAY_NY + 1), ("output.z_m", ARRAY_Z),
        ("output.average_start_s", WARMUP_S + setup["steps_per_frame"] * dt),
        ("output.average_interval_s", setup["steps_per_frame"] * dt),
        ("output.filaments_interval_s", setup["steps_per_frame"] * dt),
    ]
    return [f"{k}={toml_value(v)}" for k, v in sets]


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(float(v))
    return json.dumps(v)


def plumetrace_seed(exe, seed, setup, sets, workdir):
    out = os.path.join(workdir, f"seed-{seed}")
    args = [exe, "run", "--preset", "pompy", "--seed", str(seed), "--out", out]
    for s in sets:
        args += ["--set", s]
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    t0 = time.time()
    subprocess.run(args, check=True, capture_output=True, text=True, env=env)
    run_s = time.time() - t0
    t0 = time.process_time()
    with open(os.path.join(out, "stats.json")) as f:
        stats = json.load(f)
    first = WARMUP_S + setup["steps_per_frame"] * setup["dt"]
    ser = np.loadtxt(os.path.join(out, "filament_series.csv"), delimiter=",", skiprows=1, ndmin=2)
    acc = Accumulator(setup)
    times = ser[:, 0]
    bounds = np.flatnonzero(np.diff(times)) + 1
    starts = np.concatenate([[0], bounds])
    ends = np.concatenate([bounds, [len(times)]])
    frame_times = []
    for a, b in zip(starts, ends):
        t_s = times[a]
        if t_s < first - 1e-6:
            continue
        frame_times.append(t_s)
        f = ser[a:b]
        acc.add(t_s, np.column_stack([f[:, 1], f[:, 2], f[:, 3], f[:, 4] ** 2]))
    if len(frame_times) != setup["frames"]:
        sys.exit(f"plumetrace seed {seed}: {len(frame_times)} filament snapshots in the window, "
                 f"expected {setup['frames']}")
    res = acc.result()
    grid = np.loadtxt(os.path.join(out, "snapshot.csv"), delimiter=",", skiprows=1, usecols=(3,))
    mean = grid.reshape(ARRAY_NY + 1, ARRAY_NX + 1).T  # [ix, iy]
    gx = np.linspace(REGION[0], REGION[1], ARRAY_NX + 1)
    gy = np.linspace(REGION[2], REGION[3], ARRAY_NY + 1)
    res["own_grid"] = array_stats(mean, gx, gy)
    res["own_grid"]["samples"] = stats["mean_samples"]
    res["filament_stats"] = stats["filaments"]
    res["cpu_s"] = {"run_wall": run_s, "analysis": time.process_time() - t0}
    res["seed"] = seed
    shutil.rmtree(out, ignore_errors=True)
    if stats["mean_samples"] != setup["frames"]:
        sys.exit(f"plumetrace seed {seed}: {stats['mean_samples']} samples in the time average, "
                 f"expected {setup['frames']}")
    return res


# --- statistics --------------------------------------------------------------------------------

def mean_se(values):
    v = np.asarray([x for x in values if x == x], float)
    if len(v) == 0:
        return float("nan"), float("nan"), 0
    if len(v) < 2:
        return float(v[0]), float("nan"), 1
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v))), len(v)


def ratio(a, ase, b, bse):
    """a / b - 1 and its standard error (first order; a and b independent)."""
    if not (b > 0 and a > 0):
        return float("nan"), float("nan")
    r = a / b
    return r - 1, r * math.sqrt((ase / a) ** 2 + (bse / b) ** 2)


def paired_ratio(num, den):
    """Mean over seeds of num / den - 1 (the same seeds' two readings) and its standard error."""
    return mean_se([n / d - 1 for n, d in zip(num, den) if d > 0])


def fmt(m, se, d=2):
    return f"{m:.{d}f} +- {se:.{d}f}"


def diff_row(label, pv, rv, d=2):
    pm, pse, pn = mean_se(pv)
    rm, rse, rn = mean_se(rv)
    diff, dse = ratio(rm, rse, pm, pse)
    z = diff / dse if dse and dse == dse and dse > 0 else float("nan")
    print(f"| {label} | {fmt(pm, pse, d)} | {fmt(rm, rse, d)} | {100 * diff:+.1f} % +- {100 * dse:.1f} % "
          f"| {z:+.1f} |")
    return {"label": label, "pompy": [pm, pse, pn], "plumetrace": [rm, rse, rn],
            "diff": [diff, dse], "z": z}


def jackknife_width(profiles, ys):
    """Width of the seeds' mean profile and its jackknife standard error."""
    p = np.asarray(profiles)
    n = len(p)
    full = profile_width(p.mean(axis=0), ys)
    if n < 2:
        return full, float("nan")
    tot = p.sum(axis=0)
    loo = np.array([profile_width((tot - p[k]) / (n - 1), ys) for k in range(n)])
    return full, float(math.sqrt((n - 1) / n * ((loo - loo.mean()) ** 2).sum()))


def width_rows(pres, rres, pkey, rkey, what):
    """Rows (a): the profile's width at each of SLABS, pompy's `pkey` against plumetrace's `rkey`."""
    return [diff_row(f"(a) {what} at x = {x:.0f} m (m)",
                     [p[pkey]["widths"][str(x)] for p in pres],
                     [r[rkey]["widths"][str(x)] for r in rres]) for x in SLABS]


def region_row(pres, rres, pkey, rkey):
    """Row (b): the mean over the array region, pompy's `pkey` against plumetrace's `rkey`."""
    return diff_row("(b) mean over the array region", [p[pkey]["region_mean"] for p in pres],
                    [r[rkey]["region_mean"] for r in rres], 4)


def report(pres, rres, setup):
    rows = []
    ys = array_y()
    print(f"\n## Model against model ({len(pres)} pompy seeds, {len(rres)} plumetrace seeds): "
          "exact sums of the puffs at pompy's array points")
    print("\nMean over seeds +- standard error; difference = plumetrace / pompy - 1 +- its standard "
          "error; z = difference / its standard error.\n")
    print("| statistic | pompy | plumetrace | difference | z |")
    print("|---|---|---|---|---|")
    rows += width_rows(pres, rres, "exact", "exact", "width of the time-averaged profile")
    for x in SLABS:
        k = str(x)
        pw, pse = jackknife_width([p["exact"]["profiles"][k] for p in pres], ys)
        rw, rse = jackknife_width([r["exact"]["profiles"][k] for r in rres], ys)
        diff, dse = ratio(rw, rse, pw, pse)
        print(f"| (a') width of the seeds' mean profile at x = {x:.0f} m (m; jackknife) | {fmt(pw, pse)} "
              f"| {fmt(rw, rse)} | {100 * diff:+.1f} % +- {100 * dse:.1f} % | {diff / dse:+.1f} |")
        rows.append({"label": f"(a') mean-profile width x={x:.0f}", "pompy": [pw, pse],
                     "plumetrace": [rw, rse], "diff": [diff, dse], "z": diff / dse})
    rows.append(region_row(pres, rres, "exact", "exact"))
    for t in SPREAD_TIMES:
        k = str(t)
        rows.append(diff_row(f"(c) cross-flow spread of all puffs at t = {t:.0f} s (m)",
                             [p["spread_at"].get(k, float("nan")) for p in pres],
                             [r["spread_at"].get(k, float("nan")) for r in rres]))
    for x in SLABS:
        k = str(x)
        rows.append(diff_row(f"(c') puffs within 2.5 m of x = {x:.0f} m: spread about the frame's "
                             "centre (m)",
                             [p["slab"][k]["relative"] for p in pres if k in p["slab"]],
                             [r["slab"][k]["relative"] for r in rres if k in r["slab"]]))
        rows.append(diff_row(f"(c') puffs within 2.5 m of x = {x:.0f} m: meander of that centre (m)",
                             [p["slab"][k]["meander"] for p in pres if k in p["slab"]],
                             [r["slab"][k]["meander"] for r in rres if k in r["slab"]]))
    rows.append(diff_row("live puffs (mean over frames)", [p["live_mean"] for p in pres],
                         [r["live_mean"] for r in rres], 1))

    print("\n## As displayed: pompy's array generator against plumetrace's own output grid\n")
    print("| statistic | pompy (generator) | plumetrace (own grid) | difference | z |")
    print("|---|---|---|---|---|")
    rows += width_rows(pres, rres, "generator", "own_grid", "width")
    rows.append(region_row(pres, rres, "generator", "own_grid"))

    print("\n## (d) Each display against the exact sum of its own puffs (same seeds, paired)\n")
    print("| statistic | pompy: generator / exact - 1 | plumetrace: own grid / exact - 1 |")
    print("|---|---|---|")
    for x in SLABS:
        k = str(x)
        pm, pse, _ = paired_ratio([p["generator"]["widths"][k] for p in pres],
                                  [p["exact"]["widths"][k] for p in pres])
        rm, rse, _ = paired_ratio([r["own_grid"]["widths"][k] for r in rres],
                                  [r["exact"]["widths"][k] for r in rres])
        print(f"| width at x = {x:.0f} m | {100 * pm:+.2f} % +- {100 * pse:.2f} % "
              f"| {100 * rm:+.2f} % +- {100 * rse:.2f} % |")
        rows.append({"label": f"(d) width x={x:.0f}", "pompy_gen_over_exact": [pm, pse],
                     "plumetrace_grid_over_exact": [rm, rse]})
    for x in SLABS:
        k = str(x)
        pm, pse, _ = paired_ratio([sum(p["generator"]["profiles"][k]) for p in pres],
                                  [sum(p["exact"]["profiles"][k]) for p in pres])
        rm, rse, _ = paired_ratio([sum(r["own_grid"]["profiles"][k]) * 0.2 for r in rres],
                                  [sum(r["exact"]["profiles"][k]) * 0.2 for r in rres])
        print(f"| profile integral across y at x = {x:.0f} m | {100 * pm:+.2f} % +- {100 * pse:.2f} % "
              f"| {100 * rm:+.2f} % +- {100 * rse:.2f} % |")
    pm, pse, _ = paired_ratio([p["generator"]["region_mean"] for p in pres],
                              [p["exact"]["region_mean"] for p in pres])
    rm, rse, _ = paired_ratio([r["own_grid"]["region_mean"] for r in rres],
                              [r["exact"]["region_mean"] for r in rres])
    print(f"| mean over the array region | {100 * pm:+.2f} % +- {100 * pse:.2f} % "
          f"| {100 * rm:+.2f} % +- {100 * rse:.2f} % |")
    rows.append({"label": "(d) region mean", "pompy_gen_over_exact": [pm, pse],
                 "plumetrace_grid_over_exact": [rm, rse]})
    return rows


# --- diagnostics of the displays (--diagnose) -----------------------------------------------

def corrected_kernel(self, shift_x, shift_y, z_offset, r_sq, even_w, even_h):
    """pompy's ConcentrationArrayGenerator._puff_kernel with its two offset errors corrected:
    the array point k of a kernel of w points lies (k - (w - 1) / 2) cells from the nearest
    (half-)grid point u (pompy's np.mgrid[-w // 2:w // 2] + 0.5 puts odd kernels half a cell
    off), and the puff lies (p - u) cells from u, to be subtracted (pompy adds it)."""
    shape = (2 * (r_sq * self.kernel_rad_mult ** 2 - z_offset ** 2) ** 0.5
             / np.array([self.dx, self.dy]))
    w = self._round_up_to_next_even_or_odd(shape[0], even_w)
    h = self._round_up_to_next_even_or_odd(shape[1], even_h)
    kx = (np.arange(w) - (w - 1) / 2.0) * self.dx - shift_x
    ky = (np.arange(h) - (h - 1) / 2.0) * self.dy - shift_y
    r_sq_grid = kx[:, None] ** 2 + ky[None, :] ** 2 + z_offset ** 2
    return (self._ampl_const / r_sq ** 1.5) * np.exp(-r_sq_grid / (2 * r_sq))


class CorrectedGenerator(processors.ConcentrationArrayGenerator):
    _puff_kernel = corrected_kernel


def exact_x_sums(arr, xs, ys):
    """Per array column x, the sum over y of the exact concentration of the puffs `arr`."""
    px, py, pz, r2 = arr.T
    amp = Accumulator.A / r2 ** 1.5 * np.exp(-(ARRAY_Z - pz) ** 2 / (2 * r2))
    out = np.zeros(len(xs))
    for lo in range(0, len(px), 20000):
        sl = slice(lo, lo + 20000)
        gx = np.exp(-(xs[:, None] - px[None, sl]) ** 2 / (2 * r2[None, sl]))
        gy = np.exp(-(ys[:, None] - py[None, sl]) ** 2 / (2 * r2[None, sl])).sum(axis=0)
        out += gx @ (amp[sl] * gy)
    return out


BANDS = ((0.0, 5.0), (5.0, 7.5), (7.5, 10.0), (10.0, 15.0), (15.0, 25.0), (25.0, 50.0), (50.0, 100.0))


def in_band(xs, lo, hi):
    return (xs >= lo) & ((xs < hi) | (hi == REGION[1]))


def diagnose(exe, setup, sets, seeds=4):
    xs, ys = array_x(), array_y()
    region = models.Rectangle(*REGION)
    gens = (processors.ConcentrationArrayGenerator(region, ARRAY_Z, ARRAY_NX, ARRAY_NY, PUFF_AMOUNT),
            CorrectedGenerator(region, ARRAY_Z, ARRAY_NX, ARRAY_NY, PUFF_AMOUNT))
    rng = np.random.RandomState(1)
    p = setup["plume"]
    r0, gamma = p["puff_init_rad"], p["puff_spread_rate"]
    print("## Single puffs on pompy's array: 1000 puffs per radius within 1 m of (50, 0), "
          "height within 2.5 radii of the array\n")
    print("| puff radius (m) | age (s) | pompy's generator / exact | offsets corrected / exact "
          "| centroid error, pompy (m) | centroid error, corrected (m) |")
    print("|---|---|---|---|---|---|")
    for r in (r0, 0.04, 0.05, 0.07, 0.1, 0.15, 0.2, 0.3):
        sums = [[0.0, []], [0.0, []]]
        ex_sum = 0.0
        for _ in range(1000):
            x, y = 50 + rng.uniform(-1, 1), rng.uniform(-1, 1)
            z = ARRAY_Z + rng.uniform(-1, 1) * 2.5 * r
            arr = np.array([[x, y, z, r * r]])
            ex_sum += exact_x_sums(arr, xs, ys).sum()
            for k, g in enumerate(gens):
                a = g.generate_single_array(arr)
                sums[k][0] += a.sum()
                if a.sum() > 0:
                    sums[k][1].append(math.hypot((a.sum(1) * xs).sum() / a.sum() - x,
                                                 (a.sum(0) * ys).sum() / a.sum() - y))
        print(f"| {r:.4f} | {(r * r - r0 * r0) / gamma:.0f} | {sums[0][0] / ex_sum:.3f} "
              f"| {sums[1][0] / ex_sum:.3f} | {np.mean(sums[0][1]):.3f} | {np.mean(sums[1][1]):.3f} |",
              flush=True)

    dt, spf = setup["dt"], setup["steps_per_frame"]
    gen_x = np.zeros(len(xs))
    ex_x = np.zeros(len(xs))
    for k in range(seeds):
        wind, plume = build_pompy(setup["default_seed"] + k)
        m = VectorisedPlume(plume)
        for _ in range(setup["warmup_steps"]):
            wind.update(dt)
            m.update(dt)
        for _ in range(setup["frames"]):
            for _ in range(spf):
                wind.update(dt)
                m.update(dt)
            arr = m.puff_array
            gen_x += gens[0].generate_single_array(arr).sum(axis=1)
            ex_x += exact_x_sums(arr, xs, ys)
    print(f"\n## Where pompy's generator loses its share: pompy seeds {setup['default_seed']}.."
          f"{setup['default_seed'] + seeds - 1}, the demo's 200 frames\n")
    print("| x (m) | share of the exact sum over the region | generator / exact - 1 |")
    print("|---|---|---|")
    for lo, hi in BANDS + ((REGION[0], REGION[1]),):
        b = in_band(xs, lo, hi)
        print(f"| {lo:g}-{hi:g} | {100 * ex_x[b].sum() / ex_x.sum():.1f} % "
              f"| {100 * (gen_x[b].sum() / ex_x[b].sum() - 1):+.1f} % |", flush=True)

    nx_ = np.linspace(REGION[0], REGION[1], ARRAY_NX + 1)
    ny_ = np.linspace(REGION[2], REGION[3], ARRAY_NY + 1)
    grid_x, nodes_x, centres_x = np.zeros(len(nx_)), np.zeros(len(nx_)), np.zeros(len(xs))
    first = WARMUP_S + spf * dt
    with tempfile.TemporaryDirectory() as work:
        for s in range(1, seeds + 1):
            out = os.path.join(work, str(s))
            args = [exe, "run", "--preset", "pompy", "--seed", str(s), "--out", out]
            for o in sets:
                args += ["--set", o]
            subprocess.run(args, check=True, capture_output=True, env=dict(os.environ, RAYON_NUM_THREADS="1"))
            g = np.loadtxt(os.path.join(out, "snapshot.csv"), delimiter=",", skiprows=1, usecols=(3,))
            grid_x += g.reshape(ARRAY_NY + 1, ARRAY_NX + 1).T.sum(axis=1)
            ser = np.loadtxt(os.path.join(out, "filament_series.csv"), delimiter=",", skiprows=1)
            ser = ser[ser[:, 0] >= first - 1e-6]
            frames = len(np.unique(ser[:, 0]))
            arr = np.column_stack([ser[:, 1], ser[:, 2], ser[:, 3], ser[:, 4] ** 2])
            nodes_x += exact_x_sums(arr, nx_, ny_) / frames
            centres_x += exact_x_sums(arr, xs, ys) / frames
    print(f"\n## plumetrace's own grid (nodes 0, 0.2, ..., 100 m; cut-off 3 radii): plumetrace seeds "
          f"1..{seeds}\n")
    print("| x (m) | own grid / exact sum at its nodes - 1 | exact at its nodes / exact at pompy's "
          "cell centres - 1 (per point) |")
    print("|---|---|---|")
    for lo, hi in BANDS + ((REGION[0], REGION[1]),):
        bn, bc = in_band(nx_, lo, hi), in_band(xs, lo, hi)
        per_node = nodes_x[bn].sum() / (bn.sum() * len(ny_))
        per_centre = centres_x[bc].sum() / (bc.sum() * len(ys))
        print(f"| {lo:g}-{hi:g} | {100 * (grid_x[bn].sum() / nodes_x[bn].sum() - 1):+.1f} % "
              f"| {100 * (per_node / per_centre - 1):+.1f} % |")



def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plumetrace", required=True, help="the plumetrace binary")
    ap.add_argument("--quick", action="store_true", help="2 pompy and 4 plumetrace seeds")
    ap.add_argument("--pompy-seeds", type=int, default=None)
    ap.add_argument("--plumetrace-seeds", type=int, default=None)
    ap.add_argument("--pompy-update", choices=("vectorised", "pompy"), default="vectorised")
    ap.add_argument("--verify-seeds", type=int, default=1,
                    help="seeds on which pompy's own update runs alongside the vectorised one")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="an extra plumetrace override, after the set-up's (a variant)")
    ap.add_argument("--json", help="write every seed's numbers and the table here")
    ap.add_argument("--diagnose", action="store_true",
                    help="only the displays' diagnostics: single puffs on pompy's generator as it "
                         "is and with its offsets corrected, and by bands of x the generator and "
                         "plumetrace's own grid against exact sums (4 seeds each, about a minute)")
    ap.add_argument("--reuse-pompy", metavar="JSON",
                    help="take pompy's seeds from an earlier --json instead of running pompy "
                         "(to compare plumetrace variants, --set, against the same pompy seeds)")
    a = ap.parse_args()
    setup = demo_setup()
    sets = plumetrace_overrides(setup) + a.set
    if a.diagnose:
        diagnose(a.plumetrace, setup, sets)
        return 0
    reused = None
    if a.reuse_pompy:
        with open(a.reuse_pompy) as f:
            reused = json.load(f)["pompy"]
    n_pompy = 0 if reused else a.pompy_seeds or (2 if a.quick else 200)
    n_pt = a.plumetrace_seeds or (4 if a.quick else 4 * (len(reused) if reused else n_pompy))
    if reused:
        print(f"# pompy's concentration_array_demo: pompy {len(reused)} seeds from {a.reuse_pompy}, "
              f"plumetrace {n_pt} seeds (1..{n_pt})")
    else:
        checked = ""
        if a.pompy_update == "vectorised" and a.verify_seeds:
            checked = f", checked against pompy's own loop on {min(a.verify_seeds, n_pompy)} seed(s)"
        print(f"# pompy's concentration_array_demo: pompy {n_pompy} seeds ({setup['default_seed']} + k; "
              f"update: {a.pompy_update}{checked}), plumetrace {n_pt} seeds (1..{n_pt})")
    print(f"dt {setup['dt']} s, warm-up {setup['warmup_steps']} steps, {setup['frames']} frames of "
          f"{setup['steps_per_frame']} steps")
    print("plumetrace: run --preset pompy " + " ".join(f"--set {s}" for s in sets), flush=True)
    t_start = time.time()
    pres = list(reused or [])
    for k in range(n_pompy):
        seed = setup["default_seed"] + k
        verify = a.pompy_update == "vectorised" and k < a.verify_seeds
        r = pompy_seed(seed, setup, a.pompy_update, verify)
        pres.append(r)
        c = r["cpu_s"]
        check = f", pompy's own loop alongside {c['verify']:.1f} s (same bits)" if verify else ""
        print(f"pompy seed {seed}: CPU step {c['step']:.1f} s, generator {c['generator']:.1f} s, exact sums "
              f"{c['exact']:.1f} s{check}; live {r['live_mean']:.0f}", flush=True)
    t_pompy = time.time() - t_start
    rres = []
    t0 = time.time()
    with tempfile.TemporaryDirectory() as work:
        for s in range(1, n_pt + 1):
            rres.append(plumetrace_seed(a.plumetrace, s, setup, sets, work))
            if s % 50 == 0 or s == n_pt:
                print(f"plumetrace: {s} of {n_pt} seeds, {time.time() - t0:.0f} s", flush=True)
    t_pt = time.time() - t0
    if n_pompy:
        cpu = {k: sum(p["cpu_s"][k] for p in pres) for k in ("step", "generator", "exact", "verify")}
        print(f"\npompy: {t_pompy:.0f} s wall (CPU: stepping {cpu['step']:.0f} s, generator "
              f"{cpu['generator']:.0f} s, exact sums {cpu['exact']:.0f} s, pompy's own loop for the "
              f"check {cpu['verify']:.0f} s)")
    print(f"plumetrace: {t_pt:.0f} s wall for {n_pt} seeds (runs "
          f"{sum(r['cpu_s']['run_wall'] for r in rres):.0f} s, reading and exact sums "
          f"{sum(r['cpu_s']['analysis'] for r in rres):.0f} s)")
    supp = [r["filament_stats"]["suppressed"] for r in rres]
    print(f"plumetrace releases suppressed by the 1000-filament cap: mean {np.mean(supp):.1f} per seed")
    rows = report(pres, rres, setup)
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"setup": setup, "sets": sets, "pompy": pres, "plumetrace": rres, "rows": rows,
                       "wall_s": {"pompy": t_pompy, "plumetrace": t_pt}}, f, default=float)
    return 0


if __name__ == "__main__":
    sys.exit(main())
