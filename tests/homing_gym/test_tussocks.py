"""The example natural world: tussock blades of the stated sizes, written as a user's file."""

import numpy as np
import pytest

from homing_gym.scenes import MeshScene
from homing_gym.scenes.base import clearances
from homing_gym.scenes.tussocks import main, tussock_blades


def test_blades_have_the_stated_sizes():
    corners, colors = tussock_blades(2000, seed=3, half=4.0)
    assert corners.shape == (2000, 3, 3) and colors.shape == (2000, 3)
    width = np.linalg.norm(corners[:, 1, :2] - corners[:, 0, :2], axis=1)
    height = corners[:, 2, 2]
    assert 0.01 <= width.min() and width.max() <= 0.04
    assert 0.05 <= height.min() and height.max() <= 0.9
    assert np.all(corners[:, :2, 2] == 0)                       # feet on the floor
    assert np.abs(corners[..., :2]).max() <= 4.0 + 0.15 + 0.2 * 0.9
    assert np.all((colors >= 0) & (colors <= 1)) and np.all(colors[:, 1] > colors[:, 2])


def test_blades_refuse_a_bad_count():
    with pytest.raises(ValueError, match="blades must be an integer >= 1, got 0"):
        tussock_blades(0, seed=0, half=1.0)


def test_the_glb_keeps_parts_so_grass_can_be_passed_through(tmp_path):
    path = tmp_path / "sub" / "field.glb"
    assert main([str(path), "--blades", "400", "--rocks", "3"]) == 0
    solid = MeshScene.from_file(path, bounds=((-4, -4), (4, 4)))
    assert {p.name for p in solid.meshes} == {"sand", "grass", "rocks"}
    grass = next(p for p in solid.meshes if p.name == "grass")
    feet = grass.vertices[grass.faces[:, 0], :2]
    through = MeshScene.from_file(path, bounds=((-4, -4), (4, 4)), no_collision=("grass",))
    assert np.median(clearances(solid, feet)) < 0.02 < 0.3 < np.median(clearances(through, feet))


def test_the_ply_is_one_mesh_with_face_colours(tmp_path):
    path = tmp_path / "field.ply"
    assert main([str(path), "--blades", "300", "--rocks", "2"]) == 0
    (part,) = MeshScene.from_file(path, collision=False, bounds=((-4, -4), (4, 4))).meshes
    assert len(part.faces) == 2 + 300 + 2 * 80
    assert len(np.unique(np.round(part.face_colors, 3), axis=0)) > 100
