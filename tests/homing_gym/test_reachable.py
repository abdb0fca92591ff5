"""Only reachable episodes: tasks draw start and goals joined by a path for a disc of their
``path_radius`` (homing_gym.paths.connected), refuse worlds without such a pair quickly,
and check given routes against the robot's body."""

import math
import time

import numpy as np
import pytest

from homing_gym.paths import BODY_RADIUS, NoPathError, connected, regions, shortest_path
from homing_gym.scenes.base import Landmark, Scene, Wall, clearance
from homing_gym.tasks import LocalHomingTask, RouteFollowingTask
from homing_gym.tasks.base import sample_free_pose


def two_rooms() -> Scene:
    """6 x 2 m, split at x = 0 by a wall from bound to bound: two rooms, no door."""
    return Scene("two_rooms", ((-3.0, -1.0), (3.0, 1.0)),
                 walls=(Wall((0.0, -1.0), (0.0, 1.0), thickness=0.1),))


def doorway(gap: float) -> Scene:
    """Two 2 x 2 m rooms joined by a door in the wall at x = 0, ``gap`` metres between the
    wall's centre line ends (0.1 m less between its faces)."""
    half = gap / 2
    return Scene("doorway", ((-2.0, -1.0), (2.0, 1.0)),
                 walls=(Wall((0.0, -1.0), (0.0, -half), thickness=0.1),
                        Wall((0.0, half), (0.0, 1.0), thickness=0.1)))


def test_the_two_rooms_are_two_regions():
    labels = regions(two_rooms(), 0.22, 0.05)
    assert labels.max() == 2
    # a pair across the wall the old sampler could draw: both clear, 0.6 m apart
    assert min(clearance(two_rooms(), p) for p in ((-0.3, 0.0), (0.3, 0.0))) >= 0.22
    assert not connected(two_rooms(), (-0.3, 0.0), (0.3, 0.0), 0.22)


def test_home_and_start_are_never_drawn_in_different_rooms():
    scene, task = two_rooms(), LocalHomingTask(start_distance=(0.3, 1.5))
    for seed in range(300):
        episode = task.sample_episode(scene, np.random.default_rng(seed))
        assert np.sign(episode.home[0]) == np.sign(episode.start[0]), seed
        assert 0.3 <= math.dist(episode.home[:2], episode.start[:2]) <= 1.5
        assert min(clearance(scene, episode.home[:2]),
                   clearance(scene, episode.start[:2])) >= task.clearance_margin
        path = shortest_path(scene, episode.start, episode.home, task.path_radius)
        assert path[0] == tuple(episode.start[:2]) and path[-1] == tuple(episode.home[:2])


def test_connected_says_exactly_when_shortest_path_finds_a_path():
    rng = np.random.default_rng(0)
    for scene in (two_rooms(), doorway(0.6)):
        (x0, y0), (x1, y1) = scene.bounds
        answers = set()
        for _ in range(60):
            a, b = rng.uniform((x0, y0), (x1, y1)), rng.uniform((x0, y0), (x1, y1))
            try:
                shortest_path(scene, a, b, 0.22)
                found = True
            except NoPathError:
                found = False
            assert connected(scene, a, b, 0.22) == found
            answers.add(found)
        assert answers == {True, False}


def test_a_world_without_a_pair_at_the_distances_is_refused_quickly():
    # five 0.8 m cells in a row: no two points of one cell are 1 m apart
    walls = tuple(Wall((x, -0.4), (x, 0.4), thickness=0.1) for x in (-1.2, -0.4, 0.4, 1.2))
    scene = Scene("cells", ((-2.0, -0.4), (2.0, 0.4)), walls=walls)
    task = LocalHomingTask(start_distance=(1.0, 1.5))
    task.check_scene(scene)                   # the bounds' diagonal would hold 1.5 m
    t = time.perf_counter()
    with pytest.raises(ValueError, match=r"scene 'cells' .* no home and start 1.0-1.5 m apart"):
        task.sample_episode(scene, np.random.default_rng(0))
    assert time.perf_counter() - t < 5.0


def test_a_mostly_blocked_world_draws_from_its_free_cells():
    # a box covers all but a 0.6 m wide L along two sides of a 10 m square
    box = Landmark((0.3, 0.3), shape="box", extent=(9.4, 9.4), height=0.5)
    scene = Scene("blocked", ((-5.0, -5.0), (5.0, 5.0)), landmarks=(box,))
    rng = np.random.default_rng(1)
    t = time.perf_counter()
    poses = [sample_free_pose(scene, rng, 0.22) for _ in range(100)]
    assert time.perf_counter() - t < 5.0
    assert all(clearance(scene, p[:2]) >= 0.22 for p in poses)
    assert {p[0] < -4.4 for p in poses} == {True, False}          # both arms of the L
    with pytest.raises(ValueError, match=r"scene 'blocked' has no floor point with 0.4 m"):
        sample_free_pose(scene, rng, 0.4)


def test_a_given_route_point_too_close_says_by_how_much():
    scene = Scene("probe", ((0.0, -1.0), (4.0, 1.0)),
                  walls=(Wall((0.0, 0.5), (4.0, 0.5), thickness=0.1),))
    task = RouteFollowingTask(route=[(1.0, 0.4), (2.0, 0.0)])
    with pytest.raises(ValueError) as err:
        task.check_scene(scene)
    assert str(err.value) == ("route point 0 (1.000, 0.400) is 0.050 m from the nearest wall "
                              "or object in scene 'probe'; the robot's body needs 0.160 m "
                              "(0.110 m short)")


def test_a_given_route_needs_the_body_only_and_joined_points():
    # a 0.40 m door: closed for the sampling margin (0.22 m), open for the body (0.16 m)
    scene = doorway(0.50)
    route = [(-1.0, 0.0), (1.0, 0.0)]
    assert not connected(scene, *route, 0.22) and connected(scene, *route, BODY_RADIUS)
    task = RouteFollowingTask(route=route, start_jitter=(0.0, 0.0))
    task.check_scene(scene)
    assert task.path_radius == BODY_RADIUS
    with pytest.raises(ValueError, match=r"route points 0 \(-1.000, 0.000\) and 1 \(1.000, "
                                         r"0.000\) are not joined by any path for a disc of "
                                         r"0.16 m radius in scene 'two_rooms'"):
        RouteFollowingTask(route=route, start_jitter=(0.0, 0.0)).check_scene(two_rooms())
