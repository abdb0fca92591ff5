"""Yu & Kim distance-estimation homing: Eq. 1, correspondence, localisation, controller."""

from __future__ import annotations

import math

import numpy as np
import pytest

from homing_baselines.distance import (DistanceConfig, DistanceController, LandmarkMap,
                                assignments, eq1_distance, landmark_distances, localize,
                                map_from_positions, resect_nest_map)
from homing_baselines.landmarks_red import Arc
from homing_gym.geometry import wrap_angle

LANDMARKS = np.array([(0.45, 0.35), (-0.35, 0.55), (-0.55, -0.25), (0.30, -0.50)])


def bearings_from(pose, points):
    return wrap_angle(np.arctan2(points[:, 1] - pose[1], points[:, 0] - pose[0]) - pose[2])


def ego_map(pose, points):
    """Exact egocentric map of ``points`` seen from world ``pose``."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    rel = (points - pose[:2]) @ np.array([[c, -s], [s, c]])
    return map_from_positions(rel)


@pytest.mark.parametrize("psi", [0.0, 0.4, -1.1])
def test_eq1_recovers_distances_from_exact_bearings(psi):
    rng = np.random.default_rng(1)
    for _ in range(50):
        c = np.array([*rng.uniform(-1, 1, 2), rng.uniform(-np.pi, np.pi)])
        d = rng.uniform(0.05, 0.4)
        heading = c[2] + psi  # turn by psi, then step d straight ahead
        t = np.array([c[0] + d * math.cos(heading), c[1] + d * math.sin(heading), heading])
        theta = bearings_from(c, LANDMARKS)
        delta = wrap_angle(bearings_from(t, LANDMARKS) - theta)
        keep = np.abs(np.sin(theta - psi)) > 0.05
        r = eq1_distance(theta[keep], delta[keep], d, psi)
        truth = np.hypot(*(LANDMARKS[keep] - t[:2]).T)
        np.testing.assert_allclose(r, truth, rtol=0, atol=1e-6)


def _arcs(bearings):
    return [Arc(float(b), 0.1, 0, 0) for b in np.sort(wrap_angle(np.asarray(bearings)))]


def test_degenerate_landmark_on_motion_axis_gets_no_distance():
    c = np.array([0.0, 0.0, 0.0])
    points = np.array([(1.0, 0.0), (0.0, 1.0), (-1.0, -0.001), (0.5, -0.8)])
    t = np.array([0.2, 0.0, 0.0])
    ego = landmark_distances(_arcs(bearings_from(c, points)), _arcs(bearings_from(t, points)),
                             0.2)
    truth = ego_map(t, points)
    axis = np.abs(np.sin(truth.bearings)) < math.sin(math.radians(10))
    assert axis.sum() == 2
    assert all(ego.status[i] == "on motion axis" for i in np.flatnonzero(axis))
    assert np.all(np.isnan(ego.distances[axis]))
    np.testing.assert_allclose(ego.distances[~axis], truth.distances[~axis], atol=1e-9)
    with pytest.raises(ValueError):
        landmark_distances([], [], step=0.0)


def test_cyclic_assignments_are_the_rotations():
    cyc = assignments(4, 4, "cyclic")
    assert len(cyc) == 4 and len(assignments(4, 4, "all")) == 24
    assert [(0, 1), (1, 2), (2, 3), (3, 0)] in cyc
    assert all(len(a) == 3 for a in assignments(3, 4, "cyclic"))


@pytest.mark.parametrize("mode", ["cyclic", "all"])
def test_correspondence_recovers_true_assignment_for_rotated_sets(mode):
    nest_pose = np.array([0.1, -0.05, 0.7])
    nest = ego_map(nest_pose, LANDMARKS)
    rng = np.random.default_rng(3)
    for _ in range(20):
        pose = np.array([*rng.uniform(-0.2, 0.2, 2), rng.uniform(-np.pi, np.pi)])
        ego = ego_map(pose, LANDMARKS)
        best, candidates = localize(ego, nest, mode)
        # the true correspondence: same world landmark in both sorted maps
        world_of_ego = np.argsort(np.argsort(bearings_from(pose, LANDMARKS)))
        world_of_nest = np.argsort(np.argsort(bearings_from(nest_pose, LANDMARKS)))
        truth = {(int(world_of_ego[k]), int(world_of_nest[k])) for k in range(4)}
        assert set(best.assignment) == truth
        assert best.spread < 1e-9
        assert len(candidates) == (4 if mode == "cyclic" else 24)
        rel = np.array([math.cos(nest_pose[2]), -math.sin(nest_pose[2])])
        dx, dy = pose[:2] - nest_pose[:2]
        expected = (rel[0] * dx - rel[1] * dy, rel[1] * dx + rel[0] * dy)
        assert best.x == pytest.approx(expected[0], abs=1e-9)
        assert best.y == pytest.approx(expected[1], abs=1e-9)
        assert wrap_angle(best.heading - (pose[2] - nest_pose[2])) == pytest.approx(0, abs=1e-9)


def test_all_assignments_recover_a_permuted_unordered_set():
    nest = ego_map(np.zeros(3), LANDMARKS)
    pose = np.array([0.15, 0.1, 2.0])
    exact = ego_map(pose, LANDMARKS)
    perm = np.array([2, 0, 3, 1])
    shuffled = LandmarkMap(exact.bearings[perm], exact.distances[perm], exact.widths[perm],
                           exact.status)
    best, _ = localize(shuffled, nest, "all")
    reference, _ = localize(exact, nest, "cyclic")
    assert set(best.assignment) == {(k, j) for k, (i, j) in
                                    zip(range(4), sorted(reference.assignment)) for k in
                                    [int(np.flatnonzero(perm == i)[0])]}
    assert best.home_direction == pytest.approx(reference.home_direction, abs=1e-9)


def test_wrong_map_does_not_converge():
    nest = ego_map(np.zeros(3), LANDMARKS)
    other = LANDMARKS + np.random.default_rng(0).normal(0, 0.2, LANDMARKS.shape)
    pose = np.array([0.1, 0.05, 1.0])
    assert localize(ego_map(pose, LANDMARKS), nest)[0].spread < 1e-9
    assert localize(ego_map(pose, other), nest)[0].spread > 0.05


@pytest.mark.parametrize("mode,pose", [("cyclic", (0.1, -0.2, 2.5)), ("all", (0.6, -0.7, 2.5))])
def test_resection_rebuilds_the_nest_map(mode, pose):
    nest_pose = np.array([-0.2, 0.1, -0.4])
    ego = ego_map(np.array(pose), LANDMARKS)
    nest_bearings = np.sort(bearings_from(nest_pose, LANDMARKS))
    nest, rms = resect_nest_map(ego, nest_bearings, mode)
    truth = ego_map(nest_pose, LANDMARKS)
    assert rms < 1e-3
    np.testing.assert_allclose(nest.distances, truth.distances, atol=2e-3)


def test_arrangement_order_changes_outside_the_landmark_hull():
    """The limit of §II-B's cyclic matching: seen from outside the landmarks' convex
    hull the arrangement order can differ from the nest's, and no cyclic shift fits."""
    nest_pose = np.array([-0.2, 0.1, -0.4])
    nest = ego_map(nest_pose, LANDMARKS)
    outside = ego_map(np.array([0.6, -0.7, 2.5]), LANDMARKS)
    assert localize(outside, nest, "cyclic")[0].spread > 0.05
    assert localize(outside, nest, "all")[0].spread < 1e-9


def test_bad_parameters_raise():
    with pytest.raises(ValueError):
        DistanceConfig(assignments="some")
    with pytest.raises(ValueError):
        DistanceController(step_length=-0.1)
    with pytest.raises(ValueError):
        DistanceController(nest="elsewhere")


@pytest.mark.slow
def test_controller_reaches_home_from_1m_in_arena(free_start):
    """Four starts 1 m from a home near the arena centre, evenly spaced around it, with
    the paper's two-snapshot nest map (``goal_step``). Three of four must succeed: from
    the start towards the wall, only two landmarks get distances in both maps for
    several steps, and with two landmarks a wrong cyclic shift fits as well as the right
    one (docs/yu_kim.md), so that episode fails (a limit of the method, not hidden).
    Reaching is the claim here (``success_on="reach"``); under the stop rule the
    ``yukim`` protocol scores it."""
    gym = pytest.importorskip("gymnasium")
    import homing_gym  # noqa: F401
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy

    env = gym.make("homing_gym/LocalHoming-v0", obs_keys=("panorama", "goal", "goal_step"),
                   max_episode_steps=300, success_on="reach")
    controller = DistanceController()
    prepare_policy(controller, env)
    home = (0.05, -0.1, 0.4)
    try:
        records = [run_episode(env, controller, 0,
                               start=free_start(env, home, 1.0, 0.3 + k * math.pi / 2, 1.0 - k),
                               home=home) for k in range(4)]
    finally:
        env.close()
    successes = [r.success for r in records]
    collisions = [r.collisions for r in records]
    assert sum(successes) >= 3, (successes, collisions)


def _pose(x, y, heading=0.0):
    from homing_baselines.distance import PoseEstimate
    return PoseEstimate(x, y, heading, 0.02, ((0, 0), (1, 1), (2, 2), (3, 3)), 4)


def test_arrival_needs_two_agreeing_estimates_with_the_nest_in_reach():
    """The stop decision from hand-made estimates (arrival rule, docs/yu_kim.md): the nest
    within one move of the current estimate, and the previous estimate carried forward
    by the commanded motion agreeing with it within the tolerance."""
    from homing_baselines.distance import arrival_confirmed, carry_forward

    # previous estimate 0.5 m east of the nest facing west; it moved 0.3 m home, then
    # probed 0.16 m on: now 0.04 m west of the nest
    prev = _pose(0.5, 0.0, math.pi)
    motion = (0.46, 0.0, 0.0)
    assert carry_forward(prev, motion)[:2] == pytest.approx([0.04, 0.0], abs=1e-12)
    # a turn of 90 degrees to the left, then 0.2 m: the heading turns the displacement
    turned = carry_forward(_pose(0.0, 0.0, math.pi / 2), (0.0, 0.2, math.pi / 2))
    assert turned == pytest.approx([-0.2, 0.0, math.pi], abs=1e-12)
    reach, tol = 0.3, 0.15
    # no previous estimate: never (a single localisation may be a wrong arrangement)
    assert not arrival_confirmed(None, None, _pose(0.05, 0.0), reach, tol)
    # agreeing within 0.15 m and the nest in reach: arrive
    assert arrival_confirmed(prev, motion, _pose(-0.02, 0.05), reach, tol)
    # a jump: the current estimate puts the robot 0.1 m from the nest, but 0.3 m from
    # where the previous one and the motion put it -> no stop
    assert not arrival_confirmed(prev, motion, _pose(0.0, 0.1 + 0.2), reach, tol)
    assert not arrival_confirmed(prev, motion, _pose(-0.05, -0.25), reach, tol)
    # agreeing, but the nest beyond one move: go on
    far = _pose(0.9, 0.0, math.pi)
    assert not arrival_confirmed(far, (0.46, 0.0, 0.0), _pose(0.44, 0.0), reach, tol)
    # a sequence of estimates as the controller sees them: stop at the first pair
    # that agrees with the nest in reach
    seq = [(_pose(1.0, 0.0, math.pi), (0.46, 0.0, 0.0)),
           (_pose(0.52, 0.01, math.pi), (0.46, 0.0, 0.0)),  # agrees, nest 0.52 m: go on
           (_pose(0.2, -0.2, math.pi), (0.2, 0.0, 0.0)),    # 0.28 m, 0.25 m off: a jump
           (_pose(0.02, -0.19, math.pi), None)]             # agrees, 0.19 m: arrive
    decisions = [arrival_confirmed(a[0], a[1], b[0], reach, tol)
                 for a, b in zip(seq, seq[1:])]
    assert decisions == [False, False, True]
    with pytest.raises(ValueError):
        DistanceController(confirm_tolerance=0.0)


@pytest.mark.slow
def test_controller_stops_within_the_radius_of_the_nest(free_start):
    """Under the stop rule (``success_on="stop"``, the ``yukim`` protocol's): from three
    starts 0.5-1.0 m from the arena's nest, the controller issues stop within 0.15 m.
    Starts chosen by hand, none of the protocol's draws."""
    gym = pytest.importorskip("gymnasium")
    import homing_gym  # noqa: F401
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy

    env = gym.make("homing_gym/LocalHoming-v0", obs_keys=("panorama", "goal", "goal_step"),
                   scene="arena", max_episode_steps=300, success_on="stop",
                   renderer="tiny", physics_substeps=24)
    controller = DistanceController()
    prepare_policy(controller, env)
    home = (0.0, 0.0, 0.0)
    try:
        records = [run_episode(env, controller, 11 + k,
                               start=free_start(env, home, dist, bearing, heading),
                               home=home)
                   for k, (dist, bearing, heading) in enumerate(
                       ((0.5, 0.2, 2.0), (0.8, 2.4, -1.0), (1.0, -1.9, 0.5)))]
    finally:
        env.close()
    outcome = [(r.terminated, round(r.final_distance, 3)) for r in records]
    assert all(r.terminated and r.success for r in records), outcome


def test_free_direction_steers_around_a_landmark_ahead():
    from homing_baselines.distance import free_direction, view_obstacles

    ahead = [(0.5, 0.0, 0.1)]  # a cylinder 0.5 m straight ahead
    d = free_direction(0.0, 0.8, ahead, 0.22)
    assert d is not None and abs(d) >= math.asin(0.32 / 0.5) - 1e-9
    assert free_direction(math.pi / 2, 0.8, ahead, 0.22) == pytest.approx(math.pi / 2)
    # inside the margin only directions leading away are free
    close = [(0.3, 0.0, 0.1)]
    assert abs(free_direction(0.0, 0.3, close, 0.22)) >= math.pi / 2
    # width-based distance: an arc 2 asin(0.1 / 0.5) wide is 0.5 m away
    arc = Arc(0.0, 2 * math.asin(0.1 / 0.5), 0, 0)
    (x, y, r), = view_obstacles([arc], None, 0.1)
    assert (x, y, r) == pytest.approx((0.5, 0.0, 0.1))


def test_run_episodes_takes_a_home_pose_per_task():
    pytest.importorskip("gymnasium")
    from homing_train.harness.evaluate import run_episodes
    from homing_train.harness.policies import policy_spec

    home, start = (0.3, -0.2, 1.0), (-0.7, 0.3, 0.0)     # start clear of the cylinders
    recs = run_episodes(policy_spec("oracle"), "homing_gym/LocalHoming-v0",
                        {"max_episode_steps": 3}, [(5, start, home), (6, None, home), (7,)],
                        workers=1, progress=False)
    assert recs[0].home_pose == pytest.approx(list(home), abs=1e-4)
    assert recs[0].start_pose[:2] == pytest.approx(list(start[:2]), abs=1e-3)
    assert recs[1].home_pose == pytest.approx(list(home), abs=1e-4)
    assert recs[2].home_pose != pytest.approx(list(home), abs=1e-4)
    with pytest.raises(ValueError):
        run_episodes(policy_spec("oracle"), "homing_gym/LocalHoming-v0", {}, [(1, None, None, 0)])


def test_a_ring_red_all_round_has_no_landmarks_and_the_controller_acts():
    """A world red all round (red brick streets) separates no landmark: no arcs, and the
    controller still answers (it crashed the unseen-families suite before)."""
    from homing_baselines.landmarks_red import detect_landmarks, ring_arcs
    assert ring_arcs(np.ones(360)) == [] and ring_arcs(np.zeros(360)) == []
    red = np.zeros((48, 256, 3), np.uint8)
    red[..., 0] = 200
    assert detect_landmarks(red) == []
    controller = DistanceController()
    controller.reset()
    for _ in range(3):       # no landmark: no estimate; it moves on or stops, no error
        controller.decide({"panorama": red, "goal": red, "odometry": np.zeros(3, np.float32)})
