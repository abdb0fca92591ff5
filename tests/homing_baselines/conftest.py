"""Fixtures of the controllers' tests: Yu & Kim's arena as an env, and panoramas rendered
in it at given poses."""

import gymnasium as gym
import numpy as np
import pytest

import homing_gym  # noqa: F401  (registers the env ids)


@pytest.fixture(scope="module")
def arena(request):
    """LocalHoming-v0 in the arena reset with seed 0, made with the test module's
    ``ARENA`` kwargs (e.g. ``obs_keys``, ``start_distance``)."""
    env = gym.make("homing_gym/LocalHoming-v0", **getattr(request.module, "ARENA", {}))
    env.reset(seed=0)
    yield env
    env.close()


@pytest.fixture(scope="module")
def panorama_at(arena):
    """``panorama_at(pose)``: the panorama at ``pose`` (x, y, yaw) in the arena, the robot
    put there."""
    def render(pose):
        inner = arena.unwrapped
        inner.sim.robot.set_pose(*pose)
        return inner.render_panorama(np.asarray(pose, dtype=np.float64))

    return render
