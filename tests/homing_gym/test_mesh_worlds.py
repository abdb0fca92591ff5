"""Mesh worlds: MeshScene from files and arrays, "mesh:PATH", clearance from the mesh cut
at the robot's height, collisions, the fence, both renderers, the oracle, bad input."""

import math

import numpy as np
import pytest
import trimesh

from homing_gym.scenes import MeshScene, scene_factory
from homing_gym.scenes.base import clearance, clearances
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.mesh_example import (LEG_HALF, PILLAR, example_room_parts,
                                            write_example_room)
from homing_gym.render.topdown import BG, MapCanvas, draw_scene
from homing_train.harness.rollout import rollout


@pytest.fixture(scope="module")
def room_files(tmp_path_factory):
    """The example room as one OBJ, one PLY and a GLB with a node per part."""
    folder = tmp_path_factory.mktemp("room")
    for name in ("room.obj", "room.ply", "room.glb"):
        write_example_room(folder / name)
    return folder


@pytest.mark.parametrize("name", ["room.obj", "room.ply", "room.glb"])
def test_mesh_file_bounds_and_clearance_match_the_geometry(room_files, name):
    scene = MeshScene.from_file(room_files / name)
    np.testing.assert_allclose(np.array(scene.bounds), [[-3.15, -2.15], [3.15, 2.15]], atol=1e-5)
    assert scene.fence and scene.name == name
    # true free distances: to the pillar, to a wall, to the table legs; under the table
    # top (above the robot) is free, inside the pillar is blocked
    cases = {(0.0, -0.5): 1.0 - PILLAR[2], (2.8, -1.0): 0.2, (-1.0, 0.0): 0.5 - PILLAR[2],
             (1.4, 0.8): math.hypot(0.4, 0.3) - LEG_HALF * math.sqrt(2)}
    got = clearances(scene, list(cases))
    for (point, truth), value in zip(cases.items(), got):
        assert truth - 0.045 <= value <= truth + 1e-9, (point, truth, value)
    assert clearance(scene, PILLAR[:2]) == 0.0
    assert clearance(scene, (1.4, 0.8)) > 0.3          # the table top does not block


def test_each_live_mesh_scene_builds_its_clearance_field_once(monkeypatch):
    """Many mesh worlds in use at once (64 envs in one process): each world's field is
    built at its first use and kept while its scene lives, then freed with it."""
    import gc

    from homing_gym.scenes import base, footprint

    built = []
    monkeypatch.setattr(base, "clearance_field",
                        lambda *a: built.append(a) or footprint.clearance_field(*a))
    box = trimesh.creation.box((0.4, 0.4, 0.5))
    scenes = [MeshScene.from_arrays(box.vertices + (0.02 * k, 0.0, 0.25), box.faces,
                                    bounds=((-3, -3), (3, 3))) for k in range(40)]
    for _ in range(3):
        for k, scene in enumerate(scenes):       # the box's face at x = 0.2 + 0.02 k
            assert clearance(scene, (1.5, 0.0)) == pytest.approx(1.3 - 0.02 * k, abs=0.045)
    assert len(built) == 40
    del scenes, scene
    gc.collect()
    assert len(base._mesh_field.cache) == 0


def test_glb_parts_keep_their_names_and_colours(room_files):
    scene = MeshScene.from_file(room_files / "room.glb", no_collision=("pillar",))
    parts = {p.name: p for p in scene.meshes}
    assert set(parts) == set(example_room_parts())
    np.testing.assert_allclose(parts["pillar"].face_colors[0], np.array([20, 60, 200]) / 255)
    assert not parts["pillar"].collision and parts["north"].collision
    assert clearance(scene, PILLAR[:2]) > 0.5            # passable when it does not collide
    with pytest.raises(ValueError, match="not parts of"):
        MeshScene.from_file(room_files / "room.glb", no_collision=("sofa",))


def test_mesh_spec_options_scale_and_up_axis(room_files, tmp_path):
    joined = trimesh.util.concatenate(list(example_room_parts().values()))
    y_up = joined.copy()
    y_up.apply_transform(trimesh.transformations.rotation_matrix(-math.pi / 2, (1, 0, 0)))
    y_up.apply_scale(100.0)                                  # centimetres, y up
    y_up.export(tmp_path / "room_cm_yup.ply")
    scene = scene_factory(f"mesh:{tmp_path / 'room_cm_yup.ply'}?scale=0.01&up=y").build(None)
    np.testing.assert_allclose(np.array(scene.bounds), [[-3.15, -2.15], [3.15, 2.15]], atol=1e-5)
    assert clearance(scene, PILLAR[:2]) == 0.0
    same = scene_factory(f"mesh:{room_files / 'room.obj'}?fence=0").build(None)
    assert same is scene_factory(f"mesh:{room_files / 'room.obj'}?fence=0").build(None)
    assert not same.fence


def test_robot_bumps_into_mesh_walls_and_renderers_show_the_mesh(room_files, make_env):
    for renderer in ("raycast", "tiny"):
        env = make_env(scene=f"mesh:{room_files / 'room.glb'}", renderer=renderer,
                       render_mode="rgb_array", max_episode_steps=200)
        # facing the pillar from 0.8 m: it fills the panorama's middle columns in blue
        obs, _ = env.reset(seed=0, options={"start": (-1.0, 0.5, -math.pi / 2),
                                            "home": (0.0, 0.0, 0.0)})
        pano = obs["panorama"].astype(int)
        width = pano.shape[1]
        blue = (pano[..., 2] > pano[..., 0] + 60) & (pano[..., 2] > pano[..., 1] + 40)
        columns = np.flatnonzero(blue.any(axis=0))
        half = math.degrees(math.asin(PILLAR[2] / 1.0)) * width / 360
        assert abs(columns.mean() - width / 2) < 2 and abs(len(columns) / 2 - half) < 3
        frame = env.render()
        assert frame.shape[2] == 3
        collisions = 0
        for _ in range(60):                      # drive straight into the pillar
            _, _, _, _, info = env.step(np.array([1.0, 0.0], np.float32))
            collisions += info["collision"]
        assert collisions > 0
        assert math.dist(info["pose"][:2], PILLAR[:2]) > PILLAR[2] + 0.15


def test_fence_keeps_the_robot_inside_a_world_without_walls(make_env):
    pole = trimesh.creation.cylinder(radius=0.1, height=1.0)
    pole.apply_translation((0, 0, 0.5))
    scene = MeshScene.from_arrays(pole.vertices, pole.faces, bounds=((-1.5, -1.0), (1.5, 1.0)))
    env = make_env(scene=scene, renderer="raycast", max_episode_steps=-1)
    env.reset(seed=0, options={"start": (1.0, 0.0, 0.0), "home": (-1.0, 0.0, 0.0)})
    for _ in range(80):
        _, _, _, _, info = env.step(np.array([1.0, 0.0], np.float32))
    assert info["pose"][0] < 1.5 and info["collisions"] > 0


def test_oracle_homes_around_mesh_obstacles(room_files, make_env, controller_for):
    env = make_env(scene=f"mesh:{room_files / 'room.glb'}", renderer="raycast",
                   success_on="stop", max_episode_steps=400)
    oracle = controller_for("oracle", env)
    # the pillar stands between start and home
    result = rollout(env, oracle, seed=0, options={"start": (-1.0, -1.6, 0.0),
                                                   "home": (-1.0, 0.6, 0.0)})
    assert result.info["is_success"], result.info["distance_to_goal"]
    assert np.min(np.hypot(*(result.poses[:, :2] - PILLAR[:2]).T)) > PILLAR[2] + 0.15


def test_top_down_map_draws_the_mesh_footprint(room_files):
    scene = MeshScene.from_file(room_files / "room.glb")
    canvas = MapCanvas(scene, 300)
    img = draw_scene(scene, canvas)
    x, y = canvas.px(PILLAR[0] + PILLAR[2], PILLAR[1])
    near = img[y - 2:y + 3, x - 2:x + 3].reshape(-1, 3)
    assert np.any(np.all(near == (20, 60, 200), axis=1))     # the pillar's outline in blue
    assert np.all(img[canvas.px(0, 0)[::-1]] == BG)          # open floor stays empty


def test_bad_mesh_input_is_a_clear_error(tmp_path, room_files, make_env):
    with pytest.raises(ValueError, match="does not exist"):
        scene_factory(f"mesh:{tmp_path / 'nowhere.obj'}")
    empty = tmp_path / "empty.obj"
    empty.write_text("")
    with pytest.raises(ValueError, match="empty.obj"):
        MeshScene.from_file(empty)
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"glTF not really")
    with pytest.raises(ValueError, match="broken.glb"):
        MeshScene.from_file(broken)
    points = tmp_path / "points.ply"
    trimesh.PointCloud(np.random.default_rng(0).random((20, 3))).export(points)
    with pytest.raises(ValueError, match="no triangles"):
        MeshScene.from_file(points)
    tri = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1.0]])
    with pytest.raises(ValueError, match="NaN"):
        MeshScene.from_arrays(np.where(tri == 1, np.nan, tri), [[0, 1, 2]])
    with pytest.raises(ValueError, match="no faces"):
        MeshScene.from_arrays(tri, np.zeros((0, 3), int))
    with pytest.raises(ValueError, match="face indices"):
        MeshScene.from_arrays(tri, [[0, 1, 5]])
    uvs, texel = np.zeros((3, 2)), np.zeros((1, 1, 3), np.uint8)
    with pytest.raises(ValueError, match="uvs must be finite"):
        MeshPart(tri, [[0, 1, 2]], [[1, 1, 1]], np.full((3, 2), np.nan), texel)
    with pytest.raises(ValueError, match=r"H, W >= 1, got uint8 \(0, 4, 3\)"):
        MeshPart(tri, [[0, 1, 2]], [[1, 1, 1]], uvs, np.zeros((0, 4, 3), np.uint8))
    assert MeshPart(tri, [[0, 1, 2]], [[1, 1, 1]], uvs, texel).texture.shape == (1, 1, 3)
    with pytest.raises(ValueError, match="unknown option 'size'"):
        scene_factory(f"mesh:{room_files / 'room.obj'}?size=2")
    with pytest.raises(ValueError, match="up axis"):
        scene_factory(f"mesh:{room_files / 'room.obj'}?up=x")
    with pytest.raises(ValueError, match="scale"):
        MeshScene.from_file(room_files / "room.obj", scale=-1.0)
    with pytest.raises(ValueError, match="no triangle lies at the robot's height"):
        MeshScene.from_arrays(tri + [0, 0, 5.0], [[0, 1, 2]])   # all of it 5 m up
    block = trimesh.creation.box(extents=(4, 4, 1))
    block.apply_translation((0, 0, 0.5))
    solid = MeshScene.from_arrays(block.vertices, block.faces,
                                  bounds=((-1.0, -1.0), (1.0, 1.0)))
    with pytest.raises(ValueError, match="no free space for the robot"):
        make_env(scene=solid)


def test_textured_mesh_shows_its_texture_in_the_ray_caster(tmp_path, make_env):
    """A wall panel whose texture is red on its left half and green on its right: seen
    face on from 1 m, red fills the panorama columns left of straight ahead."""
    from PIL import Image

    image = np.zeros((8, 8, 3), np.uint8)
    image[:, :4] = (220, 20, 20)
    image[:, 4:] = (20, 200, 20)
    # a 1 x 0.6 m panel in the plane x = 1, from y = 0.5 (u = 0) to y = -0.5 (u = 1)
    vertices = [(1, 0.5, 0.0), (1, -0.5, 0.0), (1, -0.5, 0.6), (1, 0.5, 0.6)]
    uv = [(0, 0), (1, 0), (1, 1), (0, 1)]
    visual = trimesh.visual.TextureVisuals(uv=uv, image=Image.fromarray(image))
    panel = trimesh.Trimesh(vertices, [(0, 1, 2), (0, 2, 3)], process=False, visual=visual)
    panel.export(tmp_path / "panel.glb")
    scene = MeshScene.from_file(tmp_path / "panel.glb", bounds=((-1.5, -1.5), (1.5, 1.5)))
    assert scene.meshes[0].texture is not None
    env = make_env(scene=scene, renderer="raycast")
    obs, _ = env.reset(seed=0, options={"start": (0.0, 0.0, 0.0), "home": (-1.0, 0.0, 0.0)})
    row = obs["panorama"][obs["panorama"].shape[0] // 2 - 2].astype(int)
    middle = row.shape[0] // 2
    left, right = row[middle - 10:middle - 2], row[middle + 2:middle + 10]
    assert np.all(left[:, 0] > left[:, 1] + 80)         # red left of the heading
    assert np.all(right[:, 1] > right[:, 0] + 80)       # green right of it


def test_benchmark_mesh_world_has_ten_thousand_triangles(make_env):
    from homing_gym.benchmark import mesh_world
    from homing_gym.render.worldmesh import world_mesh

    scene = mesh_world()
    assert len(world_mesh(scene).triangles) > 9_500
    env = make_env(scene=scene, renderer="raycast", max_episode_steps=20)
    env.reset(seed=0)
    for _ in range(20):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
    assert truncated and not terminated


def test_homing_eval_takes_a_mesh_scene_in_worker_processes(room_files, tmp_path):
    import json

    from homing_train.harness import eval_command

    out = tmp_path / "oracle.json"
    kwargs = {"scene": f"mesh:{room_files / 'room.glb'}", "success_on": "stop",
              "max_episode_steps": 300}
    assert eval_command.main(["--policy", "oracle", "--episodes", "2", "--workers", "2",
                              "--env-kwargs", json.dumps(kwargs), "--out", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["env_kwargs"]["scene"] == kwargs["scene"]
    assert doc["summary"]["episodes"] == 2 and doc["summary"]["success_rate"] == 1.0
