"""homing-gym: Gymnasium environments for visual homing with a panoramic-camera robot.

>>> import gymnasium as gym, homing_gym
>>> gym.register_envs(homing_gym)
>>> env = gym.make("homing_gym/LocalHoming-v0")
"""

from __future__ import annotations

from functools import partial

import gymnasium as gym

from homing_gym.native_output import native_output_captured

with native_output_captured():     # PyBullet's build-time banner goes to the raw stderr
    import pybullet  # noqa: F401

__version__ = "0.2.0"

#: Registered env ids, with their entry points and step limits.
_ENVS = {
    "homing_gym/LocalHoming-v0": ("homing_gym.envs:LocalHomingEnv", 500),
    "homing_gym/RouteFollowing-v0": ("homing_gym.envs:RouteFollowingEnv", 1000),
    "homing_gym/LongRangeHoming-v0": ("homing_gym.envs:LongRangeHomingEnv", 2500),
    "homing_gym/LandmarkNavigation-v0": ("homing_gym.envs:LandmarkNavigationEnv", 3000),
    "homing_gym/WorkLocations-v0": ("homing_gym.envs:WorkLocationsEnv", 1500),
}
ENV_IDS: tuple[str, ...] = tuple(_ENVS)


def _native_vector_env(env_id: str, **kwargs):
    """The vector entry point of every id: ``gym.make_vec(env_id, num_envs=N,
    vectorization_mode="vector_entry_point", **kwargs)`` makes a
    :class:`homing_gym.vector.native.NativeVectorEnv`."""
    from homing_gym.vector.native import NativeVectorEnv

    return NativeVectorEnv(env_id, **kwargs)


def register_envs() -> None:
    """Register every env id with Gymnasium; calling it again changes nothing."""
    for env_id, (entry_point, steps) in _ENVS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry_point, max_episode_steps=steps,
                         vector_entry_point=partial(_native_vector_env, env_id))


register_envs()

from homing_gym.actions import DiscreteAction  # noqa: E402
from homing_gym.env import HomingEnv  # noqa: E402
from homing_gym.geometry import FOOT  # noqa: E402
from homing_gym.tasks.work_locations import TAUGHT_KEYS  # noqa: E402
from homing_gym.envs import (LandmarkNavigationEnv, LocalHomingEnv,  # noqa: E402
                             LongRangeHomingEnv, RouteFollowingEnv, WorkLocationsEnv)

__all__ = ["ENV_IDS", "FOOT", "TAUGHT_KEYS", "DiscreteAction", "HomingEnv", "LandmarkNavigationEnv", "LocalHomingEnv",
           "LongRangeHomingEnv", "RouteFollowingEnv", "WorkLocationsEnv",
           "register_envs", "__version__"]

from homing_gym.cli import import_listed_modules  # noqa: E402

import_listed_modules()     # a user's scenes and env ids in worker processes (--import)
