"""Average landmark vector (Lambrinos et al. 2000): the home vector on synthetic bearings,
landmark segmentation and direction on rendered panoramas, homing in the arena, bad
parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from homing_baselines.alv import (ALVConfig, ALVController, average_landmark_vector,
                                  circular_runs, segment_landmarks)
from homing_gym.geometry import wrap_angle

#: LocalHoming-v0 settings of the ``arena`` fixture (tests/homing_baselines/conftest.py).
ARENA = {"obs_keys": ("panorama", "goal", "odometry"), "start_distance": (0.3, 0.6)}


LANDMARKS = np.array([[1.0, 0.4], [-0.6, 1.1], [-0.9, -0.7], [0.5, -1.2], [1.4, -0.3]])


def _bearings(position):
    d = LANDMARKS - position
    return np.arctan2(d[:, 1], d[:, 0])


@pytest.mark.parametrize("angle", np.linspace(0, 2 * np.pi, 8, endpoint=False))
def test_alv_difference_points_home_on_synthetic_bearings(angle):
    """Compass-aligned unit vectors to five landmarks: ALV(x) - ALV(home) points home
    within 30 deg from 0.3 m in 8 directions."""
    here = 0.3 * np.array([math.cos(angle), math.sin(angle)])
    h = average_landmark_vector(_bearings(here)) - average_landmark_vector(_bearings(np.zeros(2)))
    truth = math.atan2(-here[1], -here[0])
    assert abs(math.degrees(wrap_angle(math.atan2(h[1], h[0]) - truth))) < 30


def test_circular_runs_join_across_the_seam():
    runs = circular_runs(np.array([1, 1, 0, 0, 1, 0, 1, 1], bool))
    assert sorted(sorted(r.tolist()) for r in runs) == [[0, 1, 6, 7], [4]]
    assert circular_runs(np.zeros(5, bool)) == []


def test_rendered_cylinders_are_the_dark_landmarks(arena, panorama_at):
    """From the arena's centre the four red cylinders are four dark segments at their
    bearings (within 5 deg)."""
    pose = (0.0, 0.0, 0.3)
    marks = segment_landmarks(panorama_at(pose))
    truth = [math.atan2(y, x) - pose[2] for x, y in ((0.45, 0.35), (-0.35, 0.55),
                                                     (-0.55, -0.25), (0.3, -0.5))]
    assert marks.bearings.size == 4
    for t in truth:
        assert min(abs(math.degrees(wrap_angle(b - t))) for b in marks.bearings) < 5


def test_rendered_home_vector_with_the_true_rotation_points_home(panorama_at):
    """Given the true rotation, ALV homing from rendered views 0.7 m from home points
    home within 30 deg (median over 6 directions; each within 60 deg)."""
    home = np.array([0.05, -0.1, 0.4])
    h0 = average_landmark_vector(segment_landmarks(panorama_at(home)).bearings)
    errors = []
    for k in range(6):
        a = k * math.pi / 3 + 0.3
        pose = (home[0] + 0.7 * math.cos(a), home[1] + 0.7 * math.sin(a), 1.1 * k)
        if max(abs(pose[0]), abs(pose[1])) > 1.0:
            continue
        psi = pose[2] - home[2]
        v = average_landmark_vector(segment_landmarks(panorama_at(pose)).bearings + psi) - h0
        truth = math.atan2(home[1] - pose[1], home[0] - pose[0]) - home[2]
        errors.append(abs(math.degrees(wrap_angle(math.atan2(v[1], v[0]) - truth))))
    assert len(errors) >= 3 and np.median(errors) < 30 and max(errors) < 60, errors


@pytest.mark.parametrize("seed", [5, 7, 8])
def test_controller_homes_from_known_starts(arena, seed):
    """Seeded LocalHoming-v0 episodes in the arena, starts 0.3-0.6 m from home: success
    under the env's stop rule."""
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy

    controller = ALVController()
    prepare_policy(controller, arena)
    assert run_episode(arena, controller, seed).success


@pytest.mark.parametrize("params,name", [
    ({"step_length": 0}, "step_length"), ({"stop_length": -0.1}, "stop_length"),
    ({"max_steps": 0}, "max_steps"), ({"compass_levels": 9}, "compass_levels"),
    ({"n_samples": 4}, "n_samples"), ({"polarity": "grey"}, "polarity"),
    ({"min_width": 200.0}, "min_width"), ({"min_contrast": 2.0}, "min_contrast")])
def test_bad_parameters_name_the_parameter(params, name):
    with pytest.raises(ValueError, match=name):
        ALVController(**params)


def test_config_rejects_zero_rows():
    with pytest.raises(ValueError, match="rows"):
        ALVConfig(rows=0)
