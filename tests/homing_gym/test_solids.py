"""One geometry source: what the robot sees (the ray caster's triangles) is what it bumps
into (PyBullet's collision bodies), in every built-in scene."""

import dataclasses
import math

import numpy as np
import pytest
import trimesh

from homing_gym.scenes import available_scenes, scene_factory
from homing_gym.scenes.base import Landmark, Wall, clearances
from homing_gym.sim.simulator import Simulator
from homing_gym.scenes.solids import Solid, landmark_solid, wall_solid
from homing_gym.render.worldmesh import world_mesh

#: Horizontal rays per origin, and their heights (metres): the robot's body height band.
RAYS, HEIGHTS = 48, (0.05, 0.15, 0.25)


def _collision_and_visual_ranges(scene, rng):
    """Distances along the same rays to PyBullet's first collision hit and to the first
    world-mesh triangle; fence hits (collided with, never drawn) are left out."""
    xy = rng.uniform(*np.array(scene.bounds), size=(400, 2))
    xy = xy[clearances(scene, xy) > 0.1][:8]
    assert len(xy) >= 4, f"{scene.name}: too few free points"
    a = np.linspace(0, 2 * math.pi, RAYS, endpoint=False)
    starts = np.array([(x, y, z) for x, y in xy for z in HEIGHTS for _ in a])
    dirs = np.tile(np.column_stack([np.cos(a), np.sin(a), np.zeros_like(a)]),
                   (len(xy) * len(HEIGHTS), 1))
    reach = 30.0
    sim = Simulator(scene, renderer="tiny")
    try:
        sim.place_robot((1000.0, 1000.0, 0.0))         # out of the rays' way
        hits = sim.client.rayTestBatch(starts.tolist(), (starts + reach * dirs).tolist())
        fence = set(sim.fence_ids)
    finally:
        sim.close()
    physical = np.array([h[2] * reach if h[0] >= 0 else np.inf for h in hits])
    keep = np.array([h[0] not in fence for h in hits])
    # mesh parts the robot passes through (grass, ferns, monitors, far boulders) are seen
    # and never bumped into, by design: the drawn world here is the colliding one
    m = world_mesh(dataclasses.replace(scene, meshes=tuple(p for p in scene.meshes
                                                           if p.collision)))
    tm = trimesh.Trimesh(m.triangles.reshape(-1, 3), np.arange(3 * len(m.triangles)).reshape(-1, 3),
                         process=False)
    loc, ray, _ = tm.ray.intersects_location(starts, dirs, multiple_hits=True)
    visual = np.full(len(starts), np.inf)
    np.minimum.at(visual, ray, np.einsum("ij,ij->i", loc - starts[ray], dirs[ray]))
    # the drawn surface along the same rays moved 2 mm sideways, either way
    side = np.column_stack([-dirs[:, 1], dirs[:, 0], np.zeros(len(dirs))])
    beside = np.full((2, len(starts)), np.inf)
    for k, shift in enumerate((0.002, -0.002)):
        loc, ray, _ = tm.ray.intersects_location(starts + shift * side, dirs, multiple_hits=True)
        np.minimum.at(beside[k], ray, np.einsum("ij,ij->i", loc - starts[ray] - shift * side[ray],
                                                dirs[ray]))
    return physical[keep], visual[keep], beside[:, keep]


@pytest.mark.parametrize("name", available_scenes())
def test_the_robot_bumps_into_what_it_sees(name):
    """Along horizontal rays at body height from free points, the first collision hit
    lies where the first drawn triangle of a colliding part does, and a ray misses both or neither. The
    median ray agrees to 0.1 mm and 95 % to 1 mm; the rest graze a cylinder, drawn as a
    64-sided prism 0.1 % of its radius inside the true circle, which along a grazing ray
    of a 0.25 m post is up to sqrt(2 r * 0.001 r) = 1.1 cm (a misplaced wall or post moves
    the median and the 95th percentile); a ray that grazes a corner within the collision
    margin may hit farther on, but only where a drawn surface is."""
    factory = scene_factory(name)
    scene = factory.build(np.random.default_rng(3))
    physical, visual, beside = _collision_and_visual_ranges(scene, np.random.default_rng(0))
    both = np.isfinite(physical) & np.isfinite(visual)
    assert np.array_equal(np.isfinite(physical), np.isfinite(visual)), name
    assert both.sum() > 100
    err = np.abs(physical[both] - visual[both])
    assert np.median(err) < 1e-4 and np.percentile(err, 95) < 1e-3, (name, np.sort(err)[-20:])
    # a ray grazing a box's corner within PyBullet's collision margin hits it and misses
    # the drawn face: the same ray 2 mm to one side meets the drawn face there
    far = err >= 0.02
    near_side = np.min(np.abs(beside[:, both] - physical[both]), axis=0)
    assert far.mean() < 0.01 and np.all(near_side[far] < 0.02), (name, err[far])


def test_walls_and_landmarks_become_solids_as_placed():
    """Hand-computed: a 2 m wall along +y is a box 2.05 x 0.05 m centred on its midpoint,
    turned by 90 degrees; a landmark stands on its base."""
    wall = wall_solid(Wall((1.0, 0.0), (1.0, 2.0), height=0.5, thickness=0.05))
    assert wall.shape == "box" and wall.centre == pytest.approx((1.0, 1.0, 0.25))
    assert wall.half == pytest.approx((1.025, 0.025, 0.25))
    assert wall.yaw == pytest.approx(math.pi / 2)
    post = landmark_solid(Landmark((0.5, -0.5), radius=0.1, height=0.4, base=0.2))
    assert (post.shape, post.radius, post.height) == ("cylinder", 0.1, pytest.approx(0.4))
    assert post.centre == pytest.approx((0.5, -0.5, 0.4))


def test_unknown_solid_shape_is_refused():
    with pytest.raises(ValueError, match="sphere"):
        Solid("sphere", (0, 0, 0), (1, 1, 1))
