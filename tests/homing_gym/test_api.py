"""Gymnasium and stable-baselines3 conformance, registration, spaces, rendering."""

import multiprocessing as mp

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import homing_gym


@pytest.mark.parametrize("env_id", homing_gym.ENV_IDS)
def test_gymnasium_check_env(env_id):
    env = gym.make(env_id)
    gym_check_env(env.unwrapped, skip_render_check=True)
    env.close()


@pytest.mark.parametrize("env_id", homing_gym.ENV_IDS)
@pytest.mark.parametrize("kwargs", [{}, {"action_type": "discrete"},
                                    {"obs_keys": ("panorama", "goal", "omni", "signature",
                                                  "goal_signature", "odometry")}])
def test_sb3_check_env(env_id, kwargs):
    env = gym.make(env_id, **kwargs)
    sb3_check_env(env, warn=False)
    env.close()


def test_registration_is_idempotent():
    before = {k for k in gym.registry if k.startswith("homing_gym/")}
    homing_gym.register_envs()
    gym.register_envs(homing_gym)
    after = {k for k in gym.registry if k.startswith("homing_gym/")}
    assert before == after == set(homing_gym.ENV_IDS)
    assert gym.spec("homing_gym/LocalHoming-v0").max_episode_steps == 500


def test_user_example(make_env):
    env = make_env(render_mode="rgb_array")
    obs, info = env.reset(seed=0)
    assert set(obs) == {"panorama", "goal"}
    for key in ("panorama", "goal"):
        assert obs[key].dtype == np.uint8 and obs[key].shape == (48, 256, 3)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    assert isinstance(reward, float)
    for key in ("pose", "goal_pose", "distance_to_goal", "is_success", "collision", "rewards"):
        assert key in info
    assert abs(reward - sum(info["rewards"].values())) < 1e-9
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert frame.shape[1] > frame.shape[0]


def test_optional_observation_keys(make_env):
    keys = ("panorama", "goal", "omni", "goal_omni", "signature", "goal_signature", "odometry")
    env = make_env(obs_keys=keys, panorama_shape=(32, 128), omni_size=64)
    obs, _ = env.reset(seed=1)
    assert set(obs) == set(keys)
    assert obs["omni"].shape == (64, 64, 3) and obs["omni"].dtype == np.uint8
    assert obs["signature"].shape == (128,) and obs["signature"].dtype == np.float32
    assert obs["odometry"].shape == (3,) and obs["odometry"].dtype == np.float32
    assert env.observation_space.contains(obs)


def test_previous_is_the_panorama_of_the_step_before(make_env):
    """``previous``: the current panorama at reset, then each step the panorama the
    step before showed; a reset starts again from the new view."""
    env = make_env(obs_keys=("panorama", "goal", "previous"), action_type="discrete")
    obs, _ = env.reset(seed=2)
    np.testing.assert_array_equal(obs["previous"], obs["panorama"])
    shown = [obs["panorama"]]
    for action in (0, 1, 0, 2):                      # forward, turns: the view changes
        obs, *_ = env.step(action)
        np.testing.assert_array_equal(obs["previous"], shown[-1])
        shown.append(obs["panorama"])
    assert not np.array_equal(shown[-1], shown[-2])
    obs, _ = env.reset(seed=3)
    np.testing.assert_array_equal(obs["previous"], obs["panorama"])
    assert env.observation_space.contains(obs)


def test_goal_is_home_snapshot(make_env):
    """The goal image equals the panorama rendered at the home pose."""
    env = make_env()
    obs, info = env.reset(seed=3)
    u = env.unwrapped
    u.sim.robot.set_pose(*info["goal_pose"])
    assert np.array_equal(u.render_panorama(u.sim.robot.pose()), obs["goal"])


def test_discrete_actions(make_env):
    env = make_env(action_type="discrete")
    assert env.action_space == gym.spaces.Discrete(4)
    env.reset(seed=0)
    pose0 = env.unwrapped.pose.copy()
    for _ in range(5):
        env.step(1)  # turn left in place
    pose1 = env.unwrapped.pose
    assert np.hypot(*(pose1[:2] - pose0[:2])) < 0.01
    assert 0.6 < (pose1[2] - pose0[2]) % (2 * np.pi) < 0.9   # 0.5 s at 1.5 rad/s


def _make_and_step(queue):
    import gymnasium as gym

    import homing_gym

    gym.register_envs(homing_gym)
    env = gym.make("homing_gym/LocalHoming-v0")
    obs, _ = env.reset(seed=4)
    env.step(env.action_space.sample())
    queue.put(obs["panorama"].shape)
    env.close()


def test_make_in_spawned_subprocess():
    ctx = mp.get_context("spawn")
    queue = ctx.Queue()
    proc = ctx.Process(target=_make_and_step, args=(queue,))
    proc.start()
    shape = queue.get(timeout=120)
    proc.join(timeout=60)
    assert proc.exitcode == 0 and shape == (48, 256, 3)


def test_async_vector_env_two_workers():
    env = gym.make_vec("homing_gym/LocalHoming-v0", num_envs=2, vectorization_mode="async",
                       vector_kwargs={"context": "spawn"})
    assert isinstance(env, gym.vector.AsyncVectorEnv)
    obs, info = env.reset(seed=[10, 11])
    assert obs["panorama"].shape == (2, 48, 256, 3)
    assert not np.array_equal(obs["goal"][0], obs["goal"][1])
    for _ in range(3):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    assert reward.shape == (2,)
    env.close()


def test_reset_options_place_home_and_start(make_env):
    env = make_env()
    obs, info = env.reset(seed=0, options={"home": (0.0, 0.0, 0.5), "start": (0.8, -0.3, 2.0)})
    assert np.allclose(info["goal_pose"], (0.0, 0.0, 0.5))
    assert np.allclose(info["pose"], (0.8, -0.3, 2.0), atol=1e-6)
    assert info["distance_to_goal"] == pytest.approx(np.hypot(0.8, 0.3))
    with pytest.raises(ValueError, match="start"):
        env.reset(seed=0, options={"start": (5.0, 0.0, 0.0)})
    with pytest.raises(ValueError, match="teleport"):
        env.reset(seed=0, options={"teleport": True})


def test_goal_step_is_a_second_snapshot_one_step_ahead_of_home(make_env):
    env = make_env(obs_keys=("panorama", "goal", "goal_step"), goal_step_length=0.2)
    obs, info = env.reset(seed=2)
    home = info["goal_pose"]
    ahead = home + np.array([0.2 * np.cos(home[2]), 0.2 * np.sin(home[2]), 0.0])
    u = env.unwrapped
    u.sim.robot.set_pose(*ahead)
    assert np.array_equal(u.render_panorama(u.sim.robot.pose()), obs["goal_step"])
    assert not np.array_equal(obs["goal"], obs["goal_step"])
