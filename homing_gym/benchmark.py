"""Speed benchmark: env steps per second against render-only panoramas per second.

``python -m homing_gym.benchmark`` (or ``homing-benchmark``) measures, for each
configuration, in the same run:

* ``render``: panoramas per second of the camera alone at random poses in the same world
  (the reference: what the env cannot avoid doing);
* ``env``: ``env.step`` calls per second with random actions in one process (resets
  included when episodes end);
* ``vector``: env steps per second summed over a ``gymnasium.vector.AsyncVectorEnv`` of
  ``--workers`` processes;
* ``ratio``: time per env step divided by time per render (1.25 = the env adds 25%).

Worlds: ``arena`` (Yu & Kim's arena, 1,074 triangles, untextured), ``hallway`` (Hong's
corridor: every wall, door and poster textured, so most rays sample a texture), ``forest10k`` (40 trees as
64-sided prisms of random size in a walled 10 m square, 10,290 triangles) and
``mesh10k`` (a mesh world: 30 lumpy rocks and four walls of triangles, 9,650 triangles
and the floor, :func:`mesh_world`), ``grass10k`` and ``grass50k`` (tussock grass of
10,000 and 50,000 thin blades the robot drives through, :func:`grass_world`). With
``tiny`` at 48 x 256 in the arena, homing-gym 0.1's default physics steps of 1/240 s
(``physics_substeps=24``) are measured too. ``--worlds`` also takes any scene an env
takes: a scene name (one registered by ``--import MODULE`` too) or ``mesh:PATH``.

``--resets N`` also times ``env.reset()`` in the procedural worlds (:data:`RESET_SCENES`,
LocalHoming-v0 with the default camera): with a new world at every reset
(``episodes_per_world=1``: the world drawn, the PyBullet bodies and the ray caster's mesh
built) and in the same world (the saved state restored, a new episode sampled, the goal
snapshot rendered); medians of 5 blocks of ``N`` resets.

``--culling-bound N`` instead times the ray caster alone at ``N`` random poses of each
world (the arena first, the first ``--shapes``): casting every triangle, and casting only
the triangles that the panorama shows (the same pixels): what an oracle culler that knew
the final image would cost, the most any culling of hidden triangles could gain.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import asdict, dataclass, fields

import gymnasium as gym
import numpy as np
from tqdm import tqdm

import homing_gym  # noqa: F401  (registers the envs)
from homing_gym.cli import command_parser, worker_count
from homing_gym.config import MOTIONS
from homing_gym.outputs import output_file_argument, write_text_atomic
from homing_gym.render.raycast import RayCaster, scratch_buffers
from homing_gym.render.worldmesh import WorldMesh
from homing_gym.scenes import Landmark, MeshScene, Scene, scene_factory, square_walls
from homing_gym.scenes.tussocks import tussock_blades

#: Panorama shapes measured, (H, W) pixels.
SHAPES = {"48x256": (48, 256), "60x360": (60, 360), "120x720": (120, 720)}


def forest_scene(trees: int = 40, seed: int = 0) -> Scene:
    """A walled 10 m square with ``trees`` cylinders of random radius (0.1-0.4 m), height
    (1-4 m) and colour, at least 1 m from the centre (the robot's start)."""
    rng = np.random.default_rng(seed)
    landmarks = []
    while len(landmarks) < trees:
        x, y = rng.uniform(-4.5, 4.5, 2)
        if np.hypot(x, y) > 1.0:
            landmarks.append(Landmark((float(x), float(y)), radius=float(rng.uniform(0.1, 0.4)),
                                      height=float(rng.uniform(1, 4)),
                                      color=(*rng.uniform(0.1, 0.9, 3).tolist(), 1.0)))
    return Scene("forest10k", ((-5, -5), (5, 5)), walls=square_walls(10.0),
                 landmarks=tuple(landmarks))


def mesh_world(rocks: int = 30, seed: int = 0) -> MeshScene:
    """A mesh world of about 10,000 triangles: a 10 m square walled by four mesh boxes
    with ``rocks`` lumpy solids (icospheres of 320 faces, 0.2-0.6 m across, 0.2-1.5 m
    high, random colours) at least 1 m from the centre."""
    import trimesh

    rng = np.random.default_rng(seed)
    meshes, colors = [], []
    for x, y, ex, ey in ((0, 5.05, 10.2, 0.1), (0, -5.05, 10.2, 0.1), (5.05, 0, 0.1, 10.2),
                         (-5.05, 0, 0.1, 10.2)):
        wall = trimesh.creation.box(extents=(ex, ey, 1.0))
        wall.apply_translation((x, y, 0.5))
        meshes.append(wall)
        colors.append(np.full((12, 3), 0.85))
    while len(meshes) < 4 + rocks:
        x, y = rng.uniform(-4.4, 4.4, 2)
        if np.hypot(x, y) > 1.0:
            rock = trimesh.creation.icosphere(subdivisions=2)
            rock.vertices *= rng.uniform(0.8, 1.2, (len(rock.vertices), 1))
            rock.vertices *= [*rng.uniform(0.1, 0.3, 2), rng.uniform(0.1, 0.75)]
            rock.apply_translation((x, y, -rock.vertices[:, 2].min()))
            meshes.append(rock)
            colors.append(np.tile(rng.uniform(0.1, 0.9, 3), (len(rock.faces), 1)))
    joined = trimesh.util.concatenate(meshes)
    return MeshScene.from_arrays(joined.vertices, joined.faces, np.concatenate(colors),
                                 name="mesh10k", bounds=((-5, -5), (5, 5)), fence=False)


def grass_world(blades: int = 10_000, seed: int = 0) -> MeshScene:
    """A 10 m square of tussock grass the robot drives through (no collision, fenced):
    ``blades`` blades (:func:`homing_gym.scenes.tussocks.tussock_blades`: one thin
    triangle each, 1-4 cm wide at the ground, 5-90 cm tall, in clumps of 10-60 of up to
    15 cm radius), on a brown floor."""
    corners, colors = tussock_blades(blades, seed, 4.9)
    return MeshScene.from_arrays(corners.reshape(-1, 3), np.arange(3 * blades).reshape(-1, 3),
                                 colors, collision=False, name=f"grass{blades // 1000}k",
                                 bounds=((-5, -5), (5, 5)), ground_color=(0.45, 0.35, 0.2, 1.0))


#: Worlds measured: scene kwargs.
WORLDS = {"arena": {}, "hallway": {"scene": "hallway"}, "forest10k": {"scene": forest_scene()},
          "mesh10k": {"scene": mesh_world()}, "grass10k": {"scene": grass_world(10_000)},
          "grass50k": {"scene": grass_world(50_000)}}
#: The procedural scenes whose resets ``--resets`` times.
RESET_SCENES = ("random_arena", "random_rooms", "random_nature")


def world_kwargs(world: str) -> dict:
    """The env kwargs of ``world``: a benchmark world of :data:`WORLDS`, else any scene
    an env takes (a scene name, also one registered by ``--import``, or ``mesh:PATH``);
    ``ValueError`` naming both kinds otherwise."""
    if world in WORLDS:
        return WORLDS[world]
    try:
        scene_factory(world)
    except ValueError as err:
        raise ValueError(f"world {world!r}: neither a benchmark world {list(WORLDS)} nor a "
                         f"scene ({err})") from None
    return {"scene": world}


def configs(renderers: list[str], shapes: list[str],
            worlds: list[str] = ("arena",)) -> dict[str, dict]:
    """Env kwargs of each measured configuration, named ``RENDERER HxW [WORLD]`` (the
    default physics, steps of 1/120 s; ``WORLD``: :func:`world_kwargs`); with ``tiny``
    at 48 x 256 in the arena also ``tiny 48x256 1/240 s``, homing-gym 0.1's default env."""
    out = {}
    for world in worlds:
        suffix = "" if world == "arena" else f" {world}"
        kwargs = world_kwargs(world)
        for s in shapes:
            for r in renderers:
                out[f"{r} {s}{suffix}"] = {"renderer": r, "panorama_shape": SHAPES[s],
                                           **kwargs}
                if (r, s, world) == ("tiny", "48x256", "arena"):
                    out["tiny 48x256 1/240 s"] = {"renderer": r, "panorama_shape": SHAPES[s],
                                                  "physics_substeps": 24}
    return out


@dataclass
class BenchmarkResult:
    """Throughputs (per second) of one configuration."""

    config: str
    env_kwargs: dict
    render_per_s: float
    env_steps_per_s: float
    vector_steps_per_s: float
    workers: int

    @property
    def ratio(self) -> float:
        """Time per env step over time per render."""
        return self.render_per_s / self.env_steps_per_s


def random_poses(env: gym.Env, n: int, rng: np.random.Generator) -> np.ndarray:
    """``(n, 3)`` poses ``(x, y, yaw)`` (metres, radians) drawn uniformly in the bounds of
    the env's world and over all headings."""
    (xmin, ymin), (xmax, ymax) = env.unwrapped.scene.bounds
    return np.column_stack([rng.uniform(xmin, xmax, n), rng.uniform(ymin, ymax, n),
                            rng.uniform(-np.pi, np.pi, n)])


def render_rate(env: gym.Env, n: int, rng: np.random.Generator) -> float:
    """Panoramas per second rendered at random poses of the env's world."""
    u = env.unwrapped
    poses = random_poses(env, n, rng)
    start = time.perf_counter()
    for pose in poses:
        u.render_panorama(pose)
    return n / (time.perf_counter() - start)


def shown_caster(caster: RayCaster, pose, camera_height: float, config) -> RayCaster:
    """A ray caster of only the triangles that ``caster``'s panorama at ``pose`` (``(x, y,
    yaw)``, metres and radians; ``camera_height`` metres, ``config`` a
    :class:`~homing_gym.render.panorama.CameraConfig`) shows; its panorama there has the
    same pixels. ``ValueError`` for a caster with shadows (hidden triangles cast them)."""
    if caster.shadows:
        raise ValueError("shadows=True: hidden triangles cast shadows, so the triangles "
                         "shown alone do not make the same panorama; use shadows=False")
    caster.panorama(pose, camera_height, config)
    (H, W), k = config.panorama_shape, config.supersampling
    hit = scratch_buffers(H * k, W * k)[0]           # the cast just made
    ids = np.unique(hit[hit >= 0])
    m = caster.mesh
    shown = WorldMesh(m.triangles[ids], m.colors[ids], m.texture[ids], m.uvs[ids], m.textures,
                      m.closed[ids])
    return RayCaster(shown, caster.sky, False, caster.sky_zenith)


def culling_bound(env: gym.Env, n: int, rng: np.random.Generator,
                  repeats: int = 10) -> tuple[float, float, float]:
    """``(every, shown, count)``: the median panoramas per second of the env's ray caster
    over ``n`` random poses of its world (as :func:`render_rate`, ``repeats`` panoramas
    each) casting every triangle and casting only those shown (:func:`shown_caster`),
    and the median number of triangles shown."""
    u = env.unwrapped
    if u.sim.caster is None:
        raise ValueError(f"renderer {u.camera.config.renderer!r}: the culling bound times "
                         "the ray caster, renderer='raycast'")
    h, config = u.camera.camera_height, u.camera.config
    every, shown, counts = [], [], []
    for pose in random_poses(env, n, rng):
        sub = shown_caster(u.sim.caster, pose, h, config)
        for caster, rates in ((u.sim.caster, every), (sub, shown)):
            caster.panorama(pose, h, config)
            start = time.perf_counter()
            for _ in range(repeats):
                caster.panorama(pose, h, config)
            rates.append(repeats / (time.perf_counter() - start))
        counts.append(len(sub.mesh.triangles))
    return float(np.median(every)), float(np.median(shown)), float(np.median(counts))


def culling_bound_table(worlds: list[str], shape: tuple[int, int], n: int) -> str:
    """A Markdown table of :func:`culling_bound` in the arena and each of ``worlds``
    (LocalHoming-v0, ``shape`` panoramas); ``vs arena``: the shown-only rate over the
    arena's every-triangle rate, same run."""
    lines = ["| world | triangles | shown (median) | every triangle (pano/s) | "
             "shown only (pano/s) | shown only vs arena |", "|---|---:|---:|---:|---:|---:|"]
    arena = None
    for world in tqdm(["arena", *(w for w in worlds if w != "arena")], desc="culling bound"):
        env = gym.make("homing_gym/LocalHoming-v0", renderer="raycast",
                       panorama_shape=shape, **world_kwargs(world))
        env.reset(seed=0)
        try:
            every, shown, count = culling_bound(env, n, np.random.default_rng(0))
            triangles = len(env.unwrapped.sim.caster.mesh.triangles)
        finally:
            env.close()
        arena = arena or every
        lines.append(f"| {world} | {triangles} | {count:.0f} | {every:.0f} | {shown:.0f} | "
                     f"{shown / arena:.2f}x |")
    return "\n".join(lines)


def step_rate(env, n: int, batch: int = 1) -> float:
    """Env steps per second with random actions (``batch`` envs per call for vector envs)."""
    start = time.perf_counter()
    for _ in range(n):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if batch == 1 and (terminated or truncated):
            env.reset()
    return n * batch / (time.perf_counter() - start)


def vector_rate(env_kwargs: dict, block: int, workers: int, rounds: int,
                env_id: str = "homing_gym/LocalHoming-v0") -> float:
    """Median env steps per second of an ``AsyncVectorEnv`` of ``workers`` processes."""
    vec = gym.make_vec(env_id, num_envs=workers, vectorization_mode="async",
                       vector_kwargs={"context": "spawn"}, **env_kwargs)
    vec.action_space.seed(0)
    vec.reset(seed=0)
    rate = np.median([step_rate(vec, max(block // workers, 5), batch=workers)
                      for _ in range(rounds)])
    vec.close()
    return float(rate)


def run_configs(configs: dict[str, dict], steps: int, workers: int, rounds: int = 10,
                env_id: str = "homing_gym/LocalHoming-v0") -> list[BenchmarkResult]:
    """Measure every configuration. Each round runs a render-only block and an env block
    of every configuration in turn, and the medians over ``rounds`` rounds are reported,
    so that load from other processes, and its drift over the run, hits all of them
    alike (the ratios between configurations are what the tables compare); the vector
    envs are measured after them, one configuration at a time."""
    envs, rngs = {}, {}
    for name, kwargs in configs.items():
        env = gym.make(env_id, **kwargs)
        env.action_space.seed(0)
        env.reset(seed=0)
        rngs[name] = np.random.default_rng(0)
        render_rate(env, 20, rngs[name])
        envs[name] = env
    block = max(steps // rounds, 5)
    renders: dict[str, list[float]] = {name: [] for name in configs}
    singles: dict[str, list[float]] = {name: [] for name in configs}
    try:
        for _ in tqdm(range(rounds), desc="render and env, every configuration in turn"):
            for name, env in envs.items():
                renders[name].append(render_rate(env, block, rngs[name]))
                singles[name].append(step_rate(env, block))
    finally:
        for env in envs.values():
            env.close()
    return [BenchmarkResult(name, kwargs, float(np.median(renders[name])),
                            float(np.median(singles[name])),
                            vector_rate(kwargs, block, workers, rounds, env_id), workers)
            for name, kwargs in tqdm(configs.items(), desc=f"vector envs x{workers}")]


def reset_ms(scene: str, new_world: bool, n: int, blocks: int = 5) -> float:
    """Median wall time (milliseconds) of one LocalHoming-v0 ``reset()`` in ``scene``, with
    a new world at every reset or always the same one, over ``blocks`` blocks of ``n``."""
    env = gym.make("homing_gym/LocalHoming-v0", scene=scene,
                   episodes_per_world=1 if new_world else 10**9)
    env.reset(seed=0)
    times = []
    for _ in range(blocks):
        start = time.perf_counter()
        for _ in range(n):
            env.reset()
        times.append((time.perf_counter() - start) / n * 1e3)
    env.close()
    return float(np.median(times))


def reset_table(n: int) -> str:
    """A Markdown table of :func:`reset_ms` for every scene of :data:`RESET_SCENES`."""
    lines = ["| scene | reset, new world (ms) | reset, same world (ms) |", "|---|---|---|"]
    for scene in tqdm(RESET_SCENES, desc="resets"):
        lines.append(f"| {scene} | {reset_ms(scene, True, n):.1f} | "
                     f"{reset_ms(scene, False, n):.2f} |")
    return "\n".join(lines)


def format_table(results: list[BenchmarkResult]) -> str:
    """A Markdown table of the results; ``env vs tiny``: env steps/s over those of
    ``renderer="tiny"`` at the same shape in the same world; ``env vs arena``: over
    those of the same renderer and shape in the arena (both measured in the same run)."""
    def key(r: BenchmarkResult, scene: bool = True, renderer: bool = False) -> tuple:
        return (tuple(r.env_kwargs["panorama_shape"]), r.env_kwargs.get("physics_substeps"),
                str(r.env_kwargs.get("scene")) if scene else None,
                r.env_kwargs.get("renderer") if renderer else None)

    tiny = {key(r): r.env_steps_per_s for r in results if r.env_kwargs.get("renderer") == "tiny"}
    arena = {key(r, False, True): r.env_steps_per_s for r in results
             if "scene" not in r.env_kwargs}
    lines = ["| config | render (pano/s) | env (steps/s) | env vs tiny | env vs arena | "
             "env / render time | AsyncVectorEnv (steps/s) |", "|---|---|---|---|---|---|---|"]
    for r in results:
        ref = tiny.get(key(r))
        versus = f"{r.env_steps_per_s / ref:.2f}x" if ref else "-"
        ref = arena.get(key(r, False, True)) if "scene" in r.env_kwargs else None
        world = f"{r.env_steps_per_s / ref:.2f}x" if ref else "-"
        lines.append(f"| {r.config} | {r.render_per_s:.1f} | {r.env_steps_per_s:.1f} | "
                     f"{versus} | {world} | {r.ratio:.3f} | {r.vector_steps_per_s:.1f} "
                     f"({r.workers} workers) |")
    return "\n".join(lines)


def _record(result: BenchmarkResult) -> dict:
    """A result as JSON data (a scene object named by its name)."""
    kwargs = {k: v.name if isinstance(v, Scene) else v for k, v in result.env_kwargs.items()}
    return {f.name: getattr(result, f.name) for f in fields(result)} | {
        "env_kwargs": kwargs, "ratio": result.ratio}


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("homing-benchmark", __doc__)
    parser.add_argument("--steps", type=int, default=500, help="steps per measurement")
    parser.add_argument("--workers", type=worker_count, default=2,
                        help="AsyncVectorEnv workers")
    parser.add_argument("--renderers", nargs="+", default=["tiny", "raycast"],
                        choices=["tiny", "raycast", "egl"], help="renderers to compare")
    parser.add_argument("--shapes", nargs="+", default=list(SHAPES), choices=list(SHAPES),
                        help="panorama shapes (H x W)")
    parser.add_argument("--worlds", nargs="+", default=["arena"], metavar="WORLD",
                        help=f"benchmark worlds {list(WORLDS)} (hallway: textured; forest10k: "
                             "10,290 triangles; mesh10k: a mesh world of 9,650 triangles) or "
                             "any scene: a scene name (also one --import registers) or "
                             "mesh:PATH")
    parser.add_argument("--json", type=output_file_argument,
                        help="also write the results to this JSON file (checked before the "
                        "measuring starts, replaced in one step at the end)")
    parser.add_argument("--resets", type=int, default=0, metavar="N",
                        help="also time N resets (x 5 blocks) in each procedural world, "
                             "with a new world every time and in the same world")
    parser.add_argument("--vec", choices=["native"],
                        help="measure the native vector env instead (homing_gym.vector."
                             "benchmark): --num-envs envs in one process and in each of "
                             "--processes, against one env in one process, at the first "
                             "--shapes in each --worlds")
    parser.add_argument("--num-envs", type=worker_count, default=8,
                        help="envs of the native vector env (--vec native)")
    parser.add_argument("--processes", type=worker_count, nargs="+", default=[2],
                        help="worker process counts measured beside one process (--vec native)")
    parser.add_argument("--episode-steps", type=worker_count, default=45,
                        help="mean episode length of the random actions (--vec native)")
    parser.add_argument("--motion", choices=MOTIONS, default=MOTIONS[0],
                        help="the robot's motion model in every configuration (--vec "
                             "native; 'kinematic': homing_gym.sim.kinematic)")
    parser.add_argument("--culling-bound", type=int, metavar="N",
                        help="instead time the ray caster at N random poses per world (the "
                             "arena first, the first --shapes): every triangle against only "
                             "those each panorama shows, the most culling could gain")
    args = parser.parse_args(argv)
    if args.steps < 10 or args.resets < 0:
        parser.error("need --steps >= 10 and --resets >= 0")
    if args.culling_bound is not None and args.culling_bound < 1:
        parser.error(f"--culling-bound {args.culling_bound}: need N >= 1 poses")
    if args.culling_bound:
        try:
            print(culling_bound_table(args.worlds, SHAPES[args.shapes[0]], args.culling_bound))
        except ValueError as err:
            parser.error(f"--worlds: {err}")
        return 0
    if args.vec == "native":
        return _native(args, parser)
    try:
        measured = configs(args.renderers, args.shapes, args.worlds)
    except ValueError as err:
        parser.error(f"--worlds: {err}")
    results = run_configs(measured, args.steps, args.workers)
    print(format_table(results))
    if args.resets:
        print(reset_table(args.resets))
    if args.json:
        write_text_atomic(args.json, json.dumps([_record(r) for r in results], indent=2))
    return 0


def _native(args, parser) -> int:
    """``--vec native``: the table of :mod:`homing_gym.vector.benchmark`."""
    from homing_gym.vector import benchmark as vector_benchmark

    if any(p > args.num_envs for p in args.processes):
        parser.error(f"--processes {args.processes}: at most --num-envs ({args.num_envs})")
    try:
        worlds = {w: {**world_kwargs(w), "motion": args.motion} for w in args.worlds}
    except ValueError as err:
        parser.error(f"--worlds: {err}")
    results = vector_benchmark.run(worlds, args.num_envs, sorted({1, *args.processes}),
                                   args.steps, episode_steps=args.episode_steps,
                                   shape=SHAPES[args.shapes[0]])
    print(vector_benchmark.table(results, args.num_envs))
    if args.json:
        write_text_atomic(args.json, json.dumps([asdict(r) for r in results], indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
