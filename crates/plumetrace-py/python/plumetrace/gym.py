"""A Gymnasium environment for plume tracing: the agent flies one vehicle of a scenario.

Importing this module registers ``plumetrace/PlumeTracing-v0``::

    import gymnasium as gym
    import plumetrace.gym

    env = gym.make("plumetrace/PlumeTracing-v0", scenario="demo")
    obs, info = env.reset(seed=1)

Each step runs the mission (in Rust) to the vehicle's next decision, every
``decision_period_s`` (default 1 s) of simulated time.

Observation (``Box``, float32, 12 components, what the vehicle knows, never the truth):

==================  ===========  ===========================================================
component           bounds       meaning
==================  ===========  ===========================================================
x_rel, y_rel        [-2, 2]      position estimate relative to the op-area's bounding-box
                                 centre, in half-widths (0 without a position estimate)
heading_sin, _cos   [-1, 1]      measured compass heading (sin is east, cos north)
speed               [0, 1]       measured speed / 3 m/s
reading             [0, 1]       tanh(latest reading / detection threshold)
detection           {0, 1}       a reading above the threshold since the last step
recent_detections   [0, 1]       fraction of the last 10 steps with a detection
since_detection     [0, 1]       time since the last detection / 600 s (1: none yet)
flow_east, _north   [-2, 2]      measured current, m/s (0 without a flow sensor)
time                [0, 1]       mission time / time limit
==================  ===========  ===========================================================

Action (``Box(-1, 1, (2,))``): ``turn`` (heading change of ``turn * max_turn_deg`` from the
measured heading, default 30 deg) and ``speed`` (from ``speed_min_mps`` = 0.3 to
``speed_max_mps`` = 1.5 m/s). The vehicle keeps its altitude (an AUV) or the surface. An action
takes effect at the vehicle's next decision, one decision period after the observation it
answers.

Reward: ``-decision_period_s / time_limit`` per step, ``+detection_reward`` (0.01) per step with
a detection, ``+1`` on coming within ``success_radius_m`` (10 m) of a source (terminated), ``-1``
on leaving the op-area (once inside it) or any other end of the mission (terminated); truncated at the
scenario's time limit. ``info`` has ``time_s``, ``success`` and ``reason``: empty while the
episode goes on, then why it ended:

================  ===========  =====================================================
reason            ends as      meaning
================  ===========  =====================================================
reached_source    terminated   within ``success_radius_m`` of a source (+1)
left_op_area      terminated   outside the op-area after being inside it (-1)
left_domain       terminated   the vehicle left the simulated domain (-1)
collided          terminated   the vehicle entered an obstacle (-1)
time_limit        truncated    the scenario's time limit
================  ===========  =====================================================

Settings are checked at ``gym.make``: a keyword that is neither a setting nor a valid scenario
override fails there, with the settings' names and the one a typo meant
(``max_turn_dgr`` -> ``max_turn_deg``).

``reset(seed=s)`` makes the episode's run seed ``s``: the plume, the flow, the sensors'
noise and, for a family file, the site all follow from it, so the episode meets the same plume
as ``plumetrace.run(scenario, seed=s)``. Without a seed, the next run seed is drawn from the
environment's generator (seeded by the last seed given).
"""

from __future__ import annotations

from typing import Any, Dict, Mapping, Optional, Tuple

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector.utils import batch_space

from . import _plumetrace

ENV_ID = "plumetrace/PlumeTracing-v0"
OBS_NAMES = tuple(_plumetrace.EnvCore.obs_names())
_LOW, _HIGH = _plumetrace.EnvCore.obs_bounds()
OBS_LOW = np.asarray(_LOW, dtype=np.float32)
OBS_HIGH = np.asarray(_HIGH, dtype=np.float32)

__all__ = ["ENV_ID", "OBS_NAMES", "PlumeTracingEnv", "PlumeTracingVecEnv"]


def _spaces() -> Tuple[spaces.Box, spaces.Box]:
    obs = spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)
    act = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
    return obs, act


class PlumeTracingEnv(gymnasium.Env):
    """One vehicle of a scenario flown by the agent.

    Args:
        scenario: a preset name, a scenario file or a family file (``*.family.toml``: each
            episode's site is drawn from its run seed).
        set: scenario overrides with dotted keys.
        render_mode: not supported (None).
        **settings: ``vehicle`` (index, 0), ``decision_period_s`` (0.1-600, 1),
            ``max_turn_deg`` (0-180, 30), ``speed_min_mps`` / ``speed_max_mps`` (0-10, 0.3 and
            1.5), ``success_radius_m`` (0-10000, 10), ``detection_reward`` (-1 to 1, 0.01); any
            other keyword is a scenario override (a planner key, as for ``plumetrace.run``).
    """

    metadata: Dict[str, Any] = {"render_modes": []}

    def __init__(
        self,
        scenario: str = "demo",
        set: Optional[Mapping[str, Any]] = None,
        render_mode: Optional[str] = None,
        **settings: Any,
    ) -> None:
        if render_mode is not None:
            raise ValueError(f"render_mode {render_mode!r} is not supported")
        self.render_mode = None
        self._core = _plumetrace.EnvCore(scenario, set=dict(set) if set else None, **settings)
        self.observation_space, self.action_space = _spaces()
        self._started = False

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[np.ndarray, Dict[str, Any]]:
        super().reset(seed=seed)
        run_seed = int(seed) if seed is not None else int(self.np_random.integers(0, 2**63))
        obs = self._core.reset(run_seed)
        self._started = True
        return obs, {"run_seed": run_seed, "time_s": 0.0}

    def step(self, action: Any) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        obs, reward, terminated, truncated, info = self._core.step(a)
        return obs, float(reward), bool(terminated), bool(truncated), dict(info)


class PlumeTracingVecEnv(gymnasium.vector.VectorEnv):
    """``num_envs`` environments stepped together in Rust, in parallel threads (results do not
    depend on the thread count).

    Autoreset is the next-step mode: after an episode ends, the next ``step`` resets that
    environment (its action is ignored, its reward 0) and returns the new episode's first
    observation. ``reset(seed=s)`` gives environment ``i`` the run seed ``s + i``; its later
    episodes have seeds derived from that one.
    """

    metadata: Dict[str, Any] = {
        "render_modes": [],
        "autoreset_mode": gymnasium.vector.AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        num_envs: int = 4,
        scenario: str = "demo",
        set: Optional[Mapping[str, Any]] = None,
        render_mode: Optional[str] = None,
        **settings: Any,
    ) -> None:
        if render_mode is not None:
            raise ValueError(f"render_mode {render_mode!r} is not supported")
        self.render_mode = None
        self._core = _plumetrace.VecEnvCore(
            scenario, num_envs, set=dict(set) if set else None, **settings
        )
        self.num_envs = num_envs
        self.single_observation_space, self.single_action_space = _spaces()
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._rng = np.random.default_rng()

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[np.ndarray, Dict[str, Any]]:
        if seed is not None:
            self._rng = np.random.default_rng(seed)
            base = int(seed)
        else:
            base = int(self._rng.integers(0, 2**63))
        return self._core.reset(base), {}

    def step(
        self, actions: Any
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Dict[str, Any]]:
        a = np.asarray(actions, dtype=np.float64).reshape(self.num_envs, 2)
        obs, rewards, terminated, truncated, success, reasons = self._core.step(a)
        info = {"success": success, "reason": np.asarray(reasons, dtype=object)}
        return obs, rewards, terminated, truncated, info


gymnasium.register(
    id=ENV_ID,
    entry_point="plumetrace.gym:PlumeTracingEnv",
    vector_entry_point="plumetrace.gym:PlumeTracingVecEnv",
)
