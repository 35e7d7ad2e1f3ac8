"""A Gymnasium training loop: a linear policy on the plume-tracing environment improved by
random search (perturb the weights, keep what scores better), with the vectorised environment
stepped in Rust.

    python gym_training.py [--iterations 20] [--envs 4] [--steps 300]

Needs gymnasium (`pip install "plumetrace[gym]"`). The policy maps the 12 observation
components to the three actions (turn, speed, declare); each candidate is scored by its summed
reward over `--steps` steps of `--envs` environments on the same seeds. (For a deep-learning
baseline, PPO through Stable-Baselines3, see scripts/ppo_baseline.sh.)
"""

import argparse

import numpy as np

try:
    import gymnasium as gym
except ImportError:
    raise SystemExit("this example needs gymnasium: pip install 'plumetrace[gym]'")

import plumetrace.gym


def score(env, w: np.ndarray, steps: int, seed: int) -> float:
    """Summed reward of the policy `tanh(obs @ w)` over `steps` steps, and the reasons the
    episodes ended."""
    obs, _ = env.reset(seed=seed)
    total = 0.0
    for _ in range(steps):
        obs, reward, terminated, truncated, info = env.step(np.tanh(obs @ w))
        total += float(np.sum(reward))
        for r in info["reason"][terminated | truncated]:
            score.ends[r] = score.ends.get(r, 0) + 1
    return total


score.ends = {}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--iterations", type=int, default=20)
    ap.add_argument("--envs", type=int, default=4)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    env = gym.make_vec("plumetrace/PlumeTracing-v1", num_envs=args.envs,
                       vectorization_mode="vector_entry_point", scenario="demo")
    rng = np.random.default_rng(args.seed)
    n_obs = len(plumetrace.gym.OBS_NAMES)
    best = np.zeros((n_obs, len(plumetrace.gym.ACTION_NAMES)))
    best_score = score(env, best, args.steps, args.seed)
    print(f"start: {best_score:+.3f}")
    for i in range(args.iterations):
        trial = best + 0.3 * rng.standard_normal(best.shape)
        s = score(env, trial, args.steps, args.seed)
        if s > best_score:
            best, best_score = trial, s
        print(f"iteration {i + 1}: tried {s:+.3f}, best {best_score:+.3f}")
    env.close()
    print("episode ends:", dict(sorted(score.ends.items())))


if __name__ == "__main__":
    main()
