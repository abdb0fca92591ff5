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
    ({"panorama_shape": 48}, ["panorama_shape", "(H, W)", "48"]),
    ({"sky_color": 5}, ["sky_color", "three RGB", "5"]),
    ({"obs_keys": None}, ["obs_keys", "None", "panorama"]),
    ({"obs_keys": "panorama"}, ["obs_keys", "'panorama'", "list or tuple"]),
    ({"omni_size": 100.5, "obs_keys": ("omni", "goal")}, ["omni_size", "integer", "100.5"]),
    ({"supersampling": True}, ["supersampling", "integer", "True"]),
    ({"vfov_deg": "60"}, ["vfov_deg", "'60'"]),
    ({"stop_threshold": "a"}, ["stop_threshold", "[0, 1)", "'a'"]),
    ({"lighting_change": None}, ["lighting_change", "None"]),
    ({"camera_height": True}, ["camera_height", "True"]),
    ({"max_speed": 1e9}, ["max_speed", "100 rad/s", "3.5 m/s"]),
    ({"max_yaw_rate": 1e9}, ["max_yaw_rate", "100 rad/s"]),
    ({"bogus": 1, "other": 2}, ["['bogus', 'other']", "camera_height", "start_distance"]),
    ({"scene": "mesh:MESH?bounds=0,0,1000,1000"}, ["100 m a side", "bounds"]),
])
def test_bad_kwargs(kwargs, words, tmp_path):
    if str(kwargs.get("scene", "")).startswith("mesh:MESH"):
        from homing_gym.scenes.mesh_example import write_example_room
        write_example_room(tmp_path / "room.glb")
        kwargs = {**kwargs, "scene": kwargs["scene"].replace("MESH", str(tmp_path / "room.glb"))}
    with pytest.raises(ValueError) as err:
        env = gym.make(ENV, **kwargs)
        env.reset(seed=0)
        env.close()
    for word in words:
        assert word in str(err.value)


def test_numpy_numbers_are_numbers():
    env = gym.make(ENV, camera_height=np.float32(0.2), lighting_change=np.float64(0.5),
                   panorama_shape=np.array([16, 64]))
    env.reset(seed=0)
    assert env.observation_space["panorama"].shape == (16, 64, 3)
    env.close()


@pytest.mark.parametrize("options, words", [
    ({"start": (1.19, 1.19, 0.0)}, ["start", "wall or object", "0.16 m", "0.010 m free"]),
    ({"start": (-0.4, 0.5, 0.0)}, ["start", "wall or object"]),      # inside a cylinder
    ({"home": (-0.35, 0.55, 0.0)}, ["home", "wall or object", "0.000 m free"]),
    ({"home": "abc"}, ["home", "'abc'", "finite pose"]),
    ("home", ["reset options", "dict", "'home'"]),
])
def test_reset_options_must_leave_the_robot_in_free_space(make_env, options, words):
    env = make_env(panorama_shape=(16, 64))
    with pytest.raises(ValueError) as err:
        env.reset(seed=0, options=options)
    for word in words:
        assert word in str(err.value)
    # a home near a cylinder (the robot can come within 0.15 m of it) stays allowed
    _, info = env.reset(seed=0, options={"home": (0.2, -0.3, 1.0)})
    assert np.allclose(info["home_pose"], (0.2, -0.3, 1.0))


@pytest.mark.parametrize("pose", [(np.nan, 0.0, 0.0), (0.0, 0.0, np.inf), (0.0, 0.0), "abc"])
def test_pictures_at_a_pose_need_a_finite_pose(make_env, pose):
    """Not a sky-only picture: a NaN pose is refused by name."""
    env = make_env(panorama_shape=(16, 64)).unwrapped
    env.reset(seed=0)
    for render in (env.render_panorama, env.render_view):
        with pytest.raises(ValueError, match="three finite numbers"):
            render(pose)
    assert env.render_panorama((0.0, 0.0, 0.0)).shape == (16, 64, 3)


@pytest.mark.parametrize("env_id, jitter, words", [
    ("homing_gym/RouteFollowing-v0", 100.0, ["start_jitter 100.0 m", "route's start",
                                            "hallway", "at most 0.473 m fits"]),   # (0.85 - 0.18) / sqrt 2
    ("homing_gym/WorkLocations-v0", 0.3, ["start_jitter 0.3 m", "'bedroom'", "house",
                                         "at most 0.190 m fits"]),   # (0.45 - 0.18) / sqrt 2
])
def test_start_jitter_must_fit_the_room_around_the_start(env_id, jitter, words):
    with pytest.raises(ValueError) as err:
        gym.make(env_id, start_jitter=(jitter, 0.0))
    for word in words:
        assert word in str(err.value)
    # what the message says fits does fit: every start stays clear of walls and objects
    fits = float(str(err.value).split("at most ")[1].split(" m")[0])
    env = gym.make(env_id, start_jitter=(fits, 0.0), panorama_shape=(16, 128))
    from homing_gym.scenes.base import clearance
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert clearance(env.unwrapped.scene, info["start_pose"][:2]) >= 0.16
    env.close()


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
