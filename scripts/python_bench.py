"""Costs seen from Python: the plume step and point queries against pompy on pompy's scenario,
and Gymnasium steps per second (single and vectorised).

Run through python_bench.sh, which prepares the environment. Prints one JSON object.
"""

import argparse
import json
import os
import time

import numpy as np

import plumetrace
import plumetrace.gym as pg


def cpu():
    return time.process_time()


def plume_costs(warmup_s, timed_s, queries, seed):
    """plumetrace's plume from Python: step cost per filament-step, batch query cost per point."""
    p = plumetrace.Plume("pompy", seed=seed)
    dt = p.dt_s
    p.step(int(round(warmup_s / dt)))
    steps = int(round(timed_s / dt))
    live = 0
    t0 = cpu()
    for _ in range(steps):
        p.step(1)
        live += p.stats()["live"]
    step_cpu = cpu() - t0
    f = p.filaments()
    rng = np.random.RandomState(seed + 1)
    idx = rng.randint(0, len(f), size=queries)
    pts = np.column_stack([f[idx, :2] + rng.uniform(-0.5, 0.5, size=(queries, 2)),
                           np.zeros(queries)])
    p.concentrations(pts)  # the first call after a step builds the query index
    t0 = time.perf_counter()
    c = p.concentrations(pts)
    query_wall = time.perf_counter() - t0
    t0 = cpu()
    for i in range(min(queries, 2000)):
        p.concentrations(pts[i:i + 1])
    single_cpu = cpu() - t0
    return {
        "step_ms": step_cpu / steps * 1e3,
        "ns_per_filament_step": step_cpu / max(live, 1) * 1e9,
        "mean_live": live / steps,
        "batch_query_ns_per_point_wall": query_wall / queries * 1e9,
        "single_query_us_from_python": single_cpu / min(queries, 2000) * 1e6,
        "nonzero": int(np.count_nonzero(c)),
    }


def pompy_costs(warmup_s, timed_s, queries, seed):
    from pompy import models, processors

    rng = np.random.RandomState(seed)
    region = models.Rectangle(0.0, 100.0, -50.0, 50.0)
    wind = models.WindModel(region, 21, 21, u_av=1.0, v_av=0.0, rng=rng)
    plume = models.PlumeModel(region, (5.0, 0.0, 0.0), wind, puff_release_rate=5.0,
                              max_num_puffs=10**6, rng=rng)
    dt = 0.01
    for _ in range(int(round(warmup_s / dt))):
        wind.update(dt)
        plume.update(dt)
    steps = int(round(timed_s / dt))
    live = 0
    t0 = cpu()
    for _ in range(steps):
        wind.update(dt)
        plume.update(dt)
        live += len(plume.puffs)
    step_cpu = cpu() - t0
    arr = plume.puff_array
    calc = processors.ConcentrationValueCalculator(1.0)
    qrng = np.random.RandomState(seed + 1)
    idx = qrng.randint(0, len(arr), size=queries)
    pts = arr[idx, :2] + qrng.uniform(-0.5, 0.5, size=(queries, 2))
    n = min(queries, 2000)
    t0 = cpu()
    for x, y in pts[:n]:
        calc.calc_conc_point(arr, x, y, 0.0)
    q_cpu = cpu() - t0
    return {
        "step_ms": step_cpu / steps * 1e3,
        "ns_per_filament_step": step_cpu / max(live, 1) * 1e9,
        "mean_live": live / steps,
        "single_query_us": q_cpu / n * 1e6,
    }


def gym_costs(steps, seed, envs):
    """Steps per second: random actions (episodes end often, so resets, each with the
    scenario's spin-up, are counted in), and a held course that keeps the episode going."""
    out = {}
    # The third action component (declare) stays at -1: the episodes never declare.
    for name, policy in [("random", None), ("held", np.array([0.0, 0.0, -1.0]))]:
        env = pg.PlumeTracingEnv("demo")
        rng = np.random.default_rng(seed)
        env.reset(seed=seed)
        resets = 0
        t0 = time.perf_counter()
        for _ in range(steps):
            a = np.append(rng.uniform(-1, 1, 2), -1.0) if policy is None else policy
            _, _, term, trunc, _ = env.step(a)
            if term or trunc:
                env.reset()
                resets += 1
        out[f"single_{name}_steps_per_s"] = steps / (time.perf_counter() - t0)
        out[f"single_{name}_resets"] = resets
        for n in envs:
            v = pg.PlumeTracingVecEnv(num_envs=n, scenario="demo")
            v.reset(seed=seed)
            k = max(1, steps // n)
            t0 = time.perf_counter()
            for _ in range(k):
                a = (np.column_stack([rng.uniform(-1, 1, (n, 2)), -np.ones(n)])
                     if policy is None else np.tile(policy, (n, 1)))
                v.step(a)
            out[f"vec{n}_{name}_steps_per_s"] = n * k / (time.perf_counter() - t0)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--warmup", type=float, default=50.0)
    ap.add_argument("--timed", type=float, default=20.0)
    ap.add_argument("--queries", type=int, default=10_000)
    ap.add_argument("--gym-steps", type=int, default=4000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--no-pompy", action="store_true")
    a = ap.parse_args()
    out = {"cpus": os.cpu_count(), "load": os.getloadavg()}
    out["plumetrace"] = plume_costs(a.warmup, a.timed, a.queries, a.seed)
    if not a.no_pompy:
        out["pompy"] = pompy_costs(a.warmup, a.timed, a.queries, a.seed)
        out["ratio_step_per_filament"] = (out["pompy"]["ns_per_filament_step"]
                                          / out["plumetrace"]["ns_per_filament_step"])
    out["gym"] = gym_costs(a.gym_steps, a.seed, [2, 8])
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
