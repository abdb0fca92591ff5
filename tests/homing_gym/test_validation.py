"""Bad input fails early with a ValueError that names the bad value and what is allowed."""

import math

import gymnasium as gym
import numpy as np
import pytest

from homing_gym.scenes import Landmark, Scene, Wall, square_walls

ENV = "homing_gym/LocalHoming-v0"


@pytest.mark.parametrize("kwargs, words", [
    ({"scene": "moon"}, ["moon", "arena", "random_arena"]),
    ({"scene": ["random_rooms", "random_nature"]}, ["['random_rooms', 'random_nature']",
                                                   "homing-train"]),
    ({"scene": 3}, ["unknown scene 3", "mesh:PATH"]),
    ({"panorama_shape": (4, 64)}, ["panorama_shape", "(4, 64)"]),
    ({"panorama_shape": (48, 0)}, ["panorama_shape"]),
    ({"vfov_deg": 179}, ["vfov"]),
    ({"n_views": 5}, ["n_views", "5"]),
    ({"renderer": "vulkan"}, ["vulkan", "tiny", "egl"]),
    ({"action_type": "joystick"}, ["joystick", "continuous", "discrete"]),
    ({"obs_keys": ("panorama", "depth")}, ["depth", "omni"]),
    ({"obs_keys": ()}, ["obs_keys"]),
    ({"render_mode": "ascii"}, ["ascii", "rgb_array"]),
    ({"start_distance": (1.0, 0.5)}, ["start_distance"]),
    ({"start_distance": (0.3, 9.0)}, ["start_distance", "arena"]),
    ({"success_radius": 0.0}, ["success_radius"]),
    ({"success_on": "never"}, ["never", "reach", "stop"]),
    ({"odometry_noise": -1.0}, ["odometry_noise"]),
    ({"max_speed": math.nan}, ["max_speed"]),
    ({"physics_substeps": 0}, ["physics_substeps"]),
    ({"reward": {"progres": 10.0}}, ["progres", "progress", "collision"]),
    ({"reward": {"success": math.inf}}, ["success", "inf"]),
    ({"reward": 10.0}, ["reward", "10.0"]),
])
def test_bad_kwargs(kwargs, words):
    with pytest.raises(ValueError) as err:
        env = gym.make(ENV, **kwargs)
        env.reset(seed=0)
        env.close()
    for word in words:
        assert word in str(err.value)


@pytest.mark.parametrize("action", [np.array([np.nan, 0.0], np.float32),
                                    np.array([0.0, np.inf], np.float32),
                                    np.array([1.0, 0.0, 0.0], np.float32)])
def test_bad_continuous_actions(make_env, action):
    env = make_env()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(action)


@pytest.mark.parametrize("action", [4, -1, 1.5])
def test_bad_discrete_actions(make_env, action):
    env = make_env(action_type="discrete")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(action)


def test_step_before_reset(make_env):
    with pytest.raises(RuntimeError, match="reset"):
        make_env().unwrapped.step(np.zeros(2, np.float32))


def test_landmark_outside_arena():
    lm = Landmark(position=(1.5, 0.0))
    with pytest.raises(ValueError, match=r"outside the scene bounds.*\[-1.2, 1.2\]"):
        Scene("bad", ((-1.2, -1.2), (1.2, 1.2)), walls=square_walls(2.4), landmarks=(lm,))


@pytest.mark.parametrize("kwargs", [{"radius": 0.0}, {"radius": -0.1}, {"height": 0},
                                    {"shape": "box", "extent": (0.2, -0.1)}])
def test_non_positive_sizes(kwargs):
    with pytest.raises(ValueError, match="positive"):
        Landmark(position=(0, 0), **kwargs)


def test_unknown_shape_texture_and_degenerate_wall():
    with pytest.raises(ValueError, match="cone"):
        Landmark(position=(0, 0), shape="cone")
    with pytest.raises(ValueError, match="marble"):
        Landmark(position=(0, 0), texture="marble")
    with pytest.raises(ValueError, match="length"):
        Wall((0, 0), (0, 0))


def test_a_stop_away_from_home_costs_the_wrong_stop_weight_and_ends_the_episode(make_env):
    env = make_env(scene="arena", action_type="discrete", success_on="stop",
                   start_distance=(1.0, 1.2), reward={"wrong_stop": 2.0, "time": 0.0},
                   panorama_shape=(16, 64))
    env.reset(seed=0)
    _, reward, terminated, _, info = env.step(3)              # stop, about 1 m from home
    assert terminated and not info["is_success"]
    assert info["rewards"]["wrong_stop"] == -2.0
    assert reward == pytest.approx(sum(info["rewards"].values()))
    default = make_env(scene="arena", action_type="discrete", success_on="stop",
                       start_distance=(1.0, 1.2), panorama_shape=(16, 64))
    default.reset(seed=0)
    assert default.step(3)[4]["rewards"]["wrong_stop"] == 0.0


def test_reward_weights_from_a_mapping_scale_the_progress_term(make_env):
    env = make_env(reward={"progress": 10.0, "time": 0.0})
    env.reset(seed=0)
    start = env.unwrapped.distance_to_goal
    _, reward, _, _, info = env.step(np.array([1.0, 0.0], np.float32))
    moved = start - env.unwrapped.distance_to_goal
    assert info["rewards"]["progress"] == pytest.approx(10.0 * moved)
    assert info["rewards"]["time"] == 0.0
