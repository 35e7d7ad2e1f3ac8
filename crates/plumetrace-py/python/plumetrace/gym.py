"""A Gymnasium environment for plume tracing: the agent flies one vehicle of a scenario.

Importing this module registers ``plumetrace/PlumeTracing-v1``::

    import gymnasium as gym
    import plumetrace.gym

    env = gym.make("plumetrace/PlumeTracing-v1", scenario="demo")
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

Action (``Box(-1, 1, (3,))``): ``turn`` (heading change of ``turn * max_turn_deg`` from the
measured heading, default 30 deg), ``speed`` (from ``speed_min_mps`` = 0.3 to
``speed_max_mps`` = 1.5 m/s) and ``declare`` (above ``declare_threshold``, default 0.5: the
vehicle declares the source at its position estimate, which ends the episode). The vehicle
keeps its altitude (an AUV) or the surface. An action takes effect at the vehicle's next
decision, one decision period after the observation it answers.

Reward (it may use the truth; the observation never does): ``-decision_period_s /
time_limit`` per step (a whole episode sums to -1); ``+detection_reward`` (0.01) per step with a
detection, until the episode's detection rewards reach ``detection_reward_max`` (0.2); ``+1``
for a declaration within ``success_radius_m`` (default: the scenario's
``mission.success_radius_m``) of a source, ``-1`` for one farther (both terminated); ``-1`` on
leaving the op-area (once inside it) or any other end of the mission (terminated); truncated at
the scenario's time limit. **The bound**: an episode with a correct declaration returns at
least 0; every other episode (lingering in the plume to the time limit among them) returns at
most ``detection_reward_max - 1 + decision_period_s / time_limit`` (-0.8 at the defaults), so
no policy gains by staying in the plume instead of declaring. ``info`` has the same keys at
every reset and step, in every vector mode (``INFO_KEYS``): ``run_seed``, ``time_s``,
``success``, ``error_m`` (the declaration's distance from the nearest source, -1 without one)
and ``reason``: empty while the episode goes on, then why it ended:

=================  ===========  =====================================================
reason             ends as      meaning
=================  ===========  =====================================================
declared           terminated   a declaration within ``success_radius_m`` (+1)
false_declaration  terminated   a declaration farther, or without a position (-1)
left_op_area       terminated   outside the op-area after being inside it (-1)
left_domain        terminated   the vehicle left the simulated domain (-1)
collided           terminated   the vehicle entered an obstacle (-1)
time_limit         truncated    the scenario's time limit
=================  ===========  =====================================================

Settings are checked at ``gym.make``: a keyword that is neither a setting nor a valid scenario
override fails there, with the settings' names and the one a typo meant
(``max_turn_dgr`` -> ``max_turn_deg``).

``reset(seed=s)`` makes the episode's run seed ``s``: the plume, the flow, the sensors'
noise and, for a family file, the site all follow from it, so the episode meets the same plume
as ``plumetrace.run(scenario, seed=s)``. Without a seed, the next run seed is drawn from the
environment's generator (seeded by the last seed given).

A trained policy flies as a planner: ``PolicyPlanner(policy, scenario, seed)`` is a Python
planner for ``plumetrace.run`` that gives ``policy`` the environment's observations and turns
its actions into the environment's commands (the same decisions as in the environment).
``plumetrace.sb3`` adapts the vectorised environment to Stable-Baselines3.
"""

from __future__ import annotations

import json
from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Union

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from . import _plumetrace

ENV_ID = "plumetrace/PlumeTracing-v1"
OBS_NAMES = tuple(_plumetrace.EnvCore.obs_names())
INFO_KEYS = tuple(_plumetrace.EnvCore.info_keys())
ACTION_NAMES = ("turn", "speed", "declare")
_LOW, _HIGH = _plumetrace.EnvCore.obs_bounds()
OBS_LOW = np.asarray(_LOW, dtype=np.float32)
OBS_HIGH = np.asarray(_HIGH, dtype=np.float32)

__all__ = [
    "ACTION_NAMES",
    "ENV_ID",
    "INFO_KEYS",
    "OBS_NAMES",
    "PlumeTracingEnv",
    "PlumeTracingVecEnv",
    "PolicyPlanner",
]


def _spaces() -> Tuple[spaces.Box, spaces.Box]:
    obs = spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)
    act = spaces.Box(-1.0, 1.0, shape=(len(ACTION_NAMES),), dtype=np.float32)
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
            1.5), ``success_radius_m`` (0-10000, the scenario's), ``detection_reward`` (0-1,
            0.01), ``detection_reward_max`` (0-0.9, 0.2), ``declare_threshold`` (-1 to 1, 0.5);
            any other keyword is a scenario override (a planner key, as for ``plumetrace.run``).
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

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
    ) -> Tuple[np.ndarray, Dict[str, Any]]:
        super().reset(seed=seed)
        run_seed = int(seed) if seed is not None else int(self.np_random.integers(0, 2**63))
        obs, info = self._core.reset(run_seed)
        return obs, dict(info)

    def step(self, action: Any) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        obs, reward, terminated, truncated, info = self._core.step(a)
        return obs, float(reward), bool(terminated), bool(truncated), dict(info)


def _with_masks(arrays: Mapping[str, Any], mask: np.ndarray) -> Dict[str, Any]:
    """Gymnasium's vector ``info``: each key's array and its mask ``_key``."""
    out: Dict[str, Any] = {}
    for k in INFO_KEYS:
        v = arrays[k]
        out[k] = np.asarray(v, dtype=object) if k == "reason" else np.asarray(v)
        out["_" + k] = mask.copy()
    return out


class PlumeTracingVecEnv(gymnasium.vector.VectorEnv):
    """``num_envs`` environments stepped together in Rust, in parallel threads (results do not
    depend on the thread count).

    ``autoreset_mode``: ``AutoresetMode.NEXT_STEP`` or ``"next_step"`` (default: after an episode ends, the next ``step`` resets
    that environment, its action ignored and its reward 0) or ``AutoresetMode.SAME_STEP`` or ``"same_step"`` (the step that ends
    an episode starts the next and returns its first observation; the ended episode's last
    observation and ``info`` are in ``info["final_obs"]`` and ``info["final_info"]``, as
    Gymnasium's synchronous vector environment gives them). ``reset(seed=s)`` gives environment
    ``i`` the run seed ``s + i`` (or ``s[i]`` for a list); its later episodes have seeds derived
    from that one. ``reset(options={"reset_mask": m})`` resets only the environments where the
    boolean array ``m`` is true. ``seeds`` (a list of run seeds, e.g. a benchmark task's tuning
    seeds) makes every episode fly one of them: seed ``d`` of the sequence above flies
    ``seeds[d % len(seeds)]``. ``info`` has the keys ``INFO_KEYS`` (each with its mask
    ``_key``) at every reset and step, as the synchronous and asynchronous vector modes give.
    """

    metadata: Dict[str, Any] = {
        "render_modes": [],
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        num_envs: int = 4,
        scenario: str = "demo",
        set: Optional[Mapping[str, Any]] = None,
        render_mode: Optional[str] = None,
        autoreset_mode: Union[AutoresetMode, str] = AutoresetMode.NEXT_STEP,
        seeds: Optional[Sequence[int]] = None,
        **settings: Any,
    ) -> None:
        if render_mode is not None:
            raise ValueError(f"render_mode {render_mode!r} is not supported")
        modes = {"next_step": AutoresetMode.NEXT_STEP, "same_step": AutoresetMode.SAME_STEP}
        mode = modes.get(str(autoreset_mode).lower()) or (
            autoreset_mode if autoreset_mode in modes.values() else None
        )
        if mode is None:
            raise ValueError(
                f"autoreset_mode {autoreset_mode!r} is not supported: AutoresetMode.NEXT_STEP "
                "('next_step') or AutoresetMode.SAME_STEP ('same_step')"
            )
        self.render_mode = None
        self.metadata = {**type(self).metadata, "autoreset_mode": mode}
        self._core = _plumetrace.VecEnvCore(
            scenario,
            num_envs,
            same_step=mode == AutoresetMode.SAME_STEP,
            seeds=[int(s) for s in seeds] if seeds is not None else None,
            set=dict(set) if set else None,
            **settings,
        )
        self.num_envs = num_envs
        self.single_observation_space, self.single_action_space = _spaces()
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._rng = np.random.default_rng()

    def reset(
        self,
        *,
        seed: Optional[Union[int, Sequence[Optional[int]]]] = None,
        options: Optional[Dict[str, Any]] = None,
    ) -> Tuple[np.ndarray, Dict[str, Any]]:
        n = self.num_envs
        mask = np.ones(n, dtype=np.bool_)
        if options and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"])
            if mask.shape != (n,) or mask.dtype != np.bool_ or not mask.any():
                raise ValueError(
                    f"options['reset_mask'] must be a boolean array of shape ({n},) with a "
                    f"True value, not {mask!r}"
                )
        if isinstance(seed, (list, tuple)):
            if len(seed) != n:
                raise ValueError(f"seed has {len(seed)} values for {n} environments")
            seeds = [int(s) if s is not None else int(self._rng.integers(0, 2**63)) for s in seed]
        elif seed is not None:
            self._rng = np.random.default_rng(seed)
            seeds = [int(seed) + i for i in range(n)]
        else:
            base = int(self._rng.integers(0, 2**63))
            seeds = [base + i for i in range(n)]
        obs, info = self._core.reset(seeds, mask=[bool(m) for m in mask])
        return obs, _with_masks(info, mask)

    def step(
        self, actions: Any
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Dict[str, Any]]:
        a = np.asarray(actions, dtype=np.float64).reshape(self.num_envs, len(ACTION_NAMES))
        obs, rewards, terminated, truncated, info, final = self._core.step(a)
        infos = _with_masks(info, np.ones(self.num_envs, dtype=np.bool_))
        if final is not None:
            ended, final_obs, final_info = final
            objs = np.full(self.num_envs, None, dtype=object)
            for i in np.flatnonzero(ended):
                objs[i] = final_obs[i]
            infos["final_obs"] = objs
            infos["_final_obs"] = ended.copy()
            infos["final_info"] = _with_masks(final_info, ended)
            infos["_final_info"] = ended.copy()
        return obs, rewards, terminated, truncated, infos


class PolicyPlanner:
    """A policy trained on the environment, flown as a Python planner (``plumetrace.run``,
    ``plumetrace.benchmark``): each decision gets the environment's observation of the snapshot,
    and the policy's action (turn, speed, declare) becomes the environment's command at the next
    decision, as in the environment. A declaration ends the vehicle's mission.

    Args:
        policy: ``policy(observation) -> action``, e.g. ``lambda o: model.predict(o,
            deterministic=True)[0]`` for a Stable-Baselines3 model.
        scenario: the scenario (or family file) flown, and ``seed`` its run seed (a family's
            site follows from it, and so do the op-area and the detection threshold the
            observation is scaled by).
        set, **settings: the environment's settings and overrides, as it was trained with.
    """

    def __init__(
        self,
        policy: Callable[[np.ndarray], Any],
        scenario: str,
        seed: int,
        set: Optional[Mapping[str, Any]] = None,
        **settings: Any,
    ) -> None:
        self._core = _plumetrace.ObsCore(
            str(scenario), int(seed), set=dict(set) if set else None, **settings
        )
        self._policy = policy
        self._action = np.zeros(len(ACTION_NAMES))
        self.decision_period_s = self._core.decision_period_s

    def decide(self, snapshot: Mapping[str, Any]) -> Dict[str, Any]:
        text = json.dumps(snapshot)
        command = dict(self._core.command(text, self._action))
        obs = self._core.observe(text)
        action = np.asarray(self._policy(obs), dtype=np.float64).reshape(-1)
        if action.shape != (len(ACTION_NAMES),):
            raise ValueError(
                f"the policy gave {action.shape[0]} action components, not 3 (turn, speed, declare)"
            )
        self._action = action
        return command


gymnasium.register(
    id=ENV_ID,
    entry_point="plumetrace.gym:PlumeTracingEnv",
    vector_entry_point="plumetrace.gym:PlumeTracingVecEnv",
)
