"""The column caster's shortcuts: each gives exactly the hits of the plain search."""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

from homing_gym.benchmark import grass_world, mesh_world
from homing_gym.render.column_cast import (CELL, _ATAN_SLACK, _approx_atan2, cast_columns,
                                           triangle_grid)
from homing_gym.render.raycast import camera_rays, panorama_rays, perspective_rays
from homing_gym.render.worldmesh import world_mesh


@pytest.fixture(scope="module")
def rocks():
    """The benchmark's mesh world (30 lumpy rocks, 9,650 small triangles), as the caster
    takes it, and camera poses in it."""
    mesh = world_mesh(mesh_world())
    rng = np.random.default_rng(0)
    poses = [(x, y, rng.uniform(-math.pi, math.pi), rng.choice([0.05, 0.3, 1.2]))
             for x, y in rng.uniform(-4.5, 4.5, (8, 2))]
    return mesh, poses


def _cast(mesh, pose, rays, weighted=None, triangles=None):
    x, y, yaw, height = pose
    H, W = rays.tan_elev.shape
    hit, weights = np.empty((H, W), np.int64), np.full((H, W, 3), np.nan)
    depth = np.empty((W, H))
    if weighted is None:
        weighted = np.ones(len(mesh.triangles), np.bool_)
    if triangles is None:
        triangles = triangle_grid(mesh.triangles, mesh.normals, mesh.closed)
    drawn = np.empty(len(mesh.triangles), np.int64)
    shown = cast_columns(*triangles, np.array([x, y, height]), yaw, *rays, weighted, hit,
                         weights, depth, drawn)
    return hit, weights, depth.T, drawn[:shown]


def test_the_approximate_arctangent_is_within_its_stated_error():
    rng = np.random.default_rng(0)
    ys, xs = rng.normal(size=(2, 20000)) * rng.choice([1e-6, 1.0, 1e6], (2, 20000))
    ys[:4], xs[:4] = [0.0, 1.0, -1.0, 0.0], [1.0, 0.0, 0.0, -1.0]   # on the axes
    error = max(abs(_approx_atan2(y, x) - math.atan2(y, x)) for y, x in zip(ys, xs)
                if not (y == 0.0 and x < 0.0))                     # +-pi: the same bearing
    assert error < 2.9e-7 < _ATAN_SLACK / 2


def test_a_camera_knows_its_ray_layout():
    pano = panorama_rays((48, 256), math.radians(60), 2)
    assert pano.circle and pano.even_rows and pano.tan_elev.shape == (96, 512)
    np.testing.assert_allclose(pano.top_angle, math.radians(30) - math.radians(60) / 192)
    np.testing.assert_allclose(pano.rows_per_radian, 95 / (math.radians(60) * 95 / 96))
    view = perspective_rays(160, 120, 140.0)
    assert not view.circle and not view.even_rows
    part = camera_rays(pano.beta[:-1], pano.tan_elev[:, :-1])
    assert not part.circle and part.even_rows


def test_dropping_segments_between_rows_changes_no_pixel(rocks):
    """Where the rows are even in elevation the caster drops segments that fall between
    two rows before it searches their rows; the hits are those of the search alone."""
    mesh, poses = rocks
    rays = panorama_rays((48, 256), math.radians(60), 2)
    for pose in poses:
        dropped, _, near, _ = _cast(mesh, pose, rays)
        searched, _, far, _ = _cast(mesh, pose, rays._replace(even_rows=False))
        assert np.array_equal(dropped, searched) and np.array_equal(near, far)
        assert (dropped >= 0).mean() > 0.4                  # the rocks, walls and floor


def test_columns_found_by_arithmetic_are_those_found_by_search(rocks):
    """A panorama's columns go once round the circle at even steps, so the caster finds
    a triangle's columns by arithmetic; without the last column they do not, and it
    searches: every other column comes out the same."""
    mesh, poses = rocks
    rays = panorama_rays((48, 256), math.radians(60), 1)
    part = camera_rays(rays.beta[:-1].copy(), rays.tan_elev[:, :-1])
    for pose in poses:
        circle, _, _, _ = _cast(mesh, pose, rays)
        searched, _, _, _ = _cast(mesh, pose, part)
        assert np.array_equal(circle[:, :-1], searched)


def test_weights_are_written_only_where_the_shader_reads_them(rocks):
    mesh, poses = rocks
    rays = panorama_rays((48, 256), math.radians(60), 1)
    rng = np.random.default_rng(1)
    weighted = rng.random(len(mesh.triangles)) < 0.5
    for pose in poses[:3]:
        hit, weights, _, _ = _cast(mesh, pose, rays, weighted=weighted)
        every, all_weights, _, _ = _cast(mesh, pose, rays)
        assert np.array_equal(hit, every)
        seen = hit >= 0
        needed = seen & weighted[np.maximum(hit, 0)]
        assert needed.any() and (seen & ~needed).any()
        assert np.array_equal(weights[needed], all_weights[needed])
        np.testing.assert_allclose(all_weights[seen].sum(1), 1.0, atol=1e-9)
        none = np.zeros(len(mesh.triangles), np.bool_)
        assert np.isnan(_cast(mesh, pose, rays, weighted=none)[1]).all()


def test_the_drawn_triangles_are_listed_once_and_include_every_one_hit(rocks):
    """The shader lights only the triangles the caster lists as drawn."""
    mesh, poses = rocks
    for rays in (panorama_rays((48, 256), math.radians(60), 2), perspective_rays(80, 60, 70.0)):
        for pose in poses:
            hit, _, _, drawn = _cast(mesh, pose, rays)
            assert len(set(drawn)) == len(drawn)
            assert set(np.unique(hit[hit >= 0])) <= set(drawn)


@pytest.fixture(scope="module")
def grass():
    """Dense grass (3,000 blades on 3 x 3 m: the caster culls hidden ones there), one
    blade across a cell boundary (its centre on it) and one standing on one, with the
    triangles grouped for culling and in the mesh's order (every one cast)."""
    mesh = world_mesh(grass_world(3000, seed=1))
    tris = mesh.triangles.copy()
    tris[:, :, :2] *= 0.3
    x = tris[:, :, 0].min() + 2 * CELL                      # a boundary between cells
    tris[-2] = [[x - 0.01, 0.2, 0.0], [x + 0.01, 0.2, 0.0], [x, 0.2, 0.6]]
    tris[-1] = [[x, -0.3, 0.0], [x + 0.02, -0.3, 0.0], [x, -0.3, 0.7]]
    mesh.triangles = tris
    culled = triangle_grid(mesh.triangles, mesh.normals, mesh.closed)
    every = triangle_grid(mesh.triangles, mesh.normals, mesh.closed, cull_density=np.inf)
    assert len(culled.box) > 1 and len(every.box) == 0
    return mesh, culled, every


def test_culling_hidden_grass_changes_no_pixel(grass):
    """Front to back, the caster skips the blades hidden behind nearer ones; the hits
    and depths are those of casting every blade, at random poses (cameras inside the
    grass, at its edge and outside it), and it did skip some."""
    mesh, culled, every = grass
    rays = panorama_rays((48, 256), math.radians(60), 2)
    rng = np.random.default_rng(2)
    poses = [(*rng.uniform(-2.0, 2.0, 2), rng.uniform(-math.pi, math.pi), h)
             for h in (0.05, 0.3, 0.3, 0.3, 1.2, 3.0)]
    poses += [(0.0, 0.0, 0.5, 0.3), (0.15, 0.06, -2.0, 0.2), (4.0, -3.0, 2.0, 0.3)]
    fewer = 0
    for pose in poses:
        hit, _, depth, drawn = _cast(mesh, pose, rays, triangles=culled)
        every_hit, _, every_depth, every_drawn = _cast(mesh, pose, rays, triangles=every)
        assert np.array_equal(hit, every_hit) and np.array_equal(depth, every_depth)
        fewer += len(drawn) < len(every_drawn)
    assert fewer >= len(poses) // 2


def test_a_pinhole_view_of_culled_grass_is_that_of_every_blade(grass):
    """Views (columns by search) cast every blade, in the grid's order: the same hits."""
    mesh, culled, every = grass
    rays = perspective_rays(80, 60, 70.0)
    for pose in [(0.0, 0.0, 0.5, 0.3), (0.6, -0.4, 2.5, 0.1)]:
        assert np.array_equal(_cast(mesh, pose, rays, triangles=culled)[0],
                              _cast(mesh, pose, rays, triangles=every)[0])


@pytest.mark.parametrize("turns", [-3, -1, 1, 3])
def test_any_heading_gives_the_picture_of_the_same_heading_within_one_turn(rocks, turns):
    """A heading a whole number of turns away is the same camera: the panorama (columns by
    arithmetic) and a pinhole view (columns by search) hit the same triangles, whatever
    the heading's size. Before the bearings were wrapped a heading past pi sent the
    panorama's columns out of the image (a write out of bounds: CI aborted)."""
    mesh, poses = rocks
    for rays in (panorama_rays((48, 256), math.radians(60), 1), perspective_rays(80, 60, 70.0)):
        for x, y, yaw, height in poses[:4]:
            near = _cast(mesh, (x, y, yaw, height), rays)[0]
            far = _cast(mesh, (x, y, yaw + 2 * math.pi * turns, height), rays)[0]
            assert (near >= 0).mean() > 0.4
            assert (far != near).mean() < 1e-3          # cos(yaw + beta) rounds differently


#: Renders odd cameras (any heading, tiny to large images, 1-3 rays per pixel side,
#: cameras outside the world, near the ground and above the walls) in a mesh world and
#: two textured ones, with and without shadows.
_ODD_CAMERAS = """
import sys
import numpy as np
from homing_gym.benchmark import grass_world, mesh_world
from homing_gym.render.panorama import CameraConfig, Lighting
from homing_gym.render.raycast import RayCaster
from homing_gym.scenes import scene_factory
from homing_gym.render.worldmesh import world_mesh
rng = np.random.default_rng(0)
for scene in (mesh_world(), grass_world(30000), scene_factory("hallway").build(rng),
              scene_factory("random_rooms").build(rng)):
    mesh = world_mesh(scene)
    (xmin, ymin), (xmax, ymax) = scene.bounds
    for shadows in (False, True):
        caster = RayCaster(mesh, shadows=shadows)
        for _ in range(25):
            pose = (rng.uniform(xmin - 1, xmax + 1), rng.uniform(ymin - 1, ymax + 1),
                    rng.uniform(-40, 40))
            height = float(rng.choice([0.001, 0.01, 0.3, 2.0, 5.0]))
            shape = (int(rng.integers(8, 40)), int(rng.integers(16, 300)))
            config = CameraConfig(panorama_shape=shape, vfov=float(rng.uniform(0.18, 2.09)))
            light = Lighting(direction=tuple(rng.normal(size=3) + [0, 0, 1.5]))
            caster.panorama(pose, height, config, light, int(rng.integers(1, 4)))
            caster.perspective(pose, height, int(rng.integers(1, 90)),
                               int(rng.integers(1, 70)), float(rng.uniform(5, 300)), light,
                               int(rng.integers(1, 3)))
"""


@pytest.mark.slow
def test_the_caster_never_reads_or_writes_outside_its_arrays(tmp_path):
    """numba does not check indices: a write out of bounds corrupts memory silently and
    crashes later somewhere else. Compiled with bounds checks (``NUMBA_BOUNDSCHECK``, in
    a fresh cache), odd cameras must render without an ``IndexError``."""
    env = dict(os.environ, NUMBA_BOUNDSCHECK="1", NUMBA_CACHE_DIR=str(tmp_path))
    run = subprocess.run([sys.executable, "-c", _ODD_CAMERAS], env=env, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]


def test_the_triangles_a_panorama_shows_make_the_same_panorama_alone():
    from homing_gym.benchmark import shown_caster
    from homing_gym.render.panorama import CameraConfig
    from homing_gym.render.raycast import RayCaster

    mesh = world_mesh(grass_world(5000))
    caster, config = RayCaster(mesh), CameraConfig()
    rng = np.random.default_rng(3)
    for x, y, yaw in zip(*rng.uniform(-4.5, 4.5, (2, 6)), rng.uniform(-math.pi, math.pi, 6)):
        full = caster.panorama((x, y, yaw), 0.3, config)
        alone = shown_caster(caster, (x, y, yaw), 0.3, config)
        assert 0 < len(alone.mesh.triangles) < len(mesh.triangles) // 2
        np.testing.assert_array_equal(alone.panorama((x, y, yaw), 0.3, config), full)
    with pytest.raises(ValueError, match="shadows=True"):
        shown_caster(RayCaster(mesh, shadows=True), (0.0, 0.0, 0.0), 0.3, config)
