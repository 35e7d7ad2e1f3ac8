"""The learned baseline: PPO (Stable-Baselines3) trained through the vectorised Gymnasium
environment on the tuning seeds of one benchmark task (coastal), then flown on the task's test
seeds by plumetrace.benchmark through the Python planner seam (plumetrace.gym.PolicyPlanner): the
benchmark's own loop and leaderboard, so its row has the leaderboard's columns and numbers.

    python scripts/ppo_baseline.py [--timesteps 200000] [--envs 4] [--test-seeds 100] [--out DIR]
    python scripts/ppo_baseline.py --evaluate POLICY.zip [--test-seeds 100] [--out DIR]

Run it through scripts/ppo_baseline.sh, which makes the environment (torch, stable-baselines3)
and installs the package. Training never sees a test seed: every training episode flies one of
the task's tuning seeds (the vectorised environment's `seeds`), and the two sets are disjoint.
"""

import argparse
import csv
import json
import pathlib
import shutil
import sys
import time
import tomllib

import numpy as np
import plumetrace
import torch
import plumetrace.gym as pg
from plumetrace.sb3 import PlumeTracingSB3VecEnv
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecMonitor

ROOT = pathlib.Path(__file__).resolve().parents[1]
# One thread for torch: the policy is small, and the environments step in Rust's own threads
# (torch's waiting threads otherwise spin on the cores the environments need).
torch.set_num_threads(1)
# The policy decides every 5 s (the environment's default is 1 s): episodes of the task's
# 7200 s are at most 1,440 decisions, within reach of PPO's discounting.
SETTINGS = {"decision_period_s": 5.0}


class Progress(BaseCallback):
    """Prints the training's progress every tenth of the budget, and saves the policy so far."""

    def __init__(self, total, path):
        super().__init__()
        self.total, self.next, self.start = total, total / 10, time.perf_counter()
        self.path = path

    def _on_step(self):
        if self.num_timesteps >= self.next:
            self.next += self.total / 10
            buf = self.model.ep_info_buffer
            mean = np.mean([e["r"] for e in buf]) if buf else float("nan")
            print(f"  {self.num_timesteps} steps, {time.perf_counter() - self.start:.0f} s, "
                  f"mean return of the last {len(buf)} episodes {mean:+.3f}", flush=True)
            self.model.save(self.path)
        return True


def task_of(name):
    tasks = tomllib.loads((ROOT / "benchmarks" / "tasks-v1.toml").read_text())
    for t in tasks["tasks"]:
        if t["name"] == name:
            return tasks["version"], t
    names = ", ".join(t["name"] for t in tasks["tasks"])
    sys.exit(f"ppo_baseline.py: no task {name!r} in benchmarks/tasks-v1.toml (its tasks: {names})")


def train(task, scenario, args, path):
    tuning = [plumetrace.derive_seed(task["tuning_seed"], k) for k in range(task["tuning_seeds"])]
    env = VecMonitor(PlumeTracingSB3VecEnv(
        num_envs=args.envs, scenario=scenario, seeds=tuning, seed=args.seed,
        success_radius_m=task["success_radius_m"], **SETTINGS))
    # The policy starts out not declaring: a Gaussian policy of mean 0 and deviation 1 would
    # declare (declare > 0.5) at 31 % of its steps, ending most episodes within a few decisions
    # (and spending the budget on resets). With the declare component's mean at -1 and a
    # deviation of 0.6, an untrained policy declares at 0.6 % of its steps.
    model = PPO("MlpPolicy", env, n_steps=512, batch_size=256, seed=args.seed, device="cpu",
                policy_kwargs={"log_std_init": -0.5}, verbose=0)
    with torch.no_grad():
        model.policy.action_net.bias[2] = -1.0
    start = time.perf_counter()
    model.learn(args.timesteps, callback=Progress(args.timesteps, path))
    took = time.perf_counter() - start
    return model, took, tuning


def evaluate(model, task, n_test, out):
    """Flies the policy on the task's first `n_test` test seeds with plumetrace.benchmark (into
    out/benchmark, afresh: its runs are the policy's); returns its leaderboard entry with the
    runs' outcomes counted."""
    def policy(obs):
        return model.predict(obs, deterministic=True)[0]

    def ppo(scenario, seed):
        return pg.PolicyPlanner(policy, scenario, seed,
                                success_radius_m=task["success_radius_m"], **SETTINGS)

    bench = out / "benchmark"
    shutil.rmtree(bench, ignore_errors=True)
    results = plumetrace.benchmark(ppo, bench, tasks=task["name"], seeds_per_task=n_test,
                                   progress=False)
    e = dict(results[task["name"]]["ppo"])
    with (bench / task["name"] / "runs.csv").open() as f:
        outcomes = [r["outcome"] for r in csv.DictReader(f)]
    e["outcomes"] = {o: outcomes.count(o) for o in sorted(set(outcomes))}
    return e


def markdown_row(e):
    """The entry as a row of the leaderboard's table, unranked (it flew apart from the rest)."""
    f = lambda x: "–" if x is None else f"{x:.1f}"  # noqa: E731
    g = lambda x: "–" if x is None else f"{x:.0f}"  # noqa: E731
    lo, hi = e["success_ci95"]
    return (f"| – | ppo | {e['runs']} | {e['successes']}/{e['runs']} = {e['success_rate']:.2f} "
            f"({lo:.2f} – {hi:.2f}) | {e['sources_located']}/{e['sources']} | "
            f"{f(e['error_median_m'])} / {f(e['error_p90_m'])} | {f(e['along_median_m'])} / "
            f"{f(e['cross_median_m'])} | {f(e['along_signed_median_m'])} | "
            f"{g(e['declaration_median_s'])} | {g(e['path_length_median_m'])} | "
            f"{e['false_declarations']} | {e['collisions']} | {e['cage_aborts']} | {e['failed']} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default="coastal")
    ap.add_argument("--timesteps", type=int, default=200_000)
    ap.add_argument("--envs", type=int, default=4)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--test-seeds", type=int, default=None,
                    help="test seeds flown (default: the task's seeds, 100 for coastal)")
    ap.add_argument("--out", default=str(ROOT / "target" / "ppo"))
    ap.add_argument("--evaluate", metavar="POLICY.zip",
                    help="fly a saved policy on the test seeds instead of training one")
    args = ap.parse_args()
    version, task = task_of(args.task)
    scenario = str(ROOT / task["scenario"]) if "/" in task["scenario"] else task["scenario"]
    n_test = args.test_seeds if args.test_seeds is not None else task["seeds"]
    if not 1 <= n_test <= task["test_seeds"]:
        sys.exit(f"ppo_baseline.py: --test-seeds {n_test} is outside 1..={task['test_seeds']}")
    tests = [plumetrace.derive_seed(task["test_seed"], k) for k in range(task["test_seeds"])]
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    if args.evaluate:
        model, took = PPO.load(args.evaluate, device="cpu"), 0.0
        print(f"flying {args.evaluate}", flush=True)
    else:
        print(f"training PPO on {args.task}'s {task['tuning_seeds']} tuning seeds: "
              f"{args.timesteps} steps, {args.envs} environments", flush=True)
        path = out / f"ppo_{args.task}.zip"
        model, took, tuning = train(task, scenario, args, path)
        if set(tuning) & set(tests):
            sys.exit("ppo_baseline.py: a tuning seed is a test seed")
        model.save(path)
        print(f"trained in {took:.0f} s ({args.timesteps / took:.0f} steps/s); saved {path}",
              flush=True)

    start = time.perf_counter()
    e = evaluate(model, task, n_test, out)
    flown = time.perf_counter() - start
    # A saved policy knows how many steps it was trained for.
    timesteps = int(model.num_timesteps) if args.evaluate else args.timesteps
    e.update({"task": args.task, "task_set": version, "timesteps": timesteps,
              "envs": args.envs, "seed": args.seed, "train_s": round(took, 1),
              "test_s": round(flown, 1), **{k: v for k, v in SETTINGS.items()}})
    (out / "ppo.json").write_text(json.dumps(e, indent=2) + "\n")
    row = markdown_row(e)
    (out / "ppo.md").write_text(row + "\n")
    print(f"test seeds: {n_test} flown in {flown:.0f} s; outcomes {e['outcomes']}")
    print(row)


if __name__ == "__main__":
    main()
