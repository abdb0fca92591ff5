"""PyBullet's limits: meshes above its limit on one shape load (split into several), a
world above the face limit is refused with a clear error before PyBullet sees it, and
new worlds leave nothing behind in memory."""

import gc
import tracemalloc

import numpy as np
import pytest

from homing_gym.scenes import scene_factory
from homing_gym.scenes.mesh_scene import MeshScene
from homing_gym.sim.simulator import Simulator

WALL_X = 1.0


def wall_file(tmp_path, rows: int, columns: int) -> str:
    """A PLY of a wall at x = WALL_X, y in [-2, 2], z in [0, 0.3]: a grid of ``rows`` x
    ``columns`` squares, two triangles each."""
    import trimesh

    y, z = np.meshgrid(np.linspace(-2, 2, columns + 1), np.linspace(0, 0.3, rows + 1))
    vertices = np.column_stack([np.full(y.size, WALL_X), y.ravel(), z.ravel()])
    corner = (np.arange(rows)[:, None] * (columns + 1) + np.arange(columns)).ravel()
    a, b, c, d = corner, corner + 1, corner + columns + 1, corner + columns + 2
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([b, d, c])])
    path = tmp_path / "wall.ply"
    trimesh.Trimesh(vertices, faces, process=False).export(path)
    return str(path)


def test_a_mesh_above_pybullets_limit_on_one_shape_loads_and_blocks_the_robot(tmp_path):
    # 180,000 triangles: 540,000 indices, more than one PyBullet shape takes (524,288;
    # "Number of indices exceeds the maximum" before)
    scene = MeshScene.from_file(wall_file(tmp_path, 300, 300), fence=False,
                                bounds=((-1.5, -1.5), (0.8, 1.5)))
    assert sum(len(m.faces) for m in scene.meshes) == 180_000
    sim = Simulator(scene, renderer="tiny")     # TinyRenderer: visual shapes of it too
    try:
        for y in (-1.9, -0.7, 0.0, 0.9, 1.9):   # every part of the wall stops a ray ...
            for z in (0.03, 0.15, 0.29):
                hit = sim.ray_hit((0.5, y, z), (3.0, y, z))   # clear of the robot
                assert hit is not None and hit[0] == pytest.approx(WALL_X, abs=1e-6)
        radius = sim.robot.config.body_radius
        for y in (-1.5, 0.0, 1.5):               # ... and the robot touches it
            sim.place_robot((WALL_X - radius + 0.01, y, 0.0), clear_contacts=True)
            assert sim.step(1), f"no contact with the wall at y = {y}"
        sim.place_robot((0.0, 0.0, 0.0), clear_contacts=True)
        assert not sim.step(1)
    finally:
        sim.close()


@pytest.mark.parametrize("how", ["file", "arrays", "scene string"])
def test_a_world_above_the_face_limit_is_refused_before_pybullet(tmp_path, monkeypatch, how):
    from homing_gym.scenes import mesh_part
    monkeypatch.setattr(mesh_part, "MAX_WORLD_FACES", 1_000)
    path = wall_file(tmp_path, 10, 60)                      # 1,200 triangles
    make = {"file": lambda: MeshScene.from_file(path),
            "arrays": lambda: MeshScene.from_arrays(np.zeros((3, 3)),
                                                    np.zeros((1_200, 3), int)),
            "scene string": lambda: scene_factory(f"mesh:{path}").build(None)}[how]
    with pytest.raises(ValueError, match=r"1,200 triangles, more than the 1,000") as error:
        make()
    assert how == "arrays" or path in str(error.value)


def test_new_worlds_leave_no_python_objects_behind():
    # PyBullet keeps references to every list (and every corner list in it) that its mesh
    # shapes are given: fresh lists per world lost about 0.13 MiB a random_nature world
    factory = scene_factory("random_nature")
    rng = np.random.default_rng(0)
    sim = Simulator(factory.build(rng), renderer="tiny")
    tracemalloc.start()
    try:
        used = []
        for world in range(16):                 # 4 to warm up, then 12 measured
            sim.reset_world(factory.build(rng))
            if world in (3, 15):
                gc.collect()
                used.append(tracemalloc.get_traced_memory()[0])
    finally:
        tracemalloc.stop()
        sim.close()
    grown = used[1] - used[0]
    assert grown < 300_000, f"{grown / 2**20:.2f} MiB left behind by 12 worlds"


@pytest.mark.slow
def test_memory_stays_flat_over_300_procedural_worlds():
    from homing_gym.memory_check import memory_curve
    curve = memory_curve("random_nature", worlds=300, every=50, panorama_shape=(16, 64))
    growth = curve[-1][1] - curve[1][1]          # after 50 worlds of warm-up
    assert growth < 12, f"resident memory grew {growth:.1f} MiB over 250 worlds: {curve}"


@pytest.mark.parametrize("args, words", [
    (["--scene", "arena"], "not procedural"), (["--scene", "nowhere"], "--scene"),
    (["--worlds", "0"], "--worlds"), (["--every", "500", "--worlds", "100"], "--every")])
def test_memory_check_refuses_bad_arguments_in_one_line(capsys, args, words):
    from homing_gym.memory_check import main
    with pytest.raises(SystemExit) as exit_:
        main(args)
    error = capsys.readouterr().err
    assert exit_.value.code == 2 and words in error and "Traceback" not in error
