"""Shiraishi & Sawasaki multi-resolution matching: correlation, triangulation, closed loop."""

import math

import numpy as np
import pytest

from homing_baselines.multires_matching import (find_template, front_view, locate_on_path,
                                         match_heading, predicted_directions, triangulate)
from homing_gym.teaching import clip_template


def _panorama(seed=0, shape=(16, 128)):
    rng = np.random.default_rng(seed)
    import cv2
    noise = rng.integers(0, 256, (shape[0], shape[1] // 2), dtype=np.uint8)
    return cv2.resize(noise, (shape[1], shape[0]), interpolation=cv2.INTER_LINEAR)


@pytest.mark.parametrize("offset", [0, 5, -17, 40, 64])
def test_correlation_recovers_a_heading_offset_within_one_column(offset):
    stored = _panorama()
    w = stored.shape[1]
    # the robot turned CCW by `offset` columns: its current panorama is the stored one
    # rolled so that what was at column w/2 - offset is now ahead
    current = np.roll(stored, offset, axis=1)
    deviation, score = match_heading(front_view(current, math.radians(60)), stored)
    assert score > 0.99
    column_error = math.remainder(deviation - 2 * math.pi * offset / w, 2 * math.pi) * w / (2 * math.pi)
    assert abs(column_error) <= 1.0


def test_locate_on_path_picks_the_matching_place():
    panos = [_panorama(s) for s in range(5)]
    k, deviation, score = locate_on_path(front_view(np.roll(panos[3], -7, axis=1),
                                                    math.radians(60)), panos)
    assert k == 3 and score > 0.99
    assert abs(deviation + 2 * math.pi * 7 / 128) < 2 * math.pi / 128


def test_triangulation_from_exact_directions_recovers_the_pose():
    points = np.array([[0.0, 2.0, 0.7], [3.0, 0.0, 0.65], [2.5, 4.0, 0.9], [-1.0, -1.5, 0.6]])
    true = np.array([0.6, 0.9, 0.4])
    for subset in (points[:2], points):
        bearings, elevations = predicted_directions(true, subset, 0.3)
        pose = triangulate(subset, bearings, elevations, 0.3, guess=(0.3, 1.3, 0.2))
        assert np.allclose(pose, true, atol=1e-6)
    with pytest.raises(ValueError, match="at least 2"):
        triangulate(points[:1], [0.1], [0.1], 0.3, (0, 0, 0))


def test_template_found_at_its_subpixel_position_only_inside_the_window():
    image = _panorama(1, (64, 512))
    template = clip_template(image, 200.3, 30.6, 17)
    match = find_template(image, template, 195.0, 33.0, (8, 5))
    assert match.score > 0.97
    assert abs(match.x - 200.3) < 0.25 and abs(match.y - 30.6) < 0.25
    assert find_template(image, template, 300.0, 33.0, (8, 5)).score < 0.7
    assert find_template(image, template, 200.0, 3.0, (8, 5)) is None


@pytest.mark.parametrize("goal, start", [("kitchen", (5.5, 4.55, 0.1)),
                                         ("bedroom", (5.6, 1.45, -0.15))])
def test_controller_stops_within_10_cm_of_a_work_location_from_1_m_away(make_env, controller_for,
                                                                        goal, start):
    from homing_train.harness.evaluate import run_episode

    env = make_env("homing_gym/WorkLocations-v0", goal_location=goal, max_episode_steps=200)
    controller = controller_for("multires", env)
    record = run_episode(env, controller, seed=0, start=start)
    assert record.terminated and record.success
    assert record.final_distance < 0.10
    assert record.collisions == 0


def test_controller_refuses_discrete_actions_and_bad_parameters():
    import homing_baselines
    from homing_baselines.motion import MotionSpec

    with pytest.raises(ValueError, match="continuous"):
        homing_baselines.make("multires").configure(MotionSpec(action_type="discrete"))
    with pytest.raises(ValueError, match="scales"):
        homing_baselines.make("multires", scales=(0.9, 1.1))
    with pytest.raises(ValueError, match="step_length"):
        homing_baselines.make("multires", step_length=0.0)
