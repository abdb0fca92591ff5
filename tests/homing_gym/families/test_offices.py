"""The offices family: an open-plan floor of desks in rows with chairs, windows high on the
walls and furniture along them, every part of it reached through aisles, desks and chairs
the robot bumps into and monitors that block nothing."""

import numpy as np

from homing_gym.scenes.base import clearances

FAMILY = "offices"


def test_worlds_are_walled_floors_of_varied_finishes_where_only_monitors_pass(world):
    worlds = [world(seed) for seed in range(6)]
    for w in worlds:
        assert w.name == "offices" and w.ground_plane and not w.fence
        assert 8.0 <= w.size[0] <= 16.0 and 6.0 <= w.size[1] <= 12.0
        assert all(2.0 <= wall.height <= 3.0 for wall in w.walls)
        assert {p.name for p in w.meshes if not p.collision} <= {"on_top"}
    assert len({w.floor_texture for w in worlds} | {w.walls[0].texture for w in worlds}) >= 4


def test_the_generator_declares_the_solids_trimesh_would_find(world,
                                                              assert_solids_as_trimesh_finds):
    assert_solids_as_trimesh_finds(world(2).meshes)


def test_desks_stand_in_rows_with_chairs_windows_above_and_furniture_along_the_walls(world,
                                                                                     part):
    desks = chairs = 0
    for seed in range(6):
        scene = world(seed)
        tops = np.array(scene.metadata["desks"]).reshape(-1, 4)
        assert len(tops) >= 4
        sizes = np.sort(tops[:, 2:] - tops[:, :2], axis=1)
        assert np.all((sizes[:, 0] > 0.68) & (sizes[:, 0] < 0.8))
        assert np.all((sizes[:, 1] > 1.18) & (sizes[:, 1] < 1.6))
        # in rows: the desks' edges line up, a few lines for many desks
        lines = min(len(np.unique(tops[:, k].round(2))) for k in (1, 0))
        assert lines <= len(tops) / 2
        # the floor under a desk and between its legs is blocked, as is a chair's foot
        middles = (tops[:, :2] + tops[:, 2:]) / 2
        assert np.all(clearances(scene, middles) == 0.0)
        assert np.all(clearances(scene, scene.metadata["chairs"]) == 0.0)
        desks, chairs = desks + len(tops), chairs + len(scene.metadata["chairs"])
        names = [lm.name for lm in scene.landmarks]
        windows = [lm for lm in scene.landmarks if lm.name == "window"]
        assert windows and all(lm.base >= 0.8 and lm.base + lm.height <= scene.walls[0].height
                               for lm in windows)
        assert sum(n in ("cabinet", "locker", "bookcase", "printer") for n in names) >= 2
        screens = part(scene, "on_top").vertices
        assert screens[:, 2].min() >= 0.72 and len(screens) >= 16 * len(tops)
    assert desks >= 40 and chairs >= 0.7 * desks


def test_every_part_of_the_floor_is_reached_through_aisles(world, assert_reached_through_aisles):
    for seed in range(4):
        assert_reached_through_aisles(world(seed))


def test_only_furniture_blocks_and_monitors_do_not(world, floor_grid, without):
    scene = world(1)
    grid = floor_grid(scene)
    free = clearances(scene, grid)
    assert np.array_equal(free, clearances(without(scene, "on_top"), grid))
    opened = clearances(without(scene, "furniture"), grid)
    assert np.all(opened >= free) and np.mean(opened > free + 0.1) > 0.05


def test_robot_bumps_into_a_desk(world, bump_into_a_side):
    scene = world(0)
    gap = bump_into_a_side(scene, scene.metadata["desks"], 0.7)
    assert 0.12 < gap < 0.25                       # stopped at the desk's edge
