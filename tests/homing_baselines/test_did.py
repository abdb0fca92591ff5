"""Descent in image distance (Zeil, Hofmann & Chahl 2003): the IDF and the RIDF compass on
rendered panoramas, the three-point gradient, homing in the arena, bad parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from homing_baselines.did import (DIDController, grey_panorama, plane_gradient, rms_difference,
                                  rotational_idf, visual_compass)
from homing_gym.geometry import wrap_angle


#: LocalHoming-v0 settings of the ``arena`` fixture (tests/homing_baselines/conftest.py).
ARENA = {"obs_keys": ("panorama", "goal"), "start_distance": (0.3, 0.6)}


def test_ridf_of_a_rolled_image_is_zero_at_the_roll():
    image = np.random.default_rng(0).uniform(0, 1, (12, 64))
    ridf = rotational_idf(np.roll(image, 5, axis=1), image)
    assert int(np.argmin(ridf)) == 5 and ridf[5] == pytest.approx(0, abs=1e-9)
    assert rms_difference(image, image) == 0.0


def test_rendered_compass_and_idf_grow_with_distance(arena, panorama_at):
    """Pure rotations are found within 6 deg (one column of the reduced image); the
    rotation-invariant IDF grows with the distance from home (0 -> 0.05 -> 0.1 m) in
    every one of 6 directions (further out the arena's IDF is no longer monotonic in
    every direction: docs/did.md)."""
    home = (0.05, -0.1, 0.4)
    goal = grey_panorama(panorama_at(home), 2)
    for turn in (0.9, -2.0, 3.0):
        psi, d, _ = visual_compass(grey_panorama(panorama_at((0.05, -0.1, 0.4 + turn)), 2),
                                   goal)
        assert abs(math.degrees(wrap_angle(psi - turn))) < 6
    for k in range(6):
        a = k * math.pi / 3 + 0.3
        values = [visual_compass(grey_panorama(panorama_at((
            home[0] + r * math.cos(a), home[1] + r * math.sin(a), 1.1 * k)), 2), goal)[1]
            for r in (0.0, 0.05, 0.1)]
        assert values[0] < values[1] < values[2], (a, values)


def test_plane_gradient_is_exact_on_a_plane_and_refuses_collinear_points():
    points = np.array([[0.0, 0.0], [0.05, 0.0], [0.05, 0.05]])
    values = 0.3 + points @ np.array([2.0, -1.0])
    np.testing.assert_allclose(plane_gradient(points, values), [2.0, -1.0])
    assert plane_gradient(np.array([[0, 0], [1, 1], [2, 2.0]]), np.zeros(3)) is None


def test_descent_direction_from_rendered_probes_points_home(arena, panorama_at):
    """The descent direction from three rendered samples 0.05 m apart, 0.15 m from home,
    points home within 35 deg in at least 5 of 6 directions (the sixth straddles a ridge
    of the arena's IDF), median error below 20 deg."""
    home = (0.05, -0.1, 0.4)
    goal = grey_panorama(panorama_at(home), 2)
    errors = []
    for k in range(6):
        a = k * math.pi / 3 + 0.3
        base = np.array([home[0] + 0.15 * math.cos(a), home[1] + 0.15 * math.sin(a)])
        pts = np.array([base, base + [0.05, 0], base + [0.05, 0.05]])
        d = [visual_compass(grey_panorama(panorama_at((*p, 0.7 * k)), 2), goal)[1]
             for p in pts]
        g = plane_gradient(pts, np.array(d))
        descent = math.atan2(-g[1], -g[0])
        truth = math.atan2(home[1] - base[1], home[0] - base[0])
        errors.append(abs(math.degrees(wrap_angle(descent - truth))))
    assert sum(e < 35 for e in errors) >= 5 and np.median(errors) < 20, errors


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 8])
def test_controller_homes_from_known_starts(arena, seed):
    """Seeded LocalHoming-v0 episodes in the arena with starts 0.3-0.6 m from home (the
    IDF's catchment area in this small room is about 0.3 m, see docs/did.md): success
    under the env's stop rule."""
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy

    controller = DIDController()
    prepare_policy(controller, arena)
    assert run_episode(arena, controller, seed).success


@pytest.mark.parametrize("params,name", [
    ({"probe_length": 0}, "probe_length"), ({"step_length": -1}, "step_length"),
    ({"min_step": 0.5}, "min_step"), ({"descent_gain": 0}, "descent_gain"),
    ({"stop_ratio": 1.5}, "stop_ratio"), ({"levels": 6}, "levels"),
    ({"max_cycles": 0}, "max_cycles")])
def test_bad_parameters_name_the_parameter(params, name):
    with pytest.raises(ValueError, match=name):
        DIDController(**params)
