"""The one episode loop of the package: every evaluation, demo, field, figure and
imitation run goes through :func:`rollout`.

A policy is anything with stable-baselines3's ``predict(obs, state=None,
episode_start=None) -> (action, state)``; optional ``reset(seed)``, ``check_env(env)``,
``configure(MotionSpec)``, ``needs_env``/``attach_env(env)`` (oracles only) and
``needs_next_observation()`` are used when present. The loop reads the ground truth it
records from ``info`` (``pose`` after reset and after every step), never from the env's
internals.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np

from homing_baselines.motion import MotionSpec

#: ``on_step(t, obs, action, info) -> stop``: called before step ``t`` (0-based) is taken,
#: with the observation the action was chosen from and the latest ``info`` (the reset
#: info at ``t = 0``); returning True ends the episode there, the action not taken.
StepHook = Callable[[int, dict, Any, dict], bool | None]


@dataclass
class Rollout:
    """One episode: ``poses`` ``(steps + 1, 3)`` the robot's true poses (x, y, yaw;
    metres, radians) after reset and after each step, from ``info["pose"]``; the reset
    and the last ``info``; why it ended (``stopped`` when the hook ended it)."""

    steps: int
    terminated: bool
    truncated: bool
    stopped: bool
    poses: np.ndarray
    reset_info: dict
    info: dict


def prepare_policy(policy, env: gym.Env) -> None:
    """Hand the policy what it may know: the command interface; the env itself only to
    controllers that declare ``needs_env`` (oracles)."""
    if hasattr(policy, "check_env"):
        policy.check_env(env)
    if hasattr(policy, "configure"):
        policy.configure(MotionSpec.from_env(env))
    if getattr(policy, "needs_env", False):
        policy.attach_env(env)


def rollout(env: gym.Env, policy, seed: int, options: Mapping[str, Any] | None = None,
            on_step: StepHook | None = None, max_steps: int | None = None) -> Rollout:
    """Reset ``env`` with ``seed`` (and reset ``options``), reset the policy with the same
    seed, and run the policy until the episode ends, the hook stops it, or ``max_steps``
    steps were taken. A policy in the middle of a move that will not read the next
    observation lets the env skip rendering it (``HomingEnv.skip_next_images``)."""
    obs, info = env.reset(seed=int(seed), options=dict(options) if options else None)
    reset_info = info
    if hasattr(policy, "reset"):
        policy.reset(int(seed))
    poses = [np.asarray(info["pose"], dtype=np.float64)]
    state, t = None, 0
    terminated = truncated = stopped = False
    wants_next = getattr(policy, "needs_next_observation", None)
    while not (terminated or truncated) and (max_steps is None or t < max_steps):
        action, state = policy.predict(obs, state=state, episode_start=t == 0)
        if on_step is not None and on_step(t, obs, action, info):
            stopped = True
            break
        if wants_next is not None and not wants_next():
            env.unwrapped.skip_next_images()        # mid-move: the images would go unread
        obs, _, terminated, truncated, info = env.step(action)
        poses.append(np.asarray(info["pose"], dtype=np.float64))
        t += 1
    return Rollout(steps=t, terminated=bool(terminated), truncated=bool(truncated),
                   stopped=stopped, poses=np.array(poses), reset_info=reset_info, info=info)
