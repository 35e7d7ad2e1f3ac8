"""Stable-Baselines3 on the environment: SB3's own checker passes, the vectorised environment
is an SB3 VecEnv with same-step resets, and PPO learns through it (skipped where
stable-baselines3 is not installed: scripts/ppo_baseline.sh runs them in its environment)."""

import numpy as np
import pytest

sb3 = pytest.importorskip("stable_baselines3")

from stable_baselines3.common.env_checker import check_env  # noqa: E402
from stable_baselines3.common.vec_env import VecMonitor  # noqa: E402

import plumetrace.gym as pg  # noqa: E402
from plumetrace.sb3 import PlumeTracingSB3VecEnv  # noqa: E402


def test_sb3s_own_checker_passes():
    check_env(pg.PlumeTracingEnv("demo"), warn=True, skip_render_check=True)


def test_the_vec_env_resets_an_ended_copy_in_the_same_step():
    env = PlumeTracingSB3VecEnv(num_envs=2, scenario="demo", seed=20)
    obs = env.reset()
    assert obs.shape == (2, len(pg.OBS_NAMES))
    assert [i["run_seed"] for i in env.reset_infos] == [20, 21]
    env.step_async(np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]))
    obs, rew, dones, infos = env.step_wait()
    assert dones.tolist() == [True, False]
    assert infos[0]["reason"] == "false_declaration" and not infos[0]["TimeLimit.truncated"]
    assert infos[0]["terminal_observation"].shape == (len(pg.OBS_NAMES),)
    assert not np.array_equal(infos[0]["terminal_observation"], obs[0])
    assert set(pg.INFO_KEYS) <= set(infos[1]) and "terminal_observation" not in infos[1]
    assert env.get_attr("render_mode") == [None, None]
    assert env.env_is_wrapped(VecMonitor) == [False, False]
    with pytest.raises(AttributeError, match="stepped together"):
        env.env_method("reset", indices=0)


def test_ppo_learns_through_the_vec_env():
    env = VecMonitor(PlumeTracingSB3VecEnv(num_envs=2, scenario="demo", seed=1,
                                           set={"mission.time_limit_s": 200.0}))
    model = sb3.PPO("MlpPolicy", env, n_steps=64, batch_size=64, n_epochs=1, seed=1,
                    device="cpu")
    model.learn(256)
    action, _ = model.predict(np.zeros(len(pg.OBS_NAMES), dtype=np.float32), deterministic=True)
    assert action.shape == (3,)
