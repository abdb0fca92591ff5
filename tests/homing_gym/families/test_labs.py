"""The labs family: one hall far more cluttered than an office (benches along the walls,
islands, boxes of many sizes and colours on the floor) yet reached everywhere through
aisles, clutter the robot bumps into and things on benches and shelves that block
nothing."""

import numpy as np

from homing_gym.scenes.base import clearances

FAMILY = "labs"


def test_worlds_are_walled_halls_where_only_what_stands_on_top_passes(world):
    for w in map(world, range(6)):
        assert w.name == "labs" and w.ground_plane and not w.fence
        assert 6.0 <= w.size[0] <= 12.0 and 5.0 <= w.size[1] <= 9.0
        assert all(2.0 <= wall.height <= 3.0 for wall in w.walls)
        assert {p.name for p in w.meshes if not p.collision} <= {"on_top"}


def test_the_generator_declares_the_solids_trimesh_would_find(world,
                                                              assert_solids_as_trimesh_finds):
    assert_solids_as_trimesh_finds(world(3).meshes)


def test_a_hall_far_more_cluttered_than_an_office_with_boxes_of_many_sizes_and_colours(
        world, part, floor_grid, blocked_share):
    blocked = {"labs": [], "offices": []}
    for seed in range(5):
        for name in blocked:
            scene = world(seed, name)
            blocked[name].append(blocked_share(scene, floor_grid(scene)))
        scene = world(seed)
        names = [lm.name for lm in scene.landmarks]
        assert names.count("bench") + len(scene.metadata["islands"]) >= 2
        boxes = np.array(scene.metadata["floor_boxes"]).reshape(-1, 4)
        middles = (boxes[:, :2] + boxes[:, 2:]) / 2
        assert len(boxes) >= 3 and np.all(clearances(scene, middles) == 0.0)
        boxes_part = part(scene, "boxes")
        assert len(boxes_part.solids) >= 5
        assert len(np.unique(boxes_part.face_colors.round(2), axis=0)) >= 5
        assert np.ptp((boxes[:, 2:] - boxes[:, :2]).max(axis=1)) > 0.2     # many sizes
    assert np.mean(blocked["labs"]) > 1.6 * np.mean(blocked["offices"])


def test_every_part_of_the_floor_is_reached_through_aisles(world, assert_reached_through_aisles):
    for seed in range(4):
        assert_reached_through_aisles(world(seed))


def test_clutter_blocks_and_what_stands_on_benches_and_shelves_does_not(world, floor_grid,
                                                                       without):
    scene = world(2)
    grid = floor_grid(scene)
    free = clearances(scene, grid)
    assert np.array_equal(free, clearances(without(scene, "on_top"), grid))
    for name in ("boxes", "furniture"):
        opened = clearances(without(scene, name), grid)
        assert np.all(opened >= free) and np.any(opened > free + 0.1), name


def test_robot_bumps_into_a_floor_box(world, bump_into_a_side):
    scene = world(0)
    gap = bump_into_a_side(scene, scene.metadata["floor_boxes"], 0.6)
    assert 0.12 < gap < 0.22                        # stopped at the box
