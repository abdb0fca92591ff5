"""Appearance augmentation of training images: the colour algebra against hand-computed
values, one transform per episode for the panorama and the goal alike, bad settings."""

import math

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.vec_env import DummyVecEnv

from homing_train.learning.augment import AugmentedImages, AugmentSettings, transformed
from homing_train.learning.train import TrainConfig

IDENTITY = AugmentSettings(hue=0.0, saturation=(1, 1), gain=(1, 1), brightness=(1, 1),
                           gamma=(1, 1))


def test_the_identity_settings_leave_every_pixel_as_it_was():
    images = np.random.default_rng(0).integers(0, 256, (2, 4, 8, 3), dtype=np.uint8)
    matrix, gamma = IDENTITY.draw(np.random.default_rng(1))
    np.testing.assert_allclose(matrix, np.eye(3), atol=1e-12)
    np.testing.assert_array_equal(transformed(images, matrix, gamma), images)


def test_no_saturation_gives_the_luma_in_every_channel():
    grey = AugmentSettings(hue=0.0, saturation=(0, 0), gain=(1, 1), brightness=(1, 1),
                           gamma=(1, 1))
    pixels = np.array([[255, 0, 0], [0, 255, 0], [0, 0, 255], [10, 200, 40]], np.uint8)
    out = transformed(pixels, *grey.draw(np.random.default_rng(0)))
    # Rec. 601: 0.299 R + 0.587 G + 0.114 B
    expected = np.rint([76.245, 149.685, 29.07, 0.299 * 10 + 0.587 * 200 + 0.114 * 40])
    np.testing.assert_array_equal(out, np.repeat(expected[:, None], 3, axis=1))


def test_a_third_of_a_turn_of_hue_moves_red_to_green_and_grey_stays_grey():
    settings = AugmentSettings(saturation=(1, 1), gain=(1, 1), brightness=(1, 1),
                               gamma=(1, 1))
    rng = np.random.default_rng(3)
    for _ in range(20):
        matrix, gamma = settings.draw(rng)
        grey = transformed(np.array([[90, 90, 90]], np.uint8), matrix, gamma)
        np.testing.assert_array_equal(grey, [[90, 90, 90]])
    turn = AugmentSettings(hue=2 * math.pi / 3, saturation=(1, 1), gain=(1, 1),
                           brightness=(1, 1), gamma=(1, 1))

    class Edge:                       # draws the largest rotation, counter-clockwise
        def uniform(self, low, high, size=None):
            return high if size is None else np.full(size, high)

    matrix, _ = turn.draw(Edge())
    np.testing.assert_array_equal(transformed(np.array([[200, 0, 0]], np.uint8), matrix, 1.0),
                                  [[0, 200, 0]])


def test_brightness_and_gamma_follow_the_formula():
    settings = AugmentSettings(hue=0.0, saturation=(1, 1), gain=(1, 1), brightness=(0.5, 0.5),
                               gamma=(2, 2))
    out = transformed(np.array([[200, 100, 255]], np.uint8),
                      *settings.draw(np.random.default_rng(0)))
    expected = np.rint(255 * (0.5 * np.array([200, 100, 255]) / 255) ** 2)
    np.testing.assert_array_equal(out, [expected])


class _Pictures(gym.Env):
    """Fixed images; the episode ends at the second step."""

    observation_space = gym.spaces.Dict({
        "panorama": gym.spaces.Box(0, 255, (2, 4, 3), np.uint8),
        "goal": gym.spaces.Box(0, 255, (2, 4, 3), np.uint8),
        "extra": gym.spaces.Box(-1, 1, (1,), np.float32)})
    action_space = gym.spaces.Discrete(2)

    def __init__(self):
        rng = np.random.default_rng(5)
        self.obs = {"panorama": rng.integers(0, 256, (2, 4, 3), dtype=np.uint8),
                    "goal": rng.integers(0, 256, (2, 4, 3), dtype=np.uint8),
                    "extra": np.zeros(1, np.float32)}
        self.t = 0

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return {k: v.copy() for k, v in self.obs.items()}, {}

    def step(self, action):
        self.t += 1
        return {k: v.copy() for k, v in self.obs.items()}, 0.0, self.t == 2, False, {}


def test_each_episode_has_one_transform_for_both_images_and_the_next_a_new_one():
    raw = _Pictures().obs
    env = AugmentedImages(DummyVecEnv([_Pictures, _Pictures]), AugmentSettings(), seed=0)
    first = env.reset()
    draws = list(env._draws)
    for i in range(2):
        for key in ("panorama", "goal"):
            np.testing.assert_array_equal(first[key][i], transformed(raw[key], *draws[i]))
    assert not np.array_equal(first["panorama"][0], first["panorama"][1])   # envs differ
    np.testing.assert_array_equal(first["extra"], 0.0)                      # untouched
    same, _, dones, _ = env.step(np.zeros(2, int))
    assert not dones.any()
    np.testing.assert_array_equal(same["goal"], first["goal"])
    after, _, dones, infos = env.step(np.zeros(2, int))
    assert dones.all()
    for i in range(2):               # the last view of the old episode in its colours
        np.testing.assert_array_equal(infos[i]["terminal_observation"]["panorama"],
                                      transformed(raw["panorama"], *draws[i]))
        np.testing.assert_array_equal(after["goal"][i], transformed(raw["goal"],
                                                                    *env._draws[i]))
        assert not np.array_equal(after["goal"][i], first["goal"][i])


def test_the_previous_view_is_augmented_in_its_episodes_colours():
    class WithPrevious(_Pictures):
        observation_space = gym.spaces.Dict({**_Pictures.observation_space.spaces,
                                             "previous": _Pictures.observation_space["goal"]})

        def __init__(self):
            super().__init__()
            self.obs["previous"] = self.obs["panorama"][::-1].copy()

    raw = WithPrevious().obs
    env = AugmentedImages(DummyVecEnv([WithPrevious]), AugmentSettings(), seed=3)
    assert env.image_keys == ("panorama", "goal", "previous")
    first = env.reset()
    np.testing.assert_array_equal(first["previous"][0],
                                  transformed(raw["previous"], *env._draws[0]))


@pytest.mark.parametrize("value, match", [
    ({"hue": 4.0}, "augment hue"),
    ({"saturation": [1.2, 0.5]}, "min 1.2 above max 0.5"),
    ({"gain": 2}, r"augment gain: a \[min, max\] pair"),
    ({"contrast": [1, 2]}, r"unknown keys \['contrast'\]; allowed"),
    ("strong", "augment: a mapping")])
def test_bad_augment_settings_are_refused_with_what_is_allowed(value, match):
    with pytest.raises(ValueError, match=match):
        AugmentSettings.from_value(value)
    with pytest.raises(ValueError, match=match):
        TrainConfig(env_id="homing_gym/LocalHoming-v0", augment=value)


def test_augment_needs_the_image_keys():
    class Plain(_Pictures):
        observation_space = gym.spaces.Dict({"extra": _Pictures.observation_space["extra"]})

    with pytest.raises(ValueError, match=r"image keys \['panorama', 'goal'\]"):
        AugmentedImages(DummyVecEnv([Plain]), AugmentSettings(), seed=0)


def test_the_training_envs_are_augmented_and_the_evaluation_envs_not():
    from homing_train.learning.train import make_vec

    config = TrainConfig(env_id="homing_gym/LocalHoming-v0", vec="dummy", augment={},
                         env_kwargs={"scene": "arena", "panorama_shape": [8, 32]})
    training, evaluation = make_vec(config, 1, 0), make_vec(config, 1, 0, augmented=False)
    try:
        assert isinstance(training.venv, AugmentedImages)
        assert not isinstance(evaluation.venv, AugmentedImages)
        ours, rendered = training.reset(), evaluation.reset()      # the same episode
        assert not np.array_equal(ours["goal"], rendered["goal"])
    finally:
        training.close()
        evaluation.close()
