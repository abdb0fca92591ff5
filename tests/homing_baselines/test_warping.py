"""Franz et al. 1998 warping: geometry, search on synthetic and rendered 1-D images."""

from __future__ import annotations

import math

import numpy as np
import pytest

from homing_baselines.warping import (WarpingConfig, WarpingController, warp_bearings, warp_search,
                               warping_homing)
from homing_gym.geometry import wrap_angle
from homing_gym.render.panorama import column_bearing


#: LocalHoming-v0 settings of the ``arena`` fixture (tests/homing_baselines/conftest.py).
ARENA = {"obs_keys": ("panorama", "goal")}


def test_warp_bearings_match_exact_geometry_on_the_landmark_circle():
    rng = np.random.default_rng(0)
    theta = rng.uniform(-np.pi, np.pi, 50)  # landmarks on the unit circle about home
    for alpha, rho, psi in ((0.3, 0.5, 0.0), (-2.0, 0.8, 1.2), (1.0, 0.0, -0.4)):
        pos = np.array([rho * math.cos(alpha), rho * math.sin(alpha)])
        seen = np.arctan2(np.sin(theta) - pos[1], np.cos(theta) - pos[0]) - psi
        np.testing.assert_allclose(wrap_angle(warp_bearings(seen, alpha, rho, psi) - theta),
                                   0, atol=1e-9)
    with pytest.raises(ValueError):
        warp_bearings(0.0, 0.0, 1.0)


def _image(theta_landmarks, width=256, sigma=0.08):
    phi = column_bearing(np.arange(width) + 0.5, width)
    d = wrap_angle(phi[:, None] - np.asarray(theta_landmarks)[None, :])
    return 1 - np.exp(-0.5 * (d / sigma) ** 2).max(1)


def test_search_recovers_a_synthetic_displacement():
    theta = np.radians([10, 70, 150, 200, 260, 320])
    alpha, rho, psi = 2.0, 0.3, 0.7
    pos = rho * np.array([math.cos(alpha), math.sin(alpha)])
    seen = np.arctan2(np.sin(theta) - pos[1], np.cos(theta) - pos[0]) - psi
    result = warp_search(_image(seen), _image(theta), WarpingConfig(smooth_deg=0))
    assert abs(wrap_angle(result.alpha - alpha)) < math.radians(6)
    assert abs(wrap_angle(result.psi - psi)) < math.radians(2)
    assert result.rho == pytest.approx(rho, abs=0.051)
    assert abs(wrap_angle(result.home_direction - (alpha + math.pi - psi))) < math.radians(6)
    with pytest.raises(ValueError):
        warp_search(np.zeros(10), np.zeros(12))


def test_rendered_rotation_is_found_without_displacement(panorama_at):
    home = (0.05, -0.1, 0.4)
    _, psi, result = warping_homing(panorama_at((0.05, -0.1, 1.3)), panorama_at(home))
    assert result.rho == 0.0
    assert abs(wrap_angle(psi - 0.9)) < math.radians(2)


def test_rendered_pairs_03m_apart_point_home(panorama_at):
    home = np.array([0.05, -0.1, 0.4])
    goal = panorama_at(home)
    errors = []
    for k in range(8):
        a = k * math.pi / 4
        pose = (home[0] + 0.3 * math.cos(a), home[1] + 0.3 * math.sin(a), 0.5 - 0.7 * k)
        direction, _, _ = warping_homing(panorama_at(pose), goal)
        truth = math.atan2(home[1] - pose[1], home[0] - pose[0]) - pose[2]
        errors.append(abs(math.degrees(wrap_angle(direction - truth))))
    assert max(errors) < 30, errors


def test_controller_reaches_home_from_05m(arena, free_start):
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy

    controller = WarpingController()
    prepare_policy(controller, arena)
    home = (0.05, -0.1, 0.4)
    for k in range(2):
        start = free_start(arena, home, 0.5, 1.0 + k * math.pi, 2.0 * k - 1)
        assert run_episode(arena, controller, 0, start=start, home=home).success, start


def test_controller_follows_a_new_goal_image(panorama_at):
    """On a route the goal image changes mid-episode: the controller must home on the new
    one (it stops where the new goal was taken), not on the first snapshot."""
    controller = WarpingController()
    controller.reset()
    here = panorama_at((0.05, -0.1, 0.4))
    first_goal = panorama_at((-0.5, 0.4, 0.4))
    assert controller.decide({"panorama": here, "goal": first_goal}) is not None
    assert controller.decide({"panorama": here, "goal": here.copy()}) is None


def test_bad_parameters_raise():
    with pytest.raises(ValueError):
        WarpingConfig(rho_values=(0.0, 1.0))
    with pytest.raises(ValueError):
        WarpingController(step_length=0)
