"""The ray-cast renderer: geometry against known truth, agreement with TinyRenderer."""

import math

import gymnasium as gym
import numpy as np
import pytest

from homing_gym.render.panorama import Lighting, bearing_column
from homing_gym.render.perspective import PerspectiveConfig
from homing_gym.render.column_cast import _first_past
from homing_gym.render.raycast import RayCaster
from homing_gym.scenes import Landmark, Scene, available_scenes
from homing_gym.vision import luminance

RED = (0.9, 0.05, 0.05, 1.0)


def _pole_scene(x: float, y: float) -> Scene:
    return Scene("pole", bounds=((-3, -3), (3, 3)), walls=(),
                 landmarks=(Landmark((x, y), radius=0.05, height=2.0, color=RED),))


def _red_column(image: np.ndarray, row: int) -> float:
    """Continuous column of the red pole's centre in ``row`` (weighted by redness)."""
    line = image[row].astype(float)
    redness = np.clip(line[:, 0] - line[:, 1:].mean(1), 0, None)
    redness[redness < 20] = 0
    cols = np.nonzero(redness)[0]
    assert len(cols), "pole not in view"
    return float((cols + 0.5) @ redness[cols] / redness[cols].sum())


@pytest.mark.parametrize("supersampling, median, worst", [(1, 0.5, 0.5), (4, 0.25, 0.5)])
def test_pole_bearings_match_the_geometry(supersampling, median, worst):
    """One ray per pixel puts a pole's centre within half a column (the covered columns'
    centres); 4 x 4 rays per pixel give fractional coverage, a quarter column."""
    errors = []
    rng = np.random.default_rng(0)
    for _ in range(12):
        a, d = rng.uniform(-math.pi, math.pi), rng.uniform(1.0, 2.5)
        x, y = d * math.cos(a), d * math.sin(a)
        env = gym.make("homing_gym/LocalHoming-v0", scene=_pole_scene(x, y),
                       renderer="raycast", panorama_shape=(48, 360), start_distance=(0.3, 0.5))
        env.reset(seed=0)
        u = env.unwrapped
        yaw = rng.uniform(-math.pi, math.pi)
        pano = u.sim.caster.panorama([0.0, 0.0, yaw], u.robot_config.camera_height,
                                     u.camera.config, supersampling=supersampling)
        env.close()
        truth = float(bearing_column(math.atan2(y, x) - yaw, 360))
        got = _red_column(pano, 24)
        errors.append(abs((got - truth + 180) % 360 - 180))
    assert np.median(errors) <= median and max(errors) <= worst, errors


def test_elevation_of_the_pole_top_matches_the_geometry():
    env = gym.make("homing_gym/LocalHoming-v0", scene=Scene(
        "low_pole", bounds=((-3, -3), (3, 3)), walls=(),
        landmarks=(Landmark((1.0, 0.0), radius=0.03, height=0.5, color=RED),)),
        renderer="raycast", panorama_shape=(120, 256), start_distance=(0.3, 0.5))
    env.reset(seed=0)
    pano = env.unwrapped.render_panorama(np.array([0.0, 0.0, 0.0]))
    env.close()
    column = pano[:, 128].astype(float)
    red_rows = np.nonzero(column[:, 0] - column[:, 1:].mean(1) > 40)[0]
    # the pole's top edge: 0.5 m high, 0.2 m above the camera, front face 0.97 m away
    top = math.atan2(0.5 - 0.30, 1.0 - 0.03)
    expected_row = (math.radians(30) - top) / math.radians(60) * 120
    assert abs(red_rows.min() - expected_row) <= 1.0


def test_the_same_pose_gives_identical_pixels():
    env = gym.make("homing_gym/LocalHoming-v0", scene="house", renderer="raycast")
    env.reset(seed=1)
    u = env.unwrapped
    a = u.render_panorama(u.pose)
    b = u.render_panorama(u.pose)
    env.close()
    assert np.array_equal(a, b)


def test_an_image_does_not_depend_on_the_images_rendered_before_it():
    """The caster keeps lit colours and buffers between images: a fresh caster, and one
    that has just rendered elsewhere under another light, give the same pixels."""
    env = gym.make("homing_gym/LocalHoming-v0", scene="house", renderer="raycast")
    env.reset(seed=2)
    u = env.unwrapped
    caster, config = u.sim.caster, u.camera.config
    fresh = RayCaster(caster.mesh, caster.sky)
    env.close()
    here, there = (0.5, 0.5, 0.3), (-1.0, 2.0, 2.0)
    light = Lighting(direction=(-0.5, 0.8, 0.6), ambient=0.3, diffuse=0.8)
    first = caster.panorama(here, 0.3, config)
    caster.panorama(there, 0.3, config, light)
    lit = caster.panorama(here, 0.3, config, light)
    assert np.array_equal(caster.panorama(here, 0.3, config), first)
    assert np.array_equal(fresh.panorama(here, 0.3, config, light), lit)
    assert np.array_equal(fresh.panorama(here, 0.3, config), first)
    assert not np.array_equal(lit, first)


def test_casters_sharing_a_thread_or_not_give_the_pixels_each_gives_alone():
    """Casters of one thread share their scratch buffers: a textured world with shadows
    and an untextured one rendered in turn, and each in its own thread at the same
    time, give the images each gives when it is the only caster; the buffers are one
    set per thread."""
    from concurrent.futures import ThreadPoolExecutor

    from homing_gym.render.panorama import CameraConfig
    from homing_gym.render.raycast import scratch_buffers
    from homing_gym.render.worldmesh import world_mesh
    from homing_gym.scenes import scene_factory

    rng = np.random.default_rng(0)
    hallway = RayCaster(world_mesh(scene_factory("hallway").build(rng)), shadows=True)
    pole = RayCaster(world_mesh(_pole_scene(1.0, 0.5)))
    config = CameraConfig()
    poses = [(0.2 * k, 0.1 * k, 0.7 * k) for k in range(4)]
    alone = {id(c): [c.panorama(p, 0.3, config) for p in poses] for c in (hallway, pole)}
    in_turn = {id(c): [] for c in (hallway, pole)}
    for p in poses:
        for c in (pole, hallway):
            in_turn[id(c)].append(c.panorama(p, 0.3, config))
    with ThreadPoolExecutor(2) as pool:
        threads = {id(c): pool.submit(lambda c=c: [c.panorama(p, 0.3, config) for p in poses])
                   for c in (hallway, pole)}
        threaded = {key: future.result() for key, future in threads.items()}
        elsewhere = pool.submit(scratch_buffers, 96, 512).result()[0]
    for key, images in alone.items():
        assert all(np.array_equal(a, b) for a, b in zip(images, in_turn[key]))
        assert all(np.array_equal(a, b) for a, b in zip(images, threaded[key]))
    assert not np.array_equal(alone[id(hallway)][0], alone[id(pole)][0])
    assert scratch_buffers(96, 512)[0] is scratch_buffers(96, 512)[0]
    assert elsewhere is not scratch_buffers(96, 512)[0]


def test_the_caster_search_finds_the_first_value_past_a_bound_from_any_guess():
    rng = np.random.default_rng(0)
    for _ in range(3000):
        values = np.sort(rng.integers(0, 10, int(rng.integers(1, 40))).astype(float))[::-1]
        bound, strict = float(rng.integers(-1, 11)), bool(rng.integers(0, 2))
        past = values < bound if strict else values <= bound
        first = int(np.argmax(past)) if past.any() else len(values)
        for guess in (-1, 0, first, len(values) // 2, len(values), len(values) + 7):
            assert _first_past(values, bound, strict, guess) == first


def test_perspective_view_puts_the_pole_where_the_pinhole_does():
    env = gym.make("homing_gym/LocalHoming-v0", scene=_pole_scene(2.0, 0.5),
                   renderer="raycast", start_distance=(0.3, 0.5))
    env.reset(seed=0)
    view = env.unwrapped.render_view(pose=np.array([0.0, 0.0, 0.0]), size=(320, 240))
    env.close()
    config = PerspectiveConfig(320, 240)
    expected = 160 - config.focal * 0.5 / 2.0          # column coordinate of the axis
    assert abs(_red_column(view, 120) - expected) <= 0.5


@pytest.mark.parametrize("scene", sorted(set(available_scenes())))
def test_raycast_and_tinyrenderer_agree_on_bearings(scene):
    """The column structure (horizontal luminance edges, summed over rows) of both
    renderers' panoramas at the same pose lines up to within one column; shading
    differs (PyBullet's box texture coordinates and its lighting model are not copied)."""
    images = []
    for renderer in ("tiny", "raycast"):
        env = gym.make("homing_gym/LocalHoming-v0", scene=scene, renderer=renderer,
                       panorama_shape=(48, 256), start_distance=(0.3, 0.8))
        env.reset(seed=2)
        u = env.unwrapped
        images.append(u.render_panorama(u.pose))
        env.close()
    edges = [np.abs(np.diff(luminance(im), axis=1, append=luminance(im)[:, :1])).sum(0)
             for im in images]
    a, b = (e - e.mean() for e in edges)
    scores = [float(np.dot(a, np.roll(b, s))) for s in range(-8, 9)]
    assert abs(int(np.argmax(scores)) - 8) <= 1
    diff = np.abs(images[0].astype(int) - images[1].astype(int)).mean()
    print(f"{scene}: mean absolute difference {diff:.1f} grey levels")


@pytest.mark.parametrize("scene", sorted(set(available_scenes())))
def test_every_pixel_hits_what_embree_hits(scene):
    """The column caster against a general ray caster (Intel Embree, one ray per pixel):
    the same triangle at every pixel of panoramas and perspective views at random poses,
    except where two coplanar faces tie (the same depth to 1e-4 m: z-fighting, where
    either answer is right). The poses are outside every solid, where the robot can be
    (inside one, the caster skips the solid's faces turned away: it sees through it)."""
    embree = pytest.importorskip("embreex.rtcore_scene")
    from embreex.mesh_construction import TriangleMesh

    from homing_gym.render.column_cast import cast_columns, triangle_grid
    from homing_gym.render.raycast import panorama_rays, perspective_rays
    from homing_gym.scenes import scene_factory
    from homing_gym.scenes.base import clearance
    from homing_gym.render.worldmesh import world_mesh

    world = scene_factory(scene).build(np.random.default_rng(0))
    mesh = world_mesh(world)
    reference = embree.EmbreeScene()
    TriangleMesh(reference, mesh.triangles)
    tris = mesh.triangles.astype(np.float64)
    rng = np.random.default_rng(3)
    (x0, y0), (x1, y1) = world.bounds
    poses = [(x, y, rng.uniform(-math.pi, math.pi))
             for x, y in rng.uniform((x0, y0), (x1, y1), (200, 2))
             if clearance(world, (x, y)) > 0.02]
    for x, y, yaw in poses[:3]:
        origin = np.array([x, y, rng.uniform(0.05, 0.5)])
        for rays in (panorama_rays((48, 256), math.radians(60)),
                     perspective_rays(160, 120, 140.0)):
            beta, tan = rays.beta, rays.tan_elev
            H, W = tan.shape
            hit, weights = np.empty((H, W), np.int64), np.empty((H, W, 3))
            cast_columns(*triangle_grid(mesh.triangles, mesh.normals, mesh.closed), origin, yaw,
                         *rays, np.ones(len(tris), np.bool_), hit, weights, np.empty((W, H)),
                         np.empty(len(tris), np.int64))
            cos_e = 1 / np.sqrt(1 + tan ** 2)
            dirs = np.stack([cos_e * np.cos(yaw + beta), cos_e * np.sin(yaw + beta),
                             cos_e * tan], -1).reshape(-1, 3).astype(np.float32)
            out = reference.run(np.repeat(origin[None].astype(np.float32), len(dirs), 0),
                                dirs, output=1)
            differ = (out["primID"] != hit.ravel()).nonzero()[0]
            depth = np.full(len(dirs), np.inf)
            for k in differ:
                a, b = out["primID"][k], hit.ravel()[k]
                assert a >= 0 and b >= 0, (scene, k, a, b)
                normal = np.cross(tris[b, 1] - tris[b, 0], tris[b, 2] - tris[b, 0])
                along = float(normal @ (tris[b, 0] - origin)) / float(normal @ dirs[k])
                depth[k] = abs(along - out["tfar"][k])
            assert np.all(depth[differ] < 1e-4), (scene, differ, depth[differ])


def test_camera_height_and_sky_color():
    """An ant's eye 1 cm above the floor sees the horizon line of a flat floor at the
    panorama's middle row; the sky takes the given colour."""
    env = gym.make("homing_gym/LocalHoming-v0", scene=_pole_scene(2.0, 0.0),
                   renderer="raycast", camera_height=0.01, sky_color=(0.0, 0.0, 1.0),
                   panorama_shape=(48, 64), start_distance=(0.3, 0.5))
    env.reset(seed=0)
    pano = env.unwrapped.render_panorama(np.array([0.0, 0.0, 0.0]))
    env.close()
    far = pano[:, 0]                                  # looking backwards: floor and sky only
    assert np.all(far[:24] == [0, 0, 255]) and np.all(far[24:, 2] < 200)
    with pytest.raises(ValueError, match="sky_color needs renderer='raycast'"):
        gym.make("homing_gym/LocalHoming-v0", renderer="tiny", sky_color=(0, 0, 1))
    with pytest.raises(ValueError, match="camera_height"):
        gym.make("homing_gym/LocalHoming-v0", camera_height=-1)


def test_cast_shadows_darken_the_floor_behind_an_object_and_nothing_else(make_env):
    """A 1 m box at the origin, the light from +x at 45 degrees: the floor from x = -0.2
    to about -1.2 m (|y| < 0.5) lies in its shadow and gets the ambient light alone."""
    from homing_gym.render.panorama import CameraConfig
    from homing_gym.render.worldmesh import world_mesh

    scene = Scene("block", ((-3, -3), (3, 3)),
                  landmarks=(Landmark((0.0, 0.0), shape="box", extent=(0.4, 1.0),
                                      height=1.0, color=(0.8, 0.8, 0.8, 1.0)),),
                  floor_color=(0.8, 0.8, 0.8, 1.0))
    config = CameraConfig(panorama_shape=(60, 360))
    light = Lighting(direction=(1.0, 0.0, 1.0))
    camera = (-2.0, 0.0, 0.0)

    def pixel(image, x, y):
        d = math.hypot(x - camera[0], y - camera[1])
        column = int(bearing_column(math.atan2(y - camera[1], x - camera[0]), 360))
        row = int((config.vfov / 2 + math.atan(0.3 / d)) / config.vfov * 60)
        return 255 * float(luminance(image[row:row + 1, column:column + 1])[0, 0])

    plain = RayCaster(world_mesh(scene)).panorama(camera, 0.3, config, light)
    shaded = RayCaster(world_mesh(scene), shadows=True).panorama(camera, 0.3, config, light)
    lit = 0.8 * (light.ambient + light.diffuse / math.sqrt(2)) * 255
    assert pixel(plain, -0.7, 0.0) == pytest.approx(lit, abs=3)
    assert pixel(shaded, -0.7, 0.0) == pytest.approx(0.8 * light.ambient * 255, abs=3)
    for x, y in ((-0.7, 1.5), (-1.4, 0.0), (-0.5, -1.2)):          # beside or beyond it
        assert pixel(shaded, x, y) == pytest.approx(pixel(plain, x, y), abs=1)
    with pytest.raises(ValueError, match="shadows needs renderer='raycast'"):
        make_env(renderer="tiny", shadows=True)


@pytest.mark.parametrize("float64_bytes", [0, 2**30])
def test_texture_samples_wrap_round_the_edges(monkeypatch, float64_bytes):
    """Bilinear samples on the edge of a texture blend in the texels of the opposite edge
    (the atlas stores each level with a wrapped border), in float32 and float64 atlases."""
    from homing_gym.render import raycast
    from homing_gym.render.column_cast import _texel

    monkeypatch.setattr(raycast, "ATLAS_FLOAT64_BYTES", float64_bytes)
    texture = np.arange(24, dtype=np.float32).reshape(2, 4, 3) / 24    # row 0 at the top
    atlas = raycast.texture_atlas([texture])
    assert atlas.atlas.dtype == (np.float64 if float64_bytes else np.float32)
    assert atlas.levels[:, 1:].tolist() == [[2, 4], [1, 2], [1, 1]]
    # v = 0.75: the centre of the top row; s = 0: halfway between the last and first columns
    np.testing.assert_allclose(_texel(atlas.atlas, atlas.levels, 0, 0.0, 0.75),
                               (texture[0, 3] + texture[0, 0]) / 2, rtol=1e-6)
    # v = 1: halfway between the bottom and top rows; s = 1/8: the centre of column 0
    np.testing.assert_allclose(_texel(atlas.atlas, atlas.levels, 0, 0.125, 1.0),
                               (texture[1, 0] + texture[0, 0]) / 2, rtol=1e-6)
    # a corner blends all four corners; whole turns away it is the same point
    corners = (texture[0, 0] + texture[0, 3] + texture[1, 0] + texture[1, 3]) / 4
    for s, v in [(0.0, 1.0), (3.0, -2.0), (-1.0, 5.0)]:
        np.testing.assert_allclose(_texel(atlas.atlas, atlas.levels, 0, s, v), corners,
                                   rtol=1e-6)


def test_a_float32_atlas_gives_the_pixels_of_a_float64_one(monkeypatch):
    """Worlds with large textures keep their atlas in float32 (half the memory): the
    same values, so the same pixels."""
    from homing_gym.render import raycast

    env = gym.make("homing_gym/LocalHoming-v0", scene="hallway")
    env.reset(seed=0)
    u = env.unwrapped
    caster, config = u.sim.caster, u.camera.config
    env.close()
    monkeypatch.setattr(raycast, "ATLAS_FLOAT64_BYTES", 0)
    small = RayCaster(caster.mesh, caster.sky, shadows=True)
    assert small._atlas.dtype == np.float32
    monkeypatch.undo()
    wide = RayCaster(caster.mesh, caster.sky, shadows=True)
    assert wide._atlas.dtype == np.float64
    for pose in [(0.3, 0.1, 0.4), (-1.0, 0.2, 2.5), (2.0, -0.1, -1.0)]:
        assert np.array_equal(small.panorama(pose, 0.3, config), wide.panorama(pose, 0.3, config))
        assert np.array_equal(small.perspective(pose, 0.3, 80, 60, 70.0),
                              wide.perspective(pose, 0.3, 80, 60, 70.0))
