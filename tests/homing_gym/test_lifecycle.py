"""close() frees the PyBullet client; repeated make/close does not leak."""

import pytest
import gc

import gymnasium as gym
import numpy as np
import psutil
import pybullet as p


def test_close_disconnects_and_is_idempotent():
    env = gym.make("homing_gym/LocalHoming-v0")
    env.reset(seed=0)
    client_id = env.unwrapped.sim.client._client
    assert p.isConnected(physicsClientId=client_id)
    env.close()
    assert not p.isConnected(physicsClientId=client_id)
    env.close()


@pytest.mark.slow
def test_200_make_close_cycles_leak_nothing():
    rss = psutil.Process().memory_info().rss
    clients = []
    for i in range(220):
        env = gym.make("homing_gym/LocalHoming-v0", panorama_shape=(16, 64))
        env.reset(seed=i)
        env.step(np.zeros(2, np.float32))
        clients.append(env.unwrapped.sim.client._client)
        env.close()
        if i == 19:                       # allocator warm-up, then measure 200 cycles
            gc.collect()
            rss = psutil.Process().memory_info().rss
    gc.collect()
    growth_mb = (psutil.Process().memory_info().rss - rss) / 2**20
    assert not any(p.isConnected(physicsClientId=c) for c in set(clients))
    assert growth_mb < 8, f"memory grew by {growth_mb:.1f} MB over 200 make/close cycles"


def test_a_mesh_shape_gets_only_the_corners_its_faces_use():
    # PyBullet never releases the vertex lists it is given: pass no unused corner
    from homing_gym.sim.simulator import _used_vertices
    vertices = np.arange(30, dtype=np.float64).reshape(10, 3)
    faces = np.array([[7, 2, 9], [9, 2, 4]])
    corners, indices = _used_vertices(vertices, faces)
    assert len(corners) == 4                                   # 2, 4, 7, 9
    triangles = np.asarray(corners)[np.reshape(indices, (-1, 3))]
    assert np.array_equal(triangles, vertices[faces])         # the same triangles, in order



@pytest.mark.parametrize("copier", ["deepcopy", "copy", "pickle"])
def test_an_env_refuses_to_be_copied_rather_than_share_its_world(copier):
    import copy
    import pickle
    env = gym.make("homing_gym/LocalHoming-v0", panorama_shape=(16, 64))
    env.reset(seed=0)
    copy_of = {"deepcopy": copy.deepcopy, "copy": lambda e: copy.copy(e.unwrapped),
               "pickle": pickle.dumps}[copier]
    with pytest.raises(TypeError, match="cannot be copied or pickled.*gym.make\\(env.spec\\)"):
        copy_of(env)
    env.step(np.zeros(2, np.float32))          # the original still has its world
    again = gym.make(env.spec)                 # what the message says works
    again.reset(seed=0)
    again.close()
    env.close()
