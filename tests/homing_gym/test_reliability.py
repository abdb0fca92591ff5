"""Bad input and misuse get one clear error, never a crash deep inside PyBullet or a hang."""

import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

SMALL = {"panorama_shape": (16, 64)}


def test_a_closed_env_says_so():
    env = gym.make("homing_gym/LocalHoming-v0", render_mode="rgb_array", **SMALL)
    env.reset(seed=0)
    env.close()
    for call in (lambda: env.reset(seed=0), lambda: env.step(env.action_space.sample()),
                 env.render):
        with pytest.raises(gym.error.ClosedEnvironmentError, match="closed"):
            call()


@pytest.mark.parametrize("action", [np.array([0.5 + 1j, 0.0]), ["0.5", "0"], [True, False],
                                    [0.5, True], None, "forward"])
def test_continuous_actions_must_be_real_numbers(action):
    env = gym.make("homing_gym/LocalHoming-v0", **SMALL)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(action)
    env.close()


@pytest.mark.parametrize("action", [np.nan, np.inf, None, True, 2.5, 4, -1, "1", 1 + 0j])
def test_discrete_actions_must_be_one_of_the_four(action):
    env = gym.make("homing_gym/LocalHoming-v0", action_type="discrete", **SMALL)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"discrete action .* is not one of 0 forward"):
        env.step(action)
    env.close()


def test_human_render_without_a_display_is_refused_before_pybullet(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    with pytest.raises(ValueError, match="render_mode='human'.*no X display"):
        gym.make("homing_gym/LocalHoming-v0", render_mode="human")


def test_landmark_navigation_takes_a_reward_mapping():
    # progress is the weight times the step's approach to the standing pose (metres)
    env = gym.make("homing_gym/LandmarkNavigation-v0", reward={"progress": 5.0, "time": 0.0},
                   panorama_shape=(16, 64))
    env.reset(seed=0)
    before = env.unwrapped.distance_to_goal
    _, _, _, _, info = env.step(np.array([1.0, 0.0], np.float32))
    moved = before - env.unwrapped.distance_to_goal
    assert abs(moved) > 1e-3
    assert info["rewards"]["progress"] == pytest.approx(5.0 * moved)
    assert info["rewards"]["time"] == 0.0
    env.close()


@pytest.mark.slow
def test_a_worker_that_cannot_start_ends_the_evaluation_once():
    out = subprocess.run(
        [sys.executable, "-m", "homing_train.harness.eval_command", "--policy", "random",
         "--episodes", "4", "--workers", "2", "--quiet", "--env-kwargs",
         '{"scene": "nowhere"}', "--out", "/tmp/never.json"],
        capture_output=True, text=True, timeout=180)
    assert out.returncode == 2
    assert out.stderr.count("unknown scene") == 1, out.stderr[-2000:]


@pytest.mark.parametrize("env_id, kwargs, words", [
    ("homing_gym/LocalHoming-v0", {"physics_substeps": 10**8}, "physics_substeps"),
    ("homing_gym/LocalHoming-v0", {"control_period": 1e5}, "control_period"),
    ("homing_gym/LocalHoming-v0", {"control_period": 0.01, "physics_substeps": 100},
     "physics steps"),
    ("homing_gym/LocalHoming-v0", {"success_radius": 1e6}, "success_radius"),
    ("homing_gym/LocalHoming-v0", {"start_distance": (0, 0)}, "start_distance"),
    ("homing_gym/WorkLocations-v0", {"panorama_shape": (-48, 256)}, "panorama_shape"),
])
def test_settings_that_would_hang_fling_or_end_at_once_are_refused(env_id, kwargs, words):
    with pytest.raises(ValueError, match=words):
        gym.make(env_id, **kwargs)
