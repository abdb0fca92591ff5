"""Mesh files as real projects write them: several materials, colours from materials
(glTF baseColorFactor, OBJ Kd), vertex colours beside a material, textures without UVs,
broken texture coordinates; every "mesh:PATH?..." option and its bad values; the
third-party worlds in ../shared/worlds (slow)."""

import base64
import io
import json
import os
import time
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from homing_gym.scenes import MeshScene, scene_factory
from homing_gym.scenes.base import HEIGHT_BAND, clearance
from homing_gym.scenes.mesh_example import PILLAR, write_example_room
from homing_gym.scenes.mesh_scene import (SPEC_OPTIONS, MeshOptions, _cached_scene,
                                          parse_mesh_spec)

BOUNDS = ((-3.0, -3.0), (3.0, 3.0))
GREEN = (30, 200, 30)


@pytest.fixture(autouse=True)
def forget_scene_strings():
    """Scenes read from "mesh:" strings stay cached in the process: none outlives its test
    here (other tests count the live mesh scenes)."""
    yield
    _cached_scene.cache_clear()


def _box(centre=(0.0, 0.0)) -> trimesh.Trimesh:
    box = trimesh.creation.box((1.0, 1.0, 1.0))
    box.apply_translation((*centre, 0.5))
    return box


def _pbr(mesh: trimesh.Trimesh, **material) -> trimesh.Trimesh:
    mesh.visual = trimesh.visual.TextureVisuals(
        material=trimesh.visual.material.PBRMaterial(**material))
    return mesh


def _colors(scene: MeshScene) -> dict[str, np.ndarray]:
    """Each part's face colours in 0-255 (all its faces must share one)."""
    out = {}
    for part in scene.meshes:
        assert np.ptp(part.face_colors, axis=0).max() < 1e-9, part.name
        out[part.name] = np.round(part.face_colors[0] * 255)
    return out


def _write_obj(folder: Path, name: str, materials: dict[str, str], *, uvs: bool) -> Path:
    """An OBJ of two boxes (12 and 12 faces), one per material of ``materials``
    (name: MTL lines), with or without ``vt`` texture coordinates."""
    lines = [f"mtllib {name}.mtl"]
    for k, material in enumerate(materials):
        box = _box((2.0 * k, 0.0))
        lines += [f"v {x} {y} {z}" for x, y, z in box.vertices]
        if uvs:
            lines += [f"vt {u % 1:.3f} {u // 1 / 8:.3f}" for u in np.arange(8) * 0.37]
        lines.append(f"usemtl {material}")
        base = 8 * k + 1
        lines += ["f " + " ".join(f"{base + i}/{base + i}" if uvs else f"{base + i}"
                                  for i in face) for face in box.faces]
    (folder / f"{name}.mtl").write_text(
        "".join(f"newmtl {m}\n{body}\n" for m, body in materials.items()))
    path = folder / f"{name}.obj"
    path.write_text("\n".join(lines) + "\n")
    return path


def _buffer(array: np.ndarray) -> dict:
    """A glTF buffer holding ``array``, inline."""
    return {"byteLength": array.nbytes, "uri": "data:application/gltf-buffer;base64,"
            + base64.b64encode(array.tobytes()).decode()}


def _write_gltf(path: Path, *, colors=None, uvs=None, material=None) -> Path:
    """A glTF with one part "wall" (a 1 x 1 m square at x = 1, 4 vertices): per-vertex
    ``colors`` (RGBA floats, any count), ``uvs`` (any count) and ``material`` (a glTF
    material; ``"texture"`` in it is replaced by a green PNG) as given."""
    positions = np.array([[1, -0.5, 0], [1, 0.5, 0], [1, 0.5, 1], [1, -0.5, 1]], np.float32)
    arrays = {"POSITION": positions}
    if colors is not None:
        arrays["COLOR_0"] = np.asarray(colors, np.float32)
    if uvs is not None:
        arrays["TEXCOORD_0"] = np.asarray(uvs, np.float32)
    indices = np.array([0, 1, 2, 0, 2, 3], np.uint32)
    accessors = [{"bufferView": 0, "componentType": 5125, "count": 6, "type": "SCALAR"}]
    buffers = [_buffer(indices)]
    attributes = {}
    for k, (name, array) in enumerate(arrays.items(), start=1):
        attributes[name] = k
        buffers.append(_buffer(array))
        accessor = {"bufferView": k, "componentType": 5126, "count": len(array),
                    "type": f"VEC{array.shape[1]}"}
        if name == "POSITION":
            accessor |= {"min": array.min(axis=0).tolist(), "max": array.max(axis=0).tolist()}
        accessors.append(accessor)
    primitive = {"attributes": attributes, "indices": 0}
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0, "name": "wall"}],
           "meshes": [{"name": "wall", "primitives": [primitive]}],
           "buffers": buffers, "accessors": accessors,
           "bufferViews": [{"buffer": k, "byteLength": b["byteLength"]}
                           for k, b in enumerate(buffers)]}
    if material is not None:
        primitive["material"] = 0
        pbr = dict(material)
        if pbr.pop("texture", None):
            png = io.BytesIO()
            Image.fromarray(np.full((4, 4, 3), GREEN, np.uint8)).save(png, format="PNG")
            doc["images"] = [{"uri": "data:image/png;base64,"
                                     + base64.b64encode(png.getvalue()).decode()}]
            doc["textures"] = [{"source": 0}]
            pbr["baseColorTexture"] = {"index": 0}
        doc["materials"] = [{"pbrMetallicRoughness": pbr}]
    path.write_text(json.dumps(doc))
    return path


def test_multi_material_glb_parts_take_their_base_color(tmp_path, make_env):
    """glTF materials with a baseColorFactor and no texture (as the office and outdoor
    worlds have), on parts of different sizes; the ray caster shows them."""
    sphere = trimesh.creation.icosphere(2, radius=0.4)           # 320 faces, 162 vertices
    sphere.apply_translation((0.0, 1.5, 0.5))
    trimesh.Scene({"red": _pbr(_box((1.5, 0.0)), baseColorFactor=[230, 20, 20, 255]),
                   "blue": _pbr(sphere, baseColorFactor=[20, 20, 230, 255])}
                  ).export(tmp_path / "two.glb")
    scene = MeshScene.from_file(tmp_path / "two.glb", bounds=BOUNDS)
    colors = _colors(scene)
    np.testing.assert_array_equal(colors["red"], (230, 20, 20))
    np.testing.assert_array_equal(colors["blue"], (20, 20, 230))
    env = make_env(scene=scene, renderer="raycast")
    obs, _ = env.reset(seed=0, options={"start": (0.0, 0.0, 0.0), "home": (-1.5, 0.0, 0.0)})
    row = obs["panorama"][obs["panorama"].shape[0] // 2 + 4].astype(int)
    ahead = row[row.shape[0] // 2 - 2:row.shape[0] // 2 + 3]
    assert np.all(ahead[:, 0] > ahead[:, 2] + 60)                  # the red box ahead


@pytest.mark.parametrize("uvs", [True, False], ids=["with_vt", "without_vt"])
def test_obj_materials_take_their_kd(tmp_path, uvs):
    """OBJ materials with a diffuse colour Kd and no texture map (as the monastery)."""
    path = _write_obj(tmp_path, "kd", {"brick": "Kd 0.8 0.2 0.1", "slate": "Kd 0.2 0.3 0.6"},
                      uvs=uvs)
    colors = _colors(MeshScene.from_file(path, bounds=BOUNDS))
    np.testing.assert_allclose(colors["brick"], (204, 51, 26), atol=1)
    np.testing.assert_allclose(colors["slate"], (51, 77, 153), atol=1)


def test_textures_without_uvs_show_their_mean_colour(tmp_path):
    Image.fromarray(np.full((4, 4, 3), GREEN, np.uint8)).save(tmp_path / "green.png")
    obj = _write_obj(tmp_path, "tex", {"grass": "Kd 1 1 1\nmap_Kd green.png"}, uvs=False)
    _pbr(_box(), baseColorTexture=Image.open(tmp_path / "green.png")).export(tmp_path / "t.glb")
    for path in (obj, tmp_path / "t.glb"):
        scene = MeshScene.from_file(path, bounds=BOUNDS)
        assert all(p.texture is None for p in scene.meshes)
        for color in _colors(scene).values():
            np.testing.assert_array_equal(color, GREEN)


def test_glb_vertex_colours_beside_a_material(tmp_path):
    """COLOR_0 with a plain material: each face takes its corners' colours."""
    red_green = [[1, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1], [0, 1, 0, 1]]
    path = _write_gltf(tmp_path / "wall.gltf", colors=red_green,
                       material={"baseColorFactor": [1, 1, 1, 1]})
    (part,) = MeshScene.from_file(path, bounds=BOUNDS).meshes
    np.testing.assert_allclose(part.face_colors, [[2 / 3, 1 / 3, 0], [1 / 3, 2 / 3, 0]],
                               atol=1e-9)


def test_bad_texture_coordinates_are_a_clear_error(tmp_path):
    """A texture with 3 texture coordinates for 4 vertices: the file and the part are
    named (trimesh passes such coordinates on)."""
    path = _write_gltf(tmp_path / "wall.gltf", uvs=[[0, 0], [1, 0], [1, 1]],
                       material={"texture": True})
    with pytest.raises(ValueError, match=r"wall\.gltf.*part 'wall'.*texture coordinates.*"
                                         r"\(3, 2\) for 4 vertices"):
        MeshScene.from_file(path, bounds=BOUNDS)
    good = _write_gltf(tmp_path / "good.gltf", uvs=[[0, 0], [1, 0], [1, 1], [0, 1]],
                       material={"texture": True})
    (part,) = MeshScene.from_file(good, bounds=BOUNDS).meshes
    assert part.texture.shape == (4, 4, 3) and np.all(part.texture == GREEN)


@pytest.fixture(scope="module")
def room(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("room") / "room.glb"
    write_example_room(path)
    return path


# every option: its text in a scene string and the value MeshOptions keeps
OPTION_TEXTS = {
    "scale": ("0.5", 0.5), "up": ("y", "y"), "offset": ("1,2,3", (1.0, 2.0, 3.0)),
    "bounds": ("-1,-2,3,4", ((-1.0, -2.0), (3.0, 4.0))), "fence": ("0", False),
    "ground_plane": ("false", False), "ground_color": ("0.1,0.2,0.3", (0.1, 0.2, 0.3, 1.0)),
    "sky_color": ("0.5,0.6,1", (0.5, 0.6, 1.0)), "height_band": ("0.05,0.5", (0.05, 0.5)),
    "collision": ("0", False), "no_collision": ("pillar,top", ("pillar", "top")),
}


def test_every_mesh_option_can_be_given_in_a_scene_string():
    assert set(OPTION_TEXTS) == set(SPEC_OPTIONS) == set(MeshOptions.__dataclass_fields__)
    for key, (text, value) in OPTION_TEXTS.items():
        path, options = parse_mesh_spec(f"mesh:a b/room.glb?{key}={text}")
        assert path == "a b/room.glb" and getattr(options, key) == value, key
        assert options == MeshOptions(**{key: value})


def test_scene_string_options_reach_the_scene(room):
    spec = (f"mesh:{room}?no_collision=pillar&ground_color=0.1,0.2,0.3&sky_color=0.5,0.6,1"
            f"&height_band=0.05,0.5")
    scene = scene_factory(spec).build(None)
    assert scene is scene_factory(spec).build(None)              # read once, cached
    parts = {p.name: p for p in scene.meshes}
    assert not parts["pillar"].collision and parts["north"].collision
    assert clearance(scene, PILLAR[:2]) > 0.5
    assert scene.floor_color == (0.1, 0.2, 0.3, 1.0) and scene.sky_color == (0.5, 0.6, 1.0)
    assert scene.height_band == (0.05, 0.5) != HEIGHT_BAND
    passable = scene_factory(f"mesh:{room}?collision=0&bounds=-3,-2,3,2").build(None)
    assert not any(p.collision for p in passable.meshes)
    assert clearance(passable, PILLAR[:2]) > 1.0


@pytest.mark.parametrize("query, words", [
    ("scal=2", ["unknown option 'scal'", "did you mean 'scale'", "height_band, collision"]),
    ("scale=1&scale=2", ["'scale' is given twice"]),
    ("&&", ["empty option", "key=value joined by '&'"]),
    ("=2", ["'=2' has no name"]),
    ("fence", ["'fence' has no value", "fence=VALUE"]),
    ("scale=abc", ["bad scale='abc'", "expected a number"]),
    ("scale=0", ["scale must be a positive number", "got 0.0"]),
    ("up=x", ["up must be", "('z', 'y')", "'x'"]),
    ("offset=1,2", ["bad offset='1,2'", "expected 3"]),
    ("offset=1e999,0,0", ["offset must be three finite numbers", "inf"]),
    ("bounds=0,0,-1,1", ["bounds must be", "xmin < xmax"]),
    ("fence=yes", ["bad fence='yes'", "0, 1, true or false"]),
    ("collision=2", ["bad collision='2'", "0, 1, true or false"]),
    ("ground_color=1,0", ["bad ground_color='1,0'", "3 or 4"]),
    ("ground_color=1.5,0,0", ["ground_color must be", "[0, 1]", "1.5"]),
    ("sky_color=0,0,0,1", ["bad sky_color", "expected 3"]),
    ("sky_color=0,-0.1,0", ["sky_color must be", "[0, 1]", "-0.1"]),
    ("height_band=0.3,0.1", ["height_band must be", "low < high", "(0.3, 0.1)"]),
    ("height_band=0.1,inf", ["height_band must be", "finite", "inf"]),
    ("height_band=nan,0.3", ["height_band must be", "nan"]),
    ("no_collision=a,,b", ["bad no_collision='a,,b'", "none empty"]),
])
def test_bad_scene_string_options_are_named(room, query, words):
    with pytest.raises(ValueError) as error:
        scene_factory(f"mesh:{room}?{query}")
    assert f"mesh:{room}?{query}" in str(error.value)
    for word in words:
        assert word in str(error.value)


def test_bad_mesh_options_in_python_are_named(room, tmp_path):
    for options, words in [({"no_collision": "pillar"}, ["no_collision", "list or tuple"]),
                           ({"fence": 1}, ["fence must be True or False"]),
                           ({"sacle": 2}, ["unknown option 'sacle'", "'scale'"]),
                           ({"no_collision": ("sofa",)}, ["['sofa'] are not parts", "pillar"]),
                           ({"ground_color": (0, 0, 0, 0, 1)}, ["ground_color", "3 or 4"])]:
        with pytest.raises(ValueError) as error:
            MeshScene.from_file(room, **options)
        for word in words:
            assert word in str(error.value), (options, str(error.value))
    with pytest.raises(ValueError, match="is a directory, not a mesh file"):
        scene_factory(f"mesh:{tmp_path}")
    with pytest.raises(ValueError, match="is a directory, not a mesh file"):
        MeshScene.from_file(tmp_path)


# the third-party validation worlds as docs/scenes.md gives them: scene string, triangles
WORLDS = Path(__file__).resolve().parents[2] / ".." / "shared" / "worlds"
REAL_WORLDS = {
    "cpr_inspection_outdoor": (
        "cpr_inspection_outdoor/inspection_world.glb?up=z&bounds=-18,-7.5,24,30", 5_767),
    "willowgarage_office": (
        "willowgarage_office/willowgarage_visual.glb?scale=0.0254&up=z", 13_839),
    "samurai_monastery": ("samurai_monastry.obj?up=y&bounds=-10.8,-9.6,10.8,9.7", 124_789),
}


@pytest.mark.slow
@pytest.mark.parametrize("world", sorted(REAL_WORLDS))
def test_third_party_worlds_load_and_reset(world, make_env):
    import pybullet_data

    tail, triangles = REAL_WORLDS[world]
    folder = Path(pybullet_data.getDataPath()) if world == "samurai_monastery" else WORLDS
    if not (folder / tail.partition("?")[0]).is_file():
        pytest.skip(f"{folder / tail.partition('?')[0]} is not here")
    start = time.perf_counter()
    env = make_env(scene=f"mesh:{os.path.join(folder, tail)}", renderer="raycast")
    obs, info = env.reset(seed=0)
    assert time.perf_counter() - start < 60
    scene = env.unwrapped.scene
    assert sum(len(p.faces) for p in scene.meshes) == triangles
    assert obs["panorama"].std() > 5                  # a picture, not one flat colour
    if world == "willowgarage_office":                # its materials' colours, not grey
        colors = np.concatenate([p.face_colors for p in scene.meshes])
        assert np.ptp(colors, axis=1).max() > 0.2
