"""New worlds built ahead of need, off the vector step's critical path.

A procedural scene builds a new world on a reset (every ``episodes_per_world``
episodes): the world drawn, its ray caster's mesh built, its PyBullet bodies made,
20-40 ms in all, while a vector step of 8 envs takes a few. An env's unseeded worlds
come from its seed's world stream (:func:`homing_gym.env.world_seeds`), so the next
one is known as soon as the last is taken: a :class:`WorldBuilder` process draws it and
builds its ray caster (two thirds of the cost) while the envs step, and the env only
makes the PyBullet bodies when it resets. The worlds are those the env would build
itself, pixel for pixel. If the builder is gone (or the env's scene is not a registered
name that the builder process can look up), the env builds its worlds itself. In one
process the batch starts its builder itself; a worker process of
:class:`~homing_gym.vector.processes.ProcessBatch` (a daemon, which may not start
processes of its own) is handed one that the main process started
(:func:`start_builder`).
"""

from __future__ import annotations

import multiprocessing as mp
import signal
import threading
from multiprocessing.connection import Connection

import numpy as np

from homing_gym.render.raycast import RayCaster
from homing_gym.scenes import scene_factory
from homing_gym.scenes.base import Scene
from homing_gym.sim.simulator import world_caster

#: Seconds a closing builder may take before it is killed.
CLOSE_TIMEOUT = 5.0


def next_child(stream: np.random.SeedSequence) -> np.random.SeedSequence:
    """The child ``stream.spawn(1)[0]`` will give, without spawning it."""
    return np.random.SeedSequence(stream.entropy,
                                  spawn_key=(*stream.spawn_key, stream.n_children_spawned),
                                  pool_size=stream.pool_size)


def _build(scene: str, sky_color, shadows: bool | None,
           seeds: np.random.SeedSequence) -> tuple[Scene, RayCaster]:
    world = scene_factory(scene).build(np.random.default_rng(seeds))
    return world, world_caster(world, sky_color, shadows)


def _serve(conn) -> None:
    """The builder process: build each requested world, in order, until the pipe closes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        while (message := conn.recv()) is not None:      # None: close
            key, request = message
            try:
                conn.send((key, _build(*request)))
            except Exception:           # noqa: BLE001  the env builds it, and says why
                conn.send((key, None))
    except (EOFError, OSError):
        pass


def start_builder(name: str = "homing-worlds") -> tuple[mp.Process, Connection]:
    """A spawned builder process (a daemon) and the end of its pipe that a
    :class:`WorldBuilder` talks through (in this process or handed to another)."""
    ctx = mp.get_context("spawn")
    conn, child = ctx.Pipe()
    process = ctx.Process(target=_serve, args=(child,), daemon=True, name=name)
    process.start()
    child.close()
    return process, conn


def stop_builder(process: mp.Process) -> None:
    """Wait for a builder process told to close (or whose pipe closed), killing it after
    :data:`CLOSE_TIMEOUT` seconds."""
    process.join(CLOSE_TIMEOUT)
    if process.is_alive():
        process.kill()
        process.join()


class WorldBuilder:
    """A builder process that builds the worlds of a batch's envs ahead of need, through
    ``conn`` (its pipe's end, :func:`start_builder`; by default one started here, which
    :meth:`close` also stops); a thread of this process receives the worlds as they are
    done (so that the builder never waits for the pipe)."""

    def __init__(self, conn: Connection | None = None):
        self._process: mp.Process | None = None
        if conn is None:
            self._process, conn = start_builder()
        self._conn = conn
        self._done: dict[tuple, tuple[Scene, RayCaster] | None] = {}
        self._asked: set[tuple] = set()
        self._dropped: set[tuple] = set()
        self._ready = threading.Condition()
        self.alive = True
        #: Worlds handed to envs so far.
        self.served = 0
        self._receiver = threading.Thread(target=self._receive, daemon=True,
                                          name="homing-worlds-receiver")
        self._receiver.start()

    def _receive(self) -> None:
        while True:
            try:
                key, world = self._conn.recv()
            except (EOFError, OSError):
                break
            with self._ready:
                if key in self._dropped:
                    self._dropped.discard(key)
                else:
                    self._done[key] = world
                self._ready.notify_all()
        with self._ready:
            self.alive = False
            self._ready.notify_all()

    def source(self, scene: str, sky_color, shadows: bool | None) -> "BuiltWorlds":
        """The :class:`~homing_gym.env.WorldSource` of one env whose scene is ``scene``."""
        return BuiltWorlds(self, (scene, sky_color, shadows))

    def ask(self, key: tuple, request: tuple) -> None:
        """Have world ``key`` built from ``request`` (scene, sky colour, shadows, seeds)."""
        with self._ready:
            if not self.alive:
                return
            self._asked.add(key)
        try:
            self._conn.send((key, request))
        except OSError:
            with self._ready:
                self._asked.discard(key)

    def drop(self, key: tuple) -> None:
        """Forget world ``key`` (asked, no longer wanted)."""
        with self._ready:
            if self._done.pop(key, False) is False and key in self._asked:
                self._dropped.add(key)
            self._asked.discard(key)

    def take(self, key: tuple) -> tuple[Scene, RayCaster] | None:
        """World ``key`` (waiting for it if it is still being built), or ``None``."""
        with self._ready:
            self._ready.wait_for(lambda: key not in self._asked or key in self._done
                                 or not self.alive)
            self._asked.discard(key)
            world = self._done.pop(key, None)
        self.served += world is not None
        return world

    def close(self) -> None:
        """Tell the process to stop (and wait for it, if started here), then the receiver
        (the pipe's end tells it); safe to call more than once."""
        try:
            self._conn.send(None)
        except OSError:
            pass
        if self._process is not None:
            stop_builder(self._process)
        self._receiver.join(CLOSE_TIMEOUT)
        self._conn.close()
        self._done.clear()


class BuiltWorlds:
    """One env's worlds from a :class:`WorldBuilder` (its ``world_source``)."""

    def __init__(self, builder: WorldBuilder, request: tuple):
        self._builder, self._request = builder, request
        self._next: tuple | None = None

    def _key(self, seeds: np.random.SeedSequence) -> tuple:
        return (id(self), seeds.entropy, seeds.spawn_key)

    def world(self, seeds: np.random.SeedSequence) -> tuple[Scene, RayCaster] | None:
        key = self._key(seeds)
        if key != self._next:
            return None
        self._next = None
        return self._builder.take(key)

    def ahead(self, stream: np.random.SeedSequence) -> None:
        seeds = next_child(stream)
        key = self._key(seeds)
        if key == self._next:
            return
        if self._next is not None:
            self._builder.drop(self._next)
        self._next = key
        self._builder.ask(key, (*self._request, seeds))
