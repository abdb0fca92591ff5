"""The setups of docs/integrations.md: Gymnasium vector envs, SB3 vec envs, rl-zoo3's
hyperparameter file, RecordVideo."""

from importlib import resources

import gymnasium as gym
import numpy as np
import pytest
import yaml

import homing_gym  # noqa: F401  (registers the env ids)

SMALL = {"panorama_shape": (16, 64)}


def test_gymnasium_sync_vector_env_steps_every_copy():
    envs = gym.make_vec("homing_gym/LocalHoming-v0", num_envs=2, vectorization_mode="sync",
                        **SMALL)
    obs, _ = envs.reset(seed=0)
    assert obs["panorama"].shape == (2, 16, 64, 3) and obs["panorama"].dtype == np.uint8
    obs, reward, terminated, truncated, _ = envs.step(envs.action_space.sample())
    assert reward.shape == (2,)
    envs.close()


@pytest.mark.slow
def test_gymnasium_async_vector_env_with_spawn():
    envs = gym.make_vec("homing_gym/LocalHoming-v0", num_envs=2, vectorization_mode="async",
                        vector_kwargs={"context": "spawn"}, **SMALL)
    obs, _ = envs.reset(seed=0)
    assert obs["goal"].shape == (2, 16, 64, 3)
    envs.close()


def test_native_vector_env_and_its_sb3_view_train_a_short_ppo_run():
    from stable_baselines3 import PPO

    from homing_train.learning.extractor import policy_kwargs_for
    from homing_train.learning.native_vec_env import native_vec_env

    envs = gym.make_vec("homing_gym/LocalHoming-v0", num_envs=2,
                        vectorization_mode="vector_entry_point", **SMALL)
    obs, _ = envs.reset(seed=0)
    assert obs["panorama"].shape == (2, 16, 64, 3)
    assert envs.step(envs.action_space.sample())[1].shape == (2,)
    envs.close()
    venv = native_vec_env("homing_gym/LocalHoming-v0", [SMALL] * 2)
    model = PPO("MultiInputPolicy", venv, n_steps=32, batch_size=32, n_epochs=1,
                policy_kwargs=policy_kwargs_for("panorama"))
    model.learn(64)
    assert model.num_timesteps == 64
    venv.close()


def test_sb3_make_vec_env_and_a_short_ppo_run():
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env

    from homing_train.learning.extractor import policy_kwargs_for

    venv = make_vec_env("homing_gym/LocalHoming-v0", n_envs=2, seed=0,
                        env_kwargs={**SMALL, "action_type": "discrete"})
    model = PPO("MultiInputPolicy", venv, n_steps=16, batch_size=16, n_epochs=1,
                policy_kwargs=policy_kwargs_for("panorama"), device="cpu")
    model.learn(32)
    assert model.num_timesteps == 32
    venv.close()


def test_sb3_default_cnn_takes_the_pages_36_pixel_panoramas():
    # the page's first snippet: SB3's own NatureCNN, which needs images >= 36 pixels high
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env

    venv = make_vec_env("homing_gym/LocalHoming-v0", n_envs=2, seed=0,
                        env_kwargs={"panorama_shape": (36, 128), "action_type": "discrete"})
    model = PPO("MultiInputPolicy", venv, n_steps=16, batch_size=16, n_epochs=1, device="cpu")
    model.learn(32)
    assert model.num_timesteps == 32
    venv.close()


def test_rlzoo_hyperparameter_file_builds_the_package_extractor():
    from homing_train.learning.extractor import PanoramaGoalExtractor

    path = resources.files("homing_train.learning") / "hyperparams" / "rlzoo_ppo.yml"
    entry = yaml.safe_load(path.read_text())["homing_gym/LocalHoming-v0"]
    assert entry["policy"] == "MultiInputPolicy"
    kwargs = eval(entry["policy_kwargs"])  # what rl-zoo3 does with this string
    assert kwargs["features_extractor_class"] is PanoramaGoalExtractor
    assert set(entry) - {"n_envs", "n_timesteps", "policy", "policy_kwargs"} <= set(
        __import__("inspect").signature(__import__("stable_baselines3").PPO).parameters)


def test_record_video_writes_an_mp4(tmp_path):
    pytest.importorskip("moviepy", reason="the [video] extra is not installed")
    env = gym.make("homing_gym/LocalHoming-v0", render_mode="rgb_array",
                   max_episode_steps=5, **SMALL)
    env = gym.wrappers.RecordVideo(env, str(tmp_path / "videos"), episode_trigger=lambda i: i == 0)
    env.reset(seed=0)
    done = False
    while not done:
        *_, terminated, truncated, _ = env.step(env.action_space.sample())
        done = terminated or truncated
    env.close()
    videos = list((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 0

