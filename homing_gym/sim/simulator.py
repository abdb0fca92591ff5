"""The PyBullet world of one env: its own client, the scene bodies, the robot, state resets.

Every env owns one :class:`Simulator`, and every call goes through its
``pybullet_utils.bullet_client.BulletClient``, so several envs in one process never share
state. The world is built once; :meth:`Simulator.reset_world` restores a saved snapshot
(``saveState``/``restoreState``) instead of reloading URDFs. Only a randomised scene that
changes its landmarks rebuilds those primitive bodies (no URDF loading).

Physics: ``time_step`` (the env's default 1/120 s) per ``stepSimulation``; the env runs
``substeps`` of them per control period.
"""

from __future__ import annotations

import contextlib
import functools
import os
import pkgutil
import sys
import tempfile
import threading
import warnings
from collections.abc import Iterator

import numpy as np
import pybullet as p
from pybullet_utils.bullet_client import BulletClient

from homing_gym.native_output import native_output_captured
from homing_gym.render.raycast import SKY_COLOR, RayCaster
from homing_gym.sim.kinematic import KinematicRobot
from homing_gym.sim.robot import Robot, RobotConfig
from homing_gym.scenes.base import Scene
from homing_gym.scenes.footprint import band_faces
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.solids import (Solid, fence_solids, floor_rectangle, floor_top,
                                      landmark_solid, wall_solid)
from homing_gym.scenes.textures import texture_path
from homing_gym.render.worldmesh import world_mesh

#: ``createMultiBody`` options of every static body (floor, walls, landmarks, mesh
#: parts): a PyBullet rigid body rather than a fixed-base multibody, which the solver
#: visits at every physics step (about 0.3 us a body a step: 28 against 18 us a step
#: with 40 trees). Contacts and trajectories are bit for bit the same (checked on every
#: built-in scene, both drives and 10,000-triangle worlds).
_STATIC = {"useMaximalCoordinates": True}
#: PyBullet's limits on one mesh shape given as arrays: corners and indices
#: (``B3_MAX_NUM_VERTICES``, ``B3_MAX_NUM_INDICES`` in its ``SharedMemoryPublic.h``; a
#: macOS build's are 8,192 and 32,768). A larger one fails with "Number of indices
#: exceeds the maximum".
MAX_SHAPE_VERTICES, MAX_SHAPE_INDICES = ((8_192, 32_768) if sys.platform == "darwin"
                                         else (131_072, 524_288))
#: Triangles of one PyBullet mesh shape: that many use at most three times as many
#: corners and indices, within both limits (43,690; 2,730 on macOS). A mesh part with
#: more is split into several shapes (:func:`_face_chunks`).
MAX_SHAPE_FACES = min(MAX_SHAPE_VERTICES, MAX_SHAPE_INDICES) // 3


class Simulator:
    """One PyBullet client holding a scene and the robot."""

    def __init__(self, scene: Scene, *, gui: bool = False, time_step: float = 1 / 120,
                 robot_config: RobotConfig = RobotConfig(), renderer: str = "raycast",
                 sky_color: tuple[float, float, float] | None = None,
                 shadows: bool | None = None,
                 motion: str = "pybullet"):
        with native_output_captured():    # the C++ core prints "argv[0]=" on connecting
            self.client = BulletClient(connection_mode=p.GUI if gui else p.DIRECT)
        self._connected = True
        c = self.client
        # the EGL plugin only sees bodies created after it is loaded: load it first
        self.renderer = load_egl(c) if renderer == "egl" else p.ER_TINY_RENDERER
        self._sky_color = sky_color
        #: The ray caster of the current world (``renderer="raycast"``), else None.
        self._shadows = shadows
        self.caster = (world_caster(scene, sky_color, shadows)
                       if renderer == "raycast" else None)
        self.time_step = time_step
        self._vertices, self._vertices_of = np.zeros((0, 3)), None   # world_vertices' cache
        self._gui = gui
        #: Whether PyBullet draws the world (its renderers, or the GUI): only then do the
        #: bodies get visual shapes, colours and textures (the ray caster draws its own).
        self._drawn = self.caster is None or gui
        self._robot_config = robot_config
        #: ``"pybullet"``: the URDF robot in PyBullet's physics; ``"kinematic"``: a
        #: :class:`~homing_gym.sim.kinematic.KinematicRobot` (the world's bodies stay, for
        #: rays and views).
        self.motion = motion
        self._step_simulation = c.stepSimulation      # BulletClient builds a new partial on
        self._contact_points = c.getContactPoints     # every attribute access: keep these
        self._build(scene)

    # -- building -------------------------------------------------------------------------
    def _build(self, scene: Scene) -> None:
        """Make the whole world in an empty client: floor, walls, fence, robot, landmarks
        and mesh parts (state saved)."""
        c = self.client
        c.setGravity(0, 0, -9.81)
        c.setTimeStep(self.time_step)
        c.setPhysicsEngineParameter(deterministicOverlappingPairs=1, numSolverIterations=10)
        if self._gui:
            c.configureDebugVisualizer(p.COV_ENABLE_GUI, 0)
        if not self._drawn:     # no visual shapes made for its TinyRenderer: half a URDF's cost
            c.configureDebugVisualizer(p.COV_ENABLE_TINY_RENDERER, 0)
        self._textures: dict[str, int] = {}
        self.scene = scene
        self.floor_id = self._make_floor(scene)
        self.wall_ids = [self._body(wall_solid(w)) for w in scene.walls]
        self.fence_ids = ([self._body(s, visible=False) for s in fence_solids(scene)]
                          if scene.fence else [])
        self.robot = (KinematicRobot(scene, self._robot_config) if self.motion == "kinematic"
                      else Robot(c, self._robot_config))
        self.landmark_ids = [self._body(landmark_solid(lm)) for lm in scene.landmarks]
        self.mesh_ids = [body for part in scene.meshes
                         for body in self._make_part(part, scene.height_band)]
        self._state = self.client.saveState()
        self.obstacle_ids = frozenset(self.wall_ids + self.fence_ids + self.landmark_ids
                                      + self.mesh_ids)

    def _texture(self, name: str | None) -> int | None:
        if name is None:
            return None
        if name not in self._textures:
            self._textures[name] = self.client.loadTexture(texture_path(name))
        return self._textures[name]

    def _paint(self, body: int, color, texture: str | None) -> None:
        if not self._drawn:
            return
        tex = self._texture(texture)
        self.client.changeVisualShape(body, -1, rgbaColor=list(color),
                                      textureUniqueId=-1 if tex is None else tex)

    def _make_floor(self, scene: Scene) -> int:
        x0, y0, x1, y1 = floor_rectangle(scene)
        half = [(x1 - x0) / 2, (y1 - y0) / 2, 0.05]
        centre = [(x0 + x1) / 2, (y0 + y1) / 2, floor_top(scene) - 0.05]
        c = self.client
        col = c.createCollisionShape(p.GEOM_PLANE)
        vis = (c.createVisualShape(p.GEOM_BOX, halfExtents=half, visualFramePosition=centre,
                                   rgbaColor=list(scene.floor_color))
               if scene.ground_plane and self._drawn else -1)
        body = c.createMultiBody(0, col, vis, [0, 0, 0], **_STATIC)
        if scene.ground_plane:
            self._paint(body, scene.floor_color, scene.floor_texture)
        else:
            self._hide(body)
        c.changeDynamics(body, -1, lateralFriction=1.0)
        return body

    def _hide(self, body: int) -> None:
        """Keep PyBullet's renderers from drawing a body that has no visual shape (they
        draw its collision shape otherwise)."""
        if self._drawn:
            self.client.changeVisualShape(body, -1, rgbaColor=[1, 1, 1, 0])

    def _make_part(self, part: MeshPart, band: tuple[float, float]) -> list[int]:
        """Bodies of a mesh part: static concave collision bodies of its triangles that
        reach into ``band`` (if it collides and any do; one per :data:`MAX_SHAPE_FACES`),
        and, where PyBullet draws, visual bodies (no collision) of each face colour
        (colours rounded to 1/16: a PyBullet mesh takes one colour)."""
        c, bodies = self.client, []
        faces = part.faces[band_faces(part, band)] if part.collision else part.faces[:0]
        for chunk in _face_chunks(part.vertices, faces) if len(faces) else ():
            with _MESH_LISTS.lent(*_used_vertices(part.vertices, chunk)) as (vertices, indices):
                col = c.createCollisionShape(p.GEOM_MESH, vertices=vertices, indices=indices,
                                             flags=p.GEOM_FORCE_CONCAVE_TRIMESH)
            bodies.append(c.createMultiBody(0, col, -1, [0, 0, 0], **_STATIC))
            self._hide(bodies[-1])
        if self._drawn:
            levels = np.round(part.face_colors * 16).astype(np.int64)
            keys = (levels[:, 0] * 17 + levels[:, 1]) * 17 + levels[:, 2]
            for key in np.unique(keys):
                for chunk in _face_chunks(part.vertices, part.faces[keys == key]):
                    with _MESH_LISTS.lent(*_used_vertices(part.vertices, chunk)) as (
                            vertices, indices):
                        vis = c.createVisualShape(
                            p.GEOM_MESH, vertices=vertices, indices=indices,
                            rgbaColor=[*(levels[keys == key][0] / 16), 1.0])
                    bodies.append(c.createMultiBody(0, -1, vis, [0, 0, 0], **_STATIC))
                    c.changeVisualShape(bodies[-1], -1, textureUniqueId=-1)   # no checker
        return bodies

    def _body(self, solid: Solid, visible: bool = True) -> int:
        """A static body of ``solid``: its collision shape, and (``visible``, where PyBullet
        draws) its painted visual shape; an invisible one is hidden."""
        c, half = self.client, list(solid.half)
        visible = visible and self._drawn
        if solid.shape == "cylinder":
            col = c.createCollisionShape(p.GEOM_CYLINDER, radius=solid.radius,
                                         height=solid.height)
        else:
            col = c.createCollisionShape(p.GEOM_BOX, halfExtents=half)
        vis = -1
        if visible and solid.shape == "cylinder":
            vis = c.createVisualShape(p.GEOM_CYLINDER, radius=solid.radius,
                                      length=solid.height, rgbaColor=list(solid.color))
        elif visible and solid.shape == "panel":
            vertices, indices, uvs, normals = _panel_mesh(solid.half)
            with _MESH_LISTS.lent(vertices, indices, uvs, normals) as (v, i, uv, n):
                vis = c.createVisualShape(p.GEOM_MESH, vertices=v, indices=i, uvs=uv,
                                          normals=n, rgbaColor=list(solid.color))
        elif visible:
            vis = c.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=list(solid.color))
        body = c.createMultiBody(0, col, vis, list(solid.centre),
                                 c.getQuaternionFromEuler([0, 0, solid.yaw]), **_STATIC)
        if visible:
            self._paint(body, solid.color, solid.texture)
        else:
            self._hide(body)
        return body

    # -- episodes -------------------------------------------------------------------------
    def reset_world(self, scene: Scene, caster: RayCaster | None = None) -> None:
        """Bring the world back to its saved state, switching to ``scene`` if it differs:
        a new world is built in the emptied client (PyBullet frees a removed body's
        collision shapes only on ``resetSimulation``; trajectories are the same as with
        the bodies removed one by one, checked on the three procedural worlds with both
        renderers), with ``caster`` as its ray caster if given (one built elsewhere from
        :func:`world_caster`)."""
        if scene == self.scene:
            self.client.restoreState(self._state)
            return
        self.client.resetSimulation()
        self._build(scene)
        if self.caster is not None:
            self.caster = caster or world_caster(scene, self._sky_color, self._shadows)

    def world_vertices(self) -> np.ndarray:
        """The distinct corners ``(V, 3)`` (metres) of the current world's triangles
        (:func:`~homing_gym.render.worldmesh.world_mesh`), computed once per world."""
        if self._vertices_of is not self.scene:
            corners = world_mesh(self.scene).triangles.reshape(-1, 3).astype(np.float64)
            self._vertices, self._vertices_of = np.unique(corners, axis=0), self.scene
        return self._vertices

    def place_robot(self, pose, clear_contacts: bool = False) -> None:
        """Teleport the robot to ``pose`` (x, y, yaw; metres, radians). With
        ``clear_contacts`` it is first sent 100 m away and back, which drops the contact
        points PyBullet keeps cached by proximity (with their warm-start impulses), so
        the next steps do not depend on where the robot stood before."""
        x, y, yaw = (float(v) for v in pose)
        self.robot.set_pose(x, y, yaw)
        if clear_contacts and self.motion == "pybullet":
            self.robot.set_pose(x + 100.0, y, yaw)
            self.robot.set_pose(x, y, yaw)

    def ray_hit(self, start, end) -> np.ndarray | None:
        """The first point (3-D, metres) that the straight ray from ``start`` to ``end``
        hits, or ``None`` when nothing is in the way."""
        hit = self.client.rayTest([float(v) for v in start], [float(v) for v in end])[0]
        return None if hit[0] < 0 else np.asarray(hit[3], dtype=np.float64)

    def step(self, substeps: int) -> bool:
        """Advance the physics ``substeps`` times; True if the robot touched an obstacle."""
        if self.motion == "kinematic":
            return self.robot.move(substeps, self.time_step)
        touched = False
        step, update_motors = self._step_simulation, self.robot.update_motors
        for _ in range(substeps):
            update_motors(self.time_step)
            step()
            touched = touched or self.robot_in_contact()
        return touched

    def robot_in_contact(self) -> bool:
        """True if the robot currently touches a wall or landmark (the floor does not count)."""
        contacts = self._contact_points(bodyA=self.robot.body_id)
        return any(cp[2] in self.obstacle_ids for cp in contacts)

    def close(self) -> None:
        """Disconnect the client; safe to call more than once."""
        if self._connected:
            self._connected = False
            self.client.disconnect()

    @property
    def connected(self) -> bool:
        return self._connected


def world_sky(scene: Scene, sky_color=None) -> tuple[tuple[float, float, float],
                                                     tuple[float, float, float] | None]:
    """The ray caster's sky, ``(horizon, zenith)``: the env's ``sky_color`` (uniform: no
    zenith colour), else the scene's ``sky_color`` (else white) with its appearance's
    ``sky_zenith``."""
    if sky_color:
        return tuple(sky_color), None
    return tuple(scene.sky_color or SKY_COLOR), scene.appearance.sky_zenith


def world_shadows(scene: Scene, shadows: bool | None = None) -> bool:
    """Whether the world casts shadows: the env's ``shadows`` if given (not ``None``),
    else the scene's appearance's, else not."""
    return bool(scene.appearance.shadows) if shadows is None else shadows


def world_caster(scene: Scene, sky_color=None, shadows: bool | None = None) -> RayCaster:
    """The ray caster of ``scene``'s world mesh (what a simulator with
    ``renderer="raycast"`` draws with) under the env's ``sky_color`` and ``shadows``
    (``None``: the world's; :func:`world_sky`, :func:`world_shadows`)."""
    horizon, zenith = world_sky(scene, sky_color)
    return RayCaster(world_mesh(scene), horizon, world_shadows(scene, shadows), zenith)


def _face_chunks(vertices: np.ndarray, faces: np.ndarray) -> list[np.ndarray]:
    """``faces`` in groups that PyBullet takes as one mesh shape (at most
    :data:`MAX_SHAPE_FACES` each): all in one if they fit, else ordered by their centres'
    x, so that each group covers a strip of the world (small bounding boxes for the
    broad phase)."""
    if len(faces) <= MAX_SHAPE_FACES:
        return [faces]
    order = np.argsort(vertices[faces, 0].mean(axis=1), kind="stable")
    return np.array_split(faces[order], -(-len(faces) // MAX_SHAPE_FACES))


def _used_vertices(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The corners ``(C, 3)`` that ``faces`` use (in their order in ``vertices``) and the
    faces' indices into them ``(3 F,)``: what one of PyBullet's mesh shapes takes."""
    used, inverse = np.unique(faces, return_inverse=True)
    return vertices[used], inverse.ravel()


class _ReusedLists:
    """The lists given to PyBullet's mesh shapes (``vertices``, ``indices``, ``uvs``,
    ``normals``), refilled for every shape. PyBullet 3.2.7 never releases those sequences
    nor any corner in them (its ``extractVertices`` and ``extractIndices`` keep the
    references they take), so fresh lists for each shape stayed in memory for the life
    of the process (about 0.13 MiB a ``random_nature`` world). Reused lists hold only
    the largest shape's numbers (at most :data:`MAX_SHAPE_VERTICES` corners). One per
    process, locked: envs in threads share it."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._lists: list[list] = []            # one per argument position
        self._rows: list[list[list[float]]] = []

    @contextlib.contextmanager
    def lent(self, *arrays) -> Iterator[list[list]]:
        """``arrays`` (1-D: numbers; 2-D: rows of numbers) as the reused lists, theirs
        until the block ends."""
        with self._lock:
            yield [self._refilled(k, np.asarray(a)) for k, a in enumerate(arrays)]

    def _refilled(self, position: int, array: np.ndarray) -> list:
        while len(self._lists) <= position:
            self._lists.append([])
            self._rows.append([])
        items, rows = self._lists[position], self._rows[position]
        if array.ndim == 1:
            items[:] = array.tolist()
            return items
        rows.extend([] for _ in range(len(array) - len(rows)))
        for row, values in zip(rows, array.tolist()):
            row[:] = values
        items[:] = rows[:len(array)]
        return items


_MESH_LISTS = _ReusedLists()


def _panel_mesh(half) -> tuple[list, list, list, list]:
    """The vertices, indices, uvs and normals of a panel's box of half extents ``half``
    (metres), as ``createVisualShape`` takes them: its local +y face carries the whole
    texture once (u left to right as seen from the front, v bottom to top); the other
    faces sample the texture's top-left corner."""
    hx, hy, hz = half
    corner = [0.001, 0.999]
    vertices, normals, uvs, indices = [], [], [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            normal = [0.0, 0.0, 0.0]
            normal[axis] = sign
            # two axes spanning the face, ordered so the quad winds counter-clockwise
            a, b = [(1, 2), (2, 0), (0, 1)][axis]
            face = []
            for s_a, s_b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                v = [0.0, 0.0, 0.0]
                v[axis] = sign
                v[a], v[b] = s_a * sign, s_b
                face.append([v[0] * hx, v[1] * hy, v[2] * hz])
            front = axis == 1 and sign > 0
            for v in face:
                vertices.append(v)
                normals.append(normal)
                uvs.append([0.5 - v[0] / (2 * hx), 0.5 + v[2] / (2 * hz)] if front else corner)
            k = len(vertices) - 4
            indices += [k, k + 1, k + 2, k, k + 2, k + 3]
    return vertices, indices, uvs, normals


def gui_unavailable() -> str | None:
    """Why PyBullet's GUI cannot open here, or ``None``: on Linux it needs an X display,
    and without one PyBullet ends the whole process from C instead of raising."""
    if sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
        return "no X display (DISPLAY is not set)"
    return None


SOFTWARE_GL = ("llvmpipe", "softpipe", "swrast")


@functools.cache
def egl_status() -> str | None:
    """Why EGL cannot be used in this process, or ``None`` if it can. Probed once, in a
    throwaway client: the plugin prints the OpenGL renderer's name to fd 1, and a
    software rasteriser (Mesa llvmpipe: no GPU, slower than TinyRenderer) does not count.
    (Unloading the plugin from a client that keeps running crashes PyBullet, hence the
    separate client.)"""
    egl = pkgutil.get_loader("eglRenderer")
    if egl is None:
        return "PyBullet has no eglRenderer plugin"
    probe = BulletClient(connection_mode=p.DIRECT)
    with tempfile.TemporaryFile(mode="w+") as log:
        saved = os.dup(1)
        os.dup2(log.fileno(), 1)
        try:
            plugin = probe.loadPlugin(egl.get_filename(), "_eglRendererPlugin")
        finally:
            os.dup2(saved, 1)
            os.close(saved)
            probe.disconnect()
        log.seek(0)
        gl_info = log.read()
    if plugin < 0:
        return "the EGL plugin could not be loaded"
    if any(name in gl_info for name in SOFTWARE_GL):
        return "EGL runs on a software rasteriser (no GPU)"
    return None


def load_egl(client: BulletClient) -> int:
    """Load PyBullet's EGL renderer plugin into ``client`` and return the renderer flag
    for ``getCameraImage``; fall back to TinyRenderer with a ``RuntimeWarning`` where
    :func:`egl_status` says EGL cannot be used."""
    reason = egl_status()
    if reason is None and client.loadPlugin(pkgutil.get_loader("eglRenderer").get_filename(),
                                            "_eglRendererPlugin") < 0:
        reason = "the EGL plugin could not be loaded"
    if reason:
        warnings.warn(f"renderer='egl' requested but {reason}; falling back to TinyRenderer",
                      RuntimeWarning, stacklevel=3)
        return p.ER_TINY_RENDERER
    return p.ER_BULLET_HARDWARE_OPENGL
