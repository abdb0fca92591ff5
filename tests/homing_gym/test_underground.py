"""The floor under the ground is blocked: where the first mesh surface above the height
band faces up (a terrain's hill rising above the band), not under a ceiling or a table
top (which face down), never under a part the robot passes through
(:func:`homing_gym.scenes.footprint.underground`)."""

import math
from pathlib import Path

import numpy as np
import pytest
import trimesh

from homing_gym.scenes import MeshScene
from homing_gym.scenes.base import clearance, clearances
from homing_gym.scenes.footprint import STEEP, underground
from homing_gym.scenes.mesh_part import MeshPart

BAND = (0.02, 0.35)
BOUNDS = ((-4.0, -4.0), (4.0, 4.0))
HILL = (1.5, 0.0)             # the cone's centre: above the band within 0.9 m of it


def heightfield(height, step=0.25, reach=5.0):
    """A grid mesh over [-reach, reach]^2 of heights ``height(x, y)``, wound so that its
    normals point up (an open terrain surface)."""
    ticks = np.arange(-reach, reach + step / 2, step)
    x, y = np.meshgrid(ticks, ticks, indexing="ij")
    vertices = np.column_stack([x.ravel(), y.ravel(), height(x, y).ravel()])
    n = len(ticks)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij")
    v00, v10 = (i * n + j).ravel(), ((i + 1) * n + j).ravel()
    v11, v01 = ((i + 1) * n + j + 1).ravel(), (i * n + j + 1).ravel()
    faces = np.concatenate([np.column_stack([v00, v10, v11]),
                            np.column_stack([v00, v11, v01])])
    return vertices, faces


def hill(x, y):
    """Ground 0.2 m below the floor with a cone rising to 1.2 m at :data:`HILL`."""
    r = np.hypot(x - HILL[0], y - HILL[1])
    return -0.2 + 1.4 * np.maximum(0.0, 1.0 - r / 1.5)


def quad(z, half=3.0, up=True):
    """A one-sided horizontal square at height ``z``, its normal up or down."""
    vertices = np.array([(-half, -half, z), (half, -half, z), (half, half, z),
                         (-half, half, z)])
    faces = np.array([(0, 1, 2), (0, 2, 3)])
    return vertices, faces if up else faces[:, ::-1]


def part(vertices, faces, name="mesh", collision=True):
    return MeshPart(vertices, faces, np.full((len(faces), 3), 0.5), collision=collision,
                    name=name)


def test_the_floor_under_a_hill_above_the_band_is_blocked():
    """An open terrain (normals up) whose hill rises above the band: the floor under the
    hill is under the ground (the robot would see the terrain from behind), the floor
    beside it free. Before, the ring where the slope crosses the band blocked and the
    floor inside the ring was free."""
    scene = MeshScene.from_arrays(*heightfield(hill), bounds=BOUNDS)
    under = [(HILL[0] + r * math.cos(a), HILL[1] + r * math.sin(a))
             for r in (0.0, 0.4, 0.8) for a in np.linspace(0, 2 * math.pi, 7)]
    assert np.all(clearances(scene, under) == 0.0)
    # beside the hill: free up to the ring (r = 1.26 m) where the slope crosses the band
    assert clearance(scene, (-2.0, 0.0)) == pytest.approx(2.0, abs=0.05)   # the fence
    assert clearance(scene, (HILL[0], -3.0)) == pytest.approx(1.0, abs=0.05)
    assert clearance(scene, (HILL[0], -2.0)) == pytest.approx(2.0 - 1.26, abs=0.06)


def test_a_table_top_above_the_band_keeps_the_floor_under_it_free():
    """A closed box above the band: its underside, the first surface above the floor,
    faces down."""
    top = trimesh.creation.box((1.2, 0.8, 0.04))
    scene = MeshScene.from_arrays(top.vertices + (0.0, 0.0, 0.72), top.faces, bounds=BOUNDS)
    assert clearance(scene, (0.0, 0.0)) == pytest.approx(4.0, abs=0.05)   # the fence only


@pytest.mark.parametrize("down", [True, False])
def test_a_one_sided_ceiling_keeps_the_room_free_only_facing_down(down):
    """A one-sided plane over the whole room: facing down (a ceiling seen from its front)
    the room stays free; facing up (seen from behind: the underside of a floor above, or
    of the ground) the floor under it is blocked."""
    scene = MeshScene.from_arrays(*quad(2.5, half=5.0, up=not down), bounds=BOUNDS)
    got = clearances(scene, [(0.0, 0.0), (-2.0, 1.0), (3.0, 3.0)])
    if down:
        np.testing.assert_allclose(got, [4.0, 2.0, 1.0], atol=0.05)
    else:
        assert np.all(got == 0.0)


def test_the_lowest_surface_over_each_point_decides():
    """Per point, not per triangle: one long up-facing slope (0.4 m at x = -3 up to 5 m at
    x = 3) over a down-facing ceiling at 2 m for x > 0.5 (a room dug into a hillside):
    under the ceiling the floor is free, under the lower part of the slope it is blocked,
    though the slope's lowest corner lies below the ceiling."""
    slope = np.array([(-3, -3, 0.4), (3, -3, 5.0), (3, 3, 5.0), (-3, 3, 0.4)])
    ceiling = np.array([(0.5, -3, 2.0), (3, -3, 2.0), (3, 3, 2.0), (0.5, 3, 2.0)])
    faces = np.array([(0, 1, 2), (0, 2, 3)])
    parts = (part(slope, faces), part(ceiling, faces[:, ::-1]))
    origin, resolution, shape = np.array([-4.0, -4.0]), 0.05, (161, 161)
    grid = underground(parts, BAND, origin, resolution, shape)
    x = origin[0] + np.arange(shape[0]) * resolution
    y = origin[1] + np.arange(shape[1]) * resolution
    assert grid[np.ix_((x > -2.9) & (x < 0.45), np.abs(y) < 2.9)].all()
    assert not grid[x > 0.55].any()
    assert not grid[x < -3.1].any() and not grid[:, np.abs(y) > 3.1].any()


def test_nearly_vertical_faces_block_nothing_but_hide_what_is_above():
    """A leaning board (3 degrees off vertical, its normal slightly up) above the band
    blocks nothing; under a roof (facing up) the points under the board stay free."""
    lean = math.tan(math.radians(3.0))
    board = np.array([(0.0, -1, 0.5), (-2.0 * lean, -1, 2.5), (-2.0 * lean, 1, 2.5),
                      (0.0, 1, 0.5)])
    faces = np.array([(0, 2, 1), (0, 3, 2)])
    normal = np.cross(*(board[faces[0, 1:]] - board[faces[0, 0]]))
    assert 0 < normal[2] / np.linalg.norm(normal) < STEEP           # up, but steep
    origin, resolution, shape = np.array([-2.0, -2.0]), 0.01, (401, 401)
    alone = underground((part(board, faces),), BAND, origin, resolution, shape)
    assert not alone.any()
    roof = part(*quad(3.0, half=1.5))
    covered = underground((part(board, faces), roof), BAND, origin, resolution, shape)
    x = origin[0] + np.arange(shape[0]) * resolution
    y = origin[1] + np.arange(shape[1]) * resolution
    board_x = (x > -2 * lean + 0.005) & (x < -0.005)
    assert board_x.sum() >= 8
    assert not covered[np.ix_(board_x, np.abs(y) < 0.99)].any()
    roof_x = (np.abs(x) < 1.45) & ((x < -2 * lean - 0.005) | (x > 0.005))
    assert covered[np.ix_(roof_x, np.abs(y) < 1.45)].all()


def test_parts_without_collision_block_nothing_under_them():
    """Grass or a hill the robot passes through (``collision=False``, or named in
    ``no_collision``) does not make the floor under it the underground."""
    post = trimesh.creation.box((0.2, 0.2, 0.5))
    parts = [part(*heightfield(hill), name="hill", collision=False),
             part(post.vertices + (-2.0, 2.0, 0.25), post.faces, name="post")]
    for scene in (MeshScene.from_parts(parts, bounds=BOUNDS),
                  MeshScene.from_parts([part(*heightfield(hill), name="hill"), parts[1]],
                                       bounds=BOUNDS, no_collision=("hill",))):
        assert clearance(scene, HILL) == pytest.approx(4.0 - HILL[0], abs=0.05)
    assert not underground(tuple(parts[:1]), BAND, np.zeros(2), 0.05, (100, 100)).any()


WORLDS = Path(__file__).resolve().parents[2] / ".." / "shared" / "worlds"


@pytest.mark.slow
def test_outdoor_world_free_floor_is_not_under_its_hills():
    """The outdoor site (hills to 7.7 m above the floor, open terrain): its free floor is
    the lowland, and from free points a ray straight up meets no terrain from behind (a
    check by ray casting, apart from the z-buffer)."""
    path = WORLDS / "cpr_inspection_outdoor" / "inspection_world.glb"
    if not path.is_file():
        pytest.skip(f"{path} is not here")
    scene = MeshScene.from_file(path, up="z")
    (xmin, ymin), (xmax, ymax) = scene.bounds
    rng = np.random.default_rng(0)
    points = rng.uniform((xmin, ymin), (xmax, ymax), size=(4000, 2))
    free = points[clearances(scene, points) > 0.25]
    assert 0.1 < len(free) / len(points) < 0.3            # was about 0.9: under the hills
    mesh = trimesh.util.concatenate([trimesh.Trimesh(p.vertices, p.faces, process=False)
                                     for p in scene.meshes if p.collision])
    origins = np.column_stack([free, np.full(len(free), BAND[1] + 1e-3)])
    hits, ray, tri = mesh.ray.intersects_location(
        origins, np.tile((0.0, 0.0, 1.0), (len(free), 1)), multiple_hits=True)
    first = {}
    for k, (r, t) in enumerate(zip(ray, tri)):
        if r not in first or hits[k, 2] < hits[first[r][0], 2]:
            first[r] = (k, t)
    normals = mesh.face_normals[[t for _, t in first.values()]]
    assert np.all(normals[:, 2] < STEEP)                   # none seen from behind
