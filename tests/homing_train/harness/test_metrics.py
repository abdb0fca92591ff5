"""Metrics against hand-computed values on hand-made trajectories."""

import math

import numpy as np
import pytest

from homing_gym.paths import segment_free, shortest_path
from homing_gym.scenes.arena import arena_scene
from homing_train.harness.evaluate import EpisodeRecord, summarize
from homing_train.harness.metrics import (bootstrap_ci, distance_bins, failure_kind, path_length,
                                          soft_spl, spl, wilson_interval)

# a 3-4-5 detour: straight-line distance 5, travelled 7
TRAJECTORY = [(0.0, 0.0), (3.0, 0.0), (3.0, 4.0)]


def test_path_length_of_hand_made_trajectory():
    assert path_length(TRAJECTORY) == pytest.approx(7.0)
    assert path_length([(1.0, 1.0)]) == 0.0
    assert path_length([(0, 0, 0.3), (0, 2, 1.0)]) == pytest.approx(2.0)  # yaw ignored


def test_spl_hand_computed():
    assert spl(True, 5.0, path_length(TRAJECTORY)) == pytest.approx(5 / 7)
    assert spl(False, 5.0, 7.0) == 0.0
    assert spl(True, 5.0, 4.0) == 1.0  # stopped short inside the success radius
    with pytest.raises(ValueError):
        spl(True, -1.0, 2.0)


def test_soft_spl_hand_computed():
    # ends 1 m from home after 7 m for a 5 m shortest path: (1 - 1/5) * 5/7
    assert soft_spl(1.0, 5.0, 7.0) == pytest.approx(0.8 * 5 / 7)
    assert soft_spl(0.0, 5.0, 5.0) == pytest.approx(1.0)
    assert soft_spl(6.0, 5.0, 9.0) == 0.0  # further than at the start: clipped at 0


def test_distance_bins_hand_computed():
    bins = distance_bins([0.1, 0.35, 0.59, 0.61, 1.2], [1, 0, 1, 1, 0], width=0.3)
    assert [(b.lo, b.hi, b.n, b.success_rate) for b in bins] == [
        (0.0, 0.3, 1, 1.0), (0.3, 0.6, 2, 0.5), (0.6, 0.9, 1, 1.0), (1.2, 1.5, 1, 0.0)]
    with pytest.raises(ValueError):
        distance_bins([0.1], [1], width=0)


def test_bootstrap_ci_hand_computed_cases():
    assert bootstrap_ci([0.7] * 10) == (0.7, 0.7)
    # two values 0 and 1: resampled means are 0, 0.5, 1 with probabilities 1/4, 1/2, 1/4,
    # so the 2.5th and 97.5th percentiles are 0 and 1
    assert bootstrap_ci([0.0, 1.0]) == (0.0, 1.0)
    assert all(math.isnan(v) for v in bootstrap_ci([]))


def test_bootstrap_ci_matches_normal_approximation_and_is_seeded():
    x = np.array([0, 1] * 500, dtype=float)  # p = 0.5, n = 1000
    lo, hi = bootstrap_ci(x, seed=3)
    half = 1.96 * math.sqrt(0.25 / 1000)
    assert lo == pytest.approx(0.5 - half, abs=0.006)
    assert hi == pytest.approx(0.5 + half, abs=0.006)
    assert bootstrap_ci(x, seed=3) == (lo, hi)


def test_wilson_interval_against_hand_computed_values():
    # k = 5 of n = 10: centre 0.5, half-width z sqrt(p(1-p)/n + z^2/4n^2) / (1 + z^2/n)
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-3)
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-3)
    assert wilson_interval(10, 10) == pytest.approx((0.7225, 1.0), abs=1e-3)
    assert all(math.isnan(v) for v in wilson_interval(0, 0))
    with pytest.raises(ValueError, match="successes"):
        wilson_interval(11, 10)


def _record(seed, success, start_distance, spl_value, final_distance=0.1):
    return EpisodeRecord(seed=seed, start_pose=[0, 0, 0], home_pose=[1, 0, 0],
                         start_distance=start_distance, shortest_path=start_distance,
                         success=success, terminated=success, truncated=not success, steps=10,
                         path_length=1.0, final_distance=final_distance, min_distance=0.1,
                         collisions=0, spl=spl_value, soft_spl=0.5,
                         final_heading_error_deg=10.0, wall_time=0.1)


def test_summary_means_and_bins():
    records = [_record(0, True, 0.4, 0.8), _record(1, False, 0.5, 0.0),
               _record(2, True, 1.0, 0.6, final_distance=0.3)]
    s = summarize(records, bin_width=0.3)
    assert s["episodes"] == 3
    assert s["success_rate"] == pytest.approx(2 / 3)
    assert s["spl"] == pytest.approx(1.4 / 3)
    assert s["final_distance_mean"] == pytest.approx(0.5 / 3)
    assert s["final_distance_cm_median"] == pytest.approx(10.0)
    assert s["success_ci"] == list(wilson_interval(2, 3))
    assert [(b["lo"], b["n"], b["success_rate"]) for b in s["success_by_distance"]] == [
        (0.3, 2, 0.5), (0.9, 1, 1.0)]


def test_shortest_path_is_straight_when_free_and_bends_around_a_cylinder():
    scene = arena_scene()
    assert path_length(shortest_path(scene, (-0.9, -0.9), (-0.9, 0.2))) == pytest.approx(1.1)
    # cylinder at (0.45, 0.35), radius 0.1075, inflated by the 0.16 m body radius; start and
    # goal 0.45 m either side of its centre: two tangents and an arc
    r, d = 0.1075 + 0.16, 0.45
    tangent = math.sqrt(d * d - r * r)
    arc = r * (math.pi - 2 * math.acos(r / d))
    path = shortest_path(scene, (0.9, 0.35), (0.0, 0.35), radius=0.16)
    assert path_length(path) == pytest.approx(2 * tangent + arc, rel=0.01)
    assert all(segment_free(scene, a, b, 0.16 - 1e-6) for a, b in zip(path[:-1], path[1:]))


def test_clearances_hand_computed_for_a_wall_a_box_and_a_cylinder():
    from homing_gym.scenes.base import Landmark, Scene, Wall, clearance, clearances

    scene = Scene("probe", ((-5, -5), (5, 5)), walls=(Wall((0, -1), (0, 1), thickness=0.1),),
                  landmarks=(Landmark((3, 0), shape="box", extent=(1.0, 0.4), yaw=math.pi / 2),
                             Landmark((-3, 3), radius=0.5)))
    points = [(0.55, 0), (0, 1.3), (3.0, -1.0), (3.3, 0), (-3, 4), (4.9, 4.9), (3, 0.2)]
    # the wall's face 0.5 / 0.3 past its end less half its thickness; the box (0.4 x 1.0
    # once turned) 0.5 below / 0.1 beside; the cylinder 0.5; the bounds 0.1; inside 0
    expected = [0.5, 0.25, 0.5, 0.1, 0.5, 0.1, 0.0]
    assert np.allclose(clearances(scene, points), expected)
    assert [clearance(scene, p) for p in points] == pytest.approx(expected)


def test_aggregate_success_hand_computed_point_estimates():
    from homing_train.harness.metrics import aggregate_success

    # rates 0.2, 0.4, 0.6, 1.0: mean 0.55; the IQM trims one stratum at each end
    a = aggregate_success([(1, 5), (2, 5), (3, 5), (5, 5)])
    assert (a.strata, a.episodes) == (4, 20)
    assert a.mean == pytest.approx(0.55) and a.iqm == pytest.approx(0.5)
    assert a.mean_ci[0] < a.mean < a.mean_ci[1] and a.iqm_ci[0] < a.iqm < a.iqm_ci[1]
    # strata weigh alike whatever their episodes: (1/2 + 1/10) / 2, not 2/12
    assert aggregate_success([(1, 2), (1, 10)]).mean == pytest.approx(0.3)
    assert aggregate_success([(1, 5), (2, 5)], seed=4) == aggregate_success([(1, 5), (2, 5)],
                                                                            seed=4)


def test_aggregate_interval_is_the_stratified_one_and_shrinks_with_episodes():
    from homing_train.harness.metrics import aggregate_success

    small = aggregate_success([(2, 10), (8, 10)])
    big = aggregate_success([(200, 1000), (800, 1000)])
    assert small.mean == big.mean == pytest.approx(0.5)
    assert small.mean_ci[0] < big.mean_ci[0] < 0.5 < big.mean_ci[1] < small.mean_ci[1]
    # resampling within each stratum: var = (0.16/1000 + 0.16/1000) / 4; pooling the 2000
    # episodes (0.25/2000) would give a half-width of 0.0219 instead of 0.0175
    half = 1.96 * math.sqrt((0.16 / 1000 + 0.16 / 1000) / 4)
    assert big.mean_ci[0] == pytest.approx(0.5 - half, abs=0.002)
    assert big.mean_ci[1] == pytest.approx(0.5 + half, abs=0.002)


def test_aggregate_of_strata_that_cannot_vary_and_bad_input():
    from homing_train.harness.metrics import aggregate_success

    a = aggregate_success([(0, 5), (5, 5), (1, 1)])
    assert a.mean == pytest.approx(2 / 3) and a.mean_ci == (a.mean, a.mean)
    # one varying stratum among constant ones: only it moves the mean, by 1/3 of its own
    b = aggregate_success([(0, 5), (5, 5), (1, 2)])
    assert b.mean_ci == pytest.approx((1 / 3, 2 / 3))
    for bad in ([], [(3, 2)], [(0, 0)], [(-1, 4)]):
        with pytest.raises(ValueError):
            aggregate_success(bad)


def test_every_summary_field_against_hand_computed_values():
    from dataclasses import replace
    base = _record(0, True, 0.4, 0.8)
    records = [replace(base, seed=0, path_length=1.0, steps=10, collisions=0, soft_spl=0.2,
                       min_distance=0.05, final_heading_error_deg=10.0),
               replace(base, seed=1, success=False, path_length=2.0, steps=30, collisions=4,
                       soft_spl=0.5, min_distance=0.40, final_heading_error_deg=50.0),
               replace(base, seed=2, path_length=4.5, steps=50, collisions=2, soft_spl=0.8,
                       min_distance=0.12, final_heading_error_deg=30.0)]
    s = summarize(records, bin_width=0.3)
    assert s["path_length_mean"] == pytest.approx(7.5 / 3)
    assert s["steps_mean"] == pytest.approx(30.0)
    assert s["collisions_mean"] == pytest.approx(2.0)
    assert s["collision_free_rate"] == pytest.approx(1 / 3)
    assert s["soft_spl"] == pytest.approx(0.5)
    assert s["min_distance_mean"] == pytest.approx(0.19)
    assert s["heading_error_deg_mean"] == pytest.approx(30.0)
    assert s["heading_error_deg_median"] == pytest.approx(30.0)
    assert s["reached_rate"] == pytest.approx(2 / 3)          # 0.05 and 0.12 <= 0.15 m
    assert s["reached_ci"] == list(wilson_interval(2, 3))


@pytest.mark.parametrize("truncated, steps, collisions, final, kind", [
    (True, 250, 75, 1.0, "stuck"),            # 30 % of its steps in contact
    (True, 250, 74, 1.0, "out of time"),
    (True, 250, 0, 0.16, "out of time"),      # near home, but it never stopped
    (False, 40, 0, 0.25, "stopped near"),     # the 0.15 m radius + 0.1 m
    (False, 40, 0, 0.2501, "stopped away"),
    (False, 40, 200, 1.0, "stopped away")])   # contact does not matter for a stop
def test_failure_kinds_follow_the_definitions(truncated, steps, collisions, final, kind):
    assert failure_kind(truncated, steps, collisions, final, radius=0.15) == kind
