"""Shared image primitives (homing_gym.vision) and the discrete action table."""

import gymnasium as gym
import numpy as np
import pytest

from homing_gym import DiscreteAction
from homing_gym.render.panorama import signature_weights
from homing_gym.vision import grey, horizon_line, low_resolution, low_resolution_shape, luminance

PURE = {"red": ((255, 0, 0), 0.299), "green": ((0, 255, 0), 0.587),
        "blue": ((0, 0, 255), 0.114), "white": ((255, 255, 255), 1.0), "black": ((0, 0, 0), 0.0)}


@pytest.mark.parametrize("name", sorted(PURE))
def test_luminance_of_pure_colours_is_bt601(name):
    rgb, expected = PURE[name]
    image = np.full((2, 3, 3), rgb, np.uint8)
    assert luminance(image) == pytest.approx(np.full((2, 3), expected), abs=1e-6)
    assert luminance(image, 255.0) == pytest.approx(np.full((2, 3), 255 * expected), abs=1e-4)
    assert grey(image).dtype == np.uint8
    assert np.all(grey(image) == int(255 * expected + 0.5))


def test_luminance_refuses_a_non_rgb_image():
    with pytest.raises(ValueError, match="RGB"):
        luminance(np.zeros((4, 4, 2), np.uint8))


def test_horizon_line_mixes_rows_with_the_weights():
    H, W = 48, 16
    rows = np.linspace(0, 255, H).astype(np.uint8)
    pano = np.repeat(np.repeat(rows[:, None, None], W, 1), 3, 2)
    weights = signature_weights(H, 5)
    expected = float(weights @ rows.astype(np.float64)) / 255
    line = horizon_line(pano, weights)
    assert line.shape == (W,) and np.allclose(line, expected, atol=1e-5)


def test_pyramid_levels_halve_the_size_and_stay_seamless():
    image = np.random.default_rng(0).integers(0, 255, (48, 256, 3), np.uint8)
    for levels in range(4):
        assert low_resolution(image, levels).shape == low_resolution_shape((48, 256), levels)
    # a panorama rolled by whole pyramid blocks gives the rolled reduction
    a = low_resolution(image, 2)
    b = low_resolution(np.roll(image, 8, axis=1), 2)
    assert np.array_equal(np.roll(a, 2, axis=1), b)


def test_discrete_actions():
    assert DiscreteAction.STOP == 3 and len(DiscreteAction) == 4
    assert DiscreteAction.FORWARD.command == (1.0, 0.0)
    assert DiscreteAction.TURN_LEFT.command == (0.0, 1.0)
    assert DiscreteAction.TURN_RIGHT.command == (0.0, -1.0)
    assert DiscreteAction.STOP.command == (0.0, 0.0)


def test_turn_left_turns_counter_clockwise():
    env = gym.make("homing_gym/LocalHoming-v0", action_type="discrete", panorama_shape=(16, 64),
                   success_on="reach")
    _, info = env.reset(seed=0, options={"start": [0.0, 0.0, 0.0]})
    for _ in range(5):
        _, _, _, _, info = env.step(DiscreteAction.TURN_LEFT)
    assert 0.3 < info["pose"][2] < 1.0          # about 0.5 s at up to 1.5 rad/s
    turned = info["pose"].copy()
    _, _, terminated, _, info = env.step(DiscreteAction.STOP)
    env.close()
    # a stop ends the turn where it is (the wheels ramp down within the step) and, under
    # success_on="reach" away from home, does not end the episode
    assert abs(info["pose"][2] - turned[2]) < 0.12 and not terminated   # 0.09; turning on: 0.15
