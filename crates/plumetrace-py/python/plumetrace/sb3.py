"""Stable-Baselines3 on the plume-tracing environment (needs ``stable-baselines3``).

``PlumeTracingSB3VecEnv`` is an SB3 ``VecEnv`` over the vectorised environment stepped in Rust
(``plumetrace.gym.PlumeTracingVecEnv`` in its same-step autoreset mode, as SB3 expects: a
``done`` environment's ``info`` holds ``terminal_observation`` and ``TimeLimit.truncated``,
beside the environment's own keys ``plumetrace.gym.INFO_KEYS``)::

    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor
    from plumetrace.sb3 import PlumeTracingSB3VecEnv

    env = VecMonitor(PlumeTracingSB3VecEnv(num_envs=4, scenario="demo"))
    model = PPO("MlpPolicy", env, seed=1).learn(20_000)

The single environment (``plumetrace.gym.PlumeTracingEnv``) passes SB3's own ``check_env``; it
also works through SB3's ``DummyVecEnv``, one Python environment per copy.
"""

from __future__ import annotations

from typing import Any, Iterable, List, Mapping, Optional, Sequence, Type, Union

import numpy as np

try:
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv
except ImportError as e:  # pragma: no cover - depends on the installation
    raise ImportError(
        "plumetrace.sb3 needs stable-baselines3 (pip install stable-baselines3)"
    ) from e

from .gym import INFO_KEYS, PlumeTracingVecEnv

__all__ = ["PlumeTracingSB3VecEnv"]

Indices = Union[None, int, Iterable[int]]


class PlumeTracingSB3VecEnv(VecEnv):
    """``num_envs`` copies of the environment on ``scenario`` as one SB3 ``VecEnv``; ``set``
    and ``**settings`` as for ``plumetrace.gym.PlumeTracingEnv``. ``seed(s)`` (or ``seed=s``
    here) gives copy ``i`` the run seed ``s + i`` at the next reset, as SB3's own vectorised
    environments do; ``seeds`` (a list of run seeds) makes every episode fly one of them, as
    for ``plumetrace.gym.PlumeTracingVecEnv``."""

    def __init__(
        self,
        num_envs: int = 4,
        scenario: str = "demo",
        set: Optional[Mapping[str, Any]] = None,
        seed: Optional[int] = None,
        seeds: Optional[Sequence[int]] = None,
        **settings: Any,
    ) -> None:
        self._vec = PlumeTracingVecEnv(
            num_envs, scenario, set=set, autoreset_mode="same_step", seeds=seeds, **settings
        )
        super().__init__(
            num_envs, self._vec.single_observation_space, self._vec.single_action_space
        )
        self._actions: Optional[np.ndarray] = None
        if seed is not None:
            self.seed(seed)

    def reset(self) -> np.ndarray:
        seeds: Sequence[Optional[int]] = self._seeds
        obs, info = self._vec.reset(seed=None if all(s is None for s in seeds) else list(seeds))
        self.reset_infos = [self._row(info, i) for i in range(self.num_envs)]
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        if self._actions is None:
            raise RuntimeError("step_wait() without step_async(actions)")
        obs, rewards, terminated, truncated, info = self._vec.step(self._actions)
        self._actions = None
        dones = terminated | truncated
        infos: List[dict] = []
        for i in range(self.num_envs):
            if dones[i]:
                row = self._row(info["final_info"], i)
                row["terminal_observation"] = info["final_obs"][i]
                row["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
            else:
                row = self._row(info, i)
            infos.append(row)
        return obs, rewards.astype(np.float32), dones, infos

    @staticmethod
    def _row(info: Mapping[str, Any], i: int) -> dict:
        return {k: info[k][i].item() if hasattr(info[k][i], "item") else info[k][i]
                for k in INFO_KEYS}

    def close(self) -> None:
        self._vec.close()

    def get_attr(self, attr_name: str, indices: Indices = None) -> List[Any]:
        value = getattr(self._vec, attr_name)
        return [value for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Indices = None) -> None:
        raise AttributeError(
            f"cannot set {attr_name!r}: the copies are stepped together in Rust and share "
            "their settings (make a new PlumeTracingSB3VecEnv)"
        )

    def env_method(self, method_name: str, *args: Any, indices: Indices = None,
                   **kwargs: Any) -> List[Any]:
        raise AttributeError(
            f"cannot call {method_name!r} on one copy: the copies are stepped together in Rust "
            "(use plumetrace.gym.PlumeTracingEnv in DummyVecEnv for per-copy methods)"
        )

    def env_is_wrapped(self, wrapper_class: Type[Any], indices: Indices = None) -> List[bool]:
        return [False for _ in self._get_indices(indices)]
