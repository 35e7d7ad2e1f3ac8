"""The Gymnasium environment: the checker passes, seeds drive every stream, the vectorised
environment steps the same episodes, success is a declaration, the reward cannot be gamed by
staying in the plume, and a trained policy flies as a planner."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import plumetrace
import plumetrace.gym as pg


def rollout(env, seed, n, actions):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for k in range(n):
        obs, r, term, trunc, info = env.step(actions[k % len(actions)])
        out.append(obs)
        if term or trunc:
            break
    return np.array(out)


def test_the_environment_passes_the_gymnasium_checker():
    env = gym.make(pg.ENV_ID, scenario="demo")
    check_env(env.unwrapped)
    assert env.observation_space.shape == (len(pg.OBS_NAMES),)
    assert env.action_space.low.tolist() == [-1.0, -1.0, -1.0]
    assert len(pg.ACTION_NAMES) == 3


def test_the_same_seed_gives_the_same_first_observation_and_trajectory():
    env = pg.PlumeTracingEnv("demo")
    acts = [np.array([0.3, 0.5, -1.0]), np.array([-0.2, 1.0, -1.0]), np.array([0.0, -1.0, -1.0])]
    a = rollout(env, 21, 200, acts)
    b = rollout(pg.PlumeTracingEnv("demo"), 21, 200, acts)
    c = rollout(env, 22, 200, acts)
    # A reset to a seed seen before starts from the kept spun-up plume: the same episode.
    a2 = rollout(env, 21, 200, acts)
    assert np.array_equal(a, b)
    assert np.array_equal(a, a2)
    assert not np.array_equal(a[:50], c[:50])
    assert np.all(a >= pg.OBS_LOW) and np.all(a <= pg.OBS_HIGH)


def test_reset_without_a_seed_follows_the_first_seed():
    e1, e2 = pg.PlumeTracingEnv("demo"), pg.PlumeTracingEnv("demo")
    e1.reset(seed=5)
    e2.reset(seed=5)
    assert np.array_equal(e1.reset()[0], e2.reset()[0])


# The demo with the vehicle 30 m down the flow from the source, in the plume, and a short limit.
NEAR_SOURCE = {"vehicles.0.x_m": 130.0, "vehicles.0.y_m": 0.0, "mission.time_limit_s": 600.0}


def episode(env, seed, policy, limit=5000):
    obs, info = env.reset(seed=seed)
    total, detections = 0.0, 0
    for _ in range(limit):
        obs, r, term, trunc, info = env.step(policy(obs))
        total += r
        detections += int(obs[6] > 0.5)
        if term or trunc:
            break
    return total, detections, info


def test_a_declaration_ends_the_episode_and_is_scored_against_the_radius():
    env = pg.PlumeTracingEnv("demo", set=NEAR_SOURCE)
    total, _, info = episode(env, 3, lambda o: np.array([0.0, 0.0, 1.0]))
    assert info["reason"] == "declared" and info["success"]
    assert info["error_m"] < 50.0  # the scenario's success radius
    assert 0.99 < total <= 1.2  # +1, less the time, plus detection rewards up to their cap
    # A radius tighter than the error makes the same declaration false.
    tight = pg.PlumeTracingEnv("demo", set=NEAR_SOURCE, success_radius_m=5.0)
    total, _, info = episode(tight, 3, lambda o: np.array([0.0, 0.0, 1.0]))
    assert info["reason"] == "false_declaration" and not info["success"]
    assert info["error_m"] > 5.0 and -1.01 < total < -0.99
    # Below the threshold nothing is declared.
    total, _, info = episode(env, 3, lambda o: np.array([0.0, -1.0, 0.4]), limit=20)
    assert info["reason"] == ""


def test_staying_in_the_plume_earns_less_than_declaring():
    # A policy that circles in the plume at the slowest speed for the whole episode collects
    # the detection rewards up to their cap, and still returns at most the documented bound;
    # declaring from the same start returns more than 0.
    bonus, cap = 0.05, 0.2
    env = pg.PlumeTracingEnv("demo", set=NEAR_SOURCE, detection_reward=bonus,
                             detection_reward_max=cap)
    linger, detections, info = episode(env, 3, lambda o: np.array([1.0, -1.0, -1.0]))
    assert info["reason"] in {"time_limit", "left_op_area"}
    assert detections * bonus >= cap  # it met the plume often enough to reach the cap
    assert linger <= cap - 1.0 + 1.0 / 600.0 + 1e-9
    declare, _, info = episode(env, 3, lambda o: np.array([0.0, 0.0, 1.0]))
    assert info["success"] and declare > 0.0 > linger


def test_info_has_the_same_keys_at_reset_and_every_step():
    env = pg.PlumeTracingEnv("demo")
    _, info = env.reset(seed=4)
    assert tuple(info) == pg.INFO_KEYS and info["run_seed"] == 4
    _, _, _, _, info = env.step(np.zeros(3))
    assert tuple(info) == pg.INFO_KEYS and info["reason"] == ""
    assert info["error_m"] == -1.0


def test_the_vector_environment_steps_the_same_episodes_as_single_ones():
    v = pg.PlumeTracingVecEnv(num_envs=3, scenario="demo")
    obs, _ = v.reset(seed=40)
    singles = [pg.PlumeTracingEnv("demo") for _ in range(3)]
    first = [s.reset(seed=40 + i)[0] for i, s in enumerate(singles)]
    assert np.array_equal(obs, np.array(first))
    act = np.array([[0.1, 0.5, -1.0], [-0.4, 0.0, -1.0], [0.9, -1.0, -1.0]])
    for _ in range(60):
        obs, rew, term, trunc, info = v.step(act)
        for i, s in enumerate(singles):
            o, r, te, tr, _ = s.step(act[i])
            assert np.array_equal(obs[i], o)
            assert rew[i] == r
        if term.any() or trunc.any():
            break


def test_bad_settings_and_actions_are_refused():
    with pytest.raises(plumetrace.PlumetraceError, match="max_turn_deg"):
        pg.PlumeTracingEnv("demo", max_turn_deg=400.0)
    with pytest.raises(plumetrace.PlumetraceError, match="speed_min_mps"):
        pg.PlumeTracingEnv("demo", speed_min_mps=2.0, speed_max_mps=1.0)
    env = pg.PlumeTracingEnv("demo")
    with pytest.raises(plumetrace.PlumetraceError, match="reset"):
        env.step(np.zeros(3))
    env.reset(seed=1)
    with pytest.raises(plumetrace.PlumetraceError,
                       match=r"the action has 2 components, not 3 \(turn, speed, declare\)"):
        env.step(np.zeros(2))
    with pytest.raises(plumetrace.PlumetraceError,
                       match="detection_reward_max = 1 is outside 0..=0.9"):
        pg.PlumeTracingEnv("demo", detection_reward_max=1.0)
    with pytest.raises(plumetrace.PlumetraceError,
                       match="declare_treshold: not a setting .* did you mean declare_threshold"):
        pg.PlumeTracingEnv("demo", declare_treshold=0.2)
    # Non-finite actions are held at zero, never a NaN command (nor a declaration).
    obs, *_ = env.step(np.array([np.nan, np.inf, np.nan]))
    assert np.all(np.isfinite(obs))


def test_a_family_draws_a_site_per_seed():
    from conftest import REPO

    fam = str(REPO / "examples" / "families" / "coastal.family.toml")
    env = pg.PlumeTracingEnv(fam)
    a, _ = env.reset(seed=1)
    b, _ = env.reset(seed=2)
    a2, _ = env.reset(seed=1)
    assert np.array_equal(a, a2)
    assert not np.array_equal(a, b)
    obs, r, term, trunc, info = env.step(np.array([0.0, 0.5, -1.0]))
    assert np.isfinite(r) and obs.shape == (12,)


def scripted(obs):
    """A fixed policy of the observation: weaves, and declares once a tenth of the time is gone."""
    return np.array([np.sin(7.0 * float(np.sum(obs))), 0.4, 1.0 if obs[11] > 0.1 else -1.0])


@pytest.mark.parametrize("mode", ["sync", "async", "vector_entry_point"])
def test_every_vector_mode_gives_the_same_info_keys_and_values(mode):
    v = gym.make_vec(pg.ENV_ID, num_envs=2, vectorization_mode=mode, scenario="demo",
                     set={"mission.time_limit_s": 300.0})
    want = set(pg.INFO_KEYS) | {"_" + k for k in pg.INFO_KEYS}
    try:
        obs, info = v.reset(seed=11)
        assert set(info) == want
        assert info["run_seed"].tolist() == [11, 12]
        seen = [(obs.copy(), {k: info[k].tolist() for k in ("time_s", "reason")})]
        for _ in range(3):
            obs, rew, term, trunc, info = v.step(np.array([[0.2, 0.0, -1.0], [-0.2, 1.0, -1.0]]))
            assert set(info) == want
            seen.append((obs.copy(), {k: info[k].tolist() for k in ("time_s", "reason")}))
    finally:
        v.close()
    ref = pg.PlumeTracingVecEnv(num_envs=2, scenario="demo", set={"mission.time_limit_s": 300.0})
    obs, info = ref.reset(seed=11)
    assert np.array_equal(seen[0][0], obs)
    for o, i in seen[1:]:
        obs, *_, info = ref.step(np.array([[0.2, 0.0, -1.0], [-0.2, 1.0, -1.0]]))
        assert np.array_equal(o, obs)
        assert i == {k: info[k].tolist() for k in ("time_s", "reason")}


def test_the_same_step_mode_resets_an_ended_copy_in_the_step_that_ends_it():
    v = pg.PlumeTracingVecEnv(num_envs=2, scenario="demo", autoreset_mode="same_step")
    assert v.metadata["autoreset_mode"] == gym.vector.AutoresetMode.SAME_STEP
    single = pg.PlumeTracingEnv("demo")
    obs, _ = v.reset(seed=20)
    s_obs, _ = single.reset(seed=20)
    declare = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    obs, rew, term, trunc, info = v.step(declare)
    s_obs, s_rew, s_term, _, s_info = single.step(declare[0])
    assert term.tolist() == [True, False] and s_term
    assert rew[0] == s_rew and info["_final_obs"].tolist() == [True, False]
    assert np.array_equal(info["final_obs"][0], s_obs)
    assert info["final_info"]["reason"][0] == s_info["reason"] == "false_declaration"
    # The copy's next episode has begun: a new seed, time at its first decision.
    assert info["reason"][0] == "" and info["run_seed"][0] != 20
    obs, rew, term, trunc, info = v.step(np.zeros((2, 3)) - 1.0)
    assert not term.any() and rew[0] != 0.0


def test_a_reset_mask_resets_one_copy():
    v = pg.PlumeTracingVecEnv(num_envs=2, scenario="demo")
    v.reset(seed=30)
    for _ in range(3):
        before, *_ = v.step(np.zeros((2, 3)) - 1.0)
    obs, info = v.reset(seed=[None, 9], options={"reset_mask": np.array([False, True])})
    fresh, _ = pg.PlumeTracingEnv("demo").reset(seed=9)
    assert np.array_equal(obs[0], before[0]) and np.array_equal(obs[1], fresh)
    assert info["_run_seed"].tolist() == [False, True] and info["run_seed"][1] == 9
    with pytest.raises(ValueError, match="reset_mask"):
        v.reset(options={"reset_mask": np.array([False, False])})
    with pytest.raises(ValueError, match="autoreset_mode 'disabled' is not supported"):
        pg.PlumeTracingVecEnv(num_envs=2, scenario="demo", autoreset_mode="disabled")


def test_a_policy_flies_as_a_planner_on_the_environments_observations():
    # The same policy in the environment and through the Python planner seam sees the same
    # observations and declares at the same point.
    seen_env, seen_run = [], []

    def in_env(obs):
        seen_env.append(obs.copy())
        return scripted(obs)

    def in_run(obs):
        seen_run.append(obs.copy())
        return scripted(obs)

    env = pg.PlumeTracingEnv("demo")
    _, _, info = episode(env, 8, in_env)
    assert info["reason"] in {"declared", "false_declaration"}
    r = plumetrace.run("demo", seed=8, planner=pg.PolicyPlanner(in_run, "demo", 8),
                       trajectory=False, outputs=False)
    assert r.summary["first_declaration"]["error_m"] == pytest.approx(info["error_m"], abs=1e-9)
    n = len(seen_env)
    assert np.array_equal(np.array(seen_run[:n]), np.array(seen_env))
    with pytest.raises(ValueError, match=r"the policy gave 2 action components, not 3"):
        plumetrace.run("demo", seed=8, outputs=False,
                       planner=pg.PolicyPlanner(lambda o: np.zeros(2), "demo", 8))


def test_a_seed_list_makes_every_episode_fly_one_of_them():
    # As the PPO baseline trains on a benchmark task's tuning seeds only.
    pool = [plumetrace.derive_seed(3201, k) for k in range(5)]
    v = pg.PlumeTracingVecEnv(num_envs=2, scenario="demo", autoreset_mode="same_step",
                              seeds=pool)
    _, info = v.reset(seed=1)
    seen = set(info["run_seed"].tolist())
    for _ in range(6):  # every step declares, so every step ends both episodes
        _, _, term, _, info = v.step(np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]))
        assert term.all()
        seen |= set(info["run_seed"].tolist()) | set(info["final_info"]["run_seed"].tolist())
    assert seen <= set(pool) and len(seen) >= 3
    with pytest.raises(plumetrace.PlumetraceError, match="seeds is empty"):
        pg.PlumeTracingVecEnv(num_envs=2, scenario="demo", seeds=[])
