"""The package layers: homing_train -> homing_baselines -> homing_gym, no import cycles;
inside homing_gym, the env core -> sim -> render -> scenes (PARTS).

Every module of the three installed packages is parsed (``ast``; imports inside functions
and under ``TYPE_CHECKING`` count too) and its imports of the three packages become edges
of a ``networkx`` graph."""

import ast
import importlib.util
import pkgutil
import subprocess
import sys

import networkx as nx
import pytest

PACKAGES = ("homing_gym", "homing_baselines", "homing_train")
LAYER = {"homing_gym": 0, "homing_baselines": 1, "homing_train": 2}
#: Top-level modules of homing_gym that every part may use: helpers with no world, camera
#: or episode of their own.
SHARED = {"homing_gym.cli", "homing_gym.geometry", "homing_gym.native_output",
          "homing_gym.selfsimilar", "homing_gym.validation", "homing_gym.vision"}
#: The parts of homing_gym below the env core, each with the parts it may import (besides
#: itself and SHARED): scenes <- render <- sim <- env core (env, envs, tasks, ...).
PARTS = {"homing_gym.scenes": set(), "homing_gym.render": {"homing_gym.scenes"},
         "homing_gym.sim": {"homing_gym.scenes", "homing_gym.render"}}
#: The modules of homing_gym that import PyBullet: the package (its banner silenced once),
#: the simulated world, and the two TinyRenderer bridges of the renderer.
PYBULLET_USERS = {"homing_gym", "homing_gym.sim.simulator", "homing_gym.sim.robot",
                  "homing_gym.render.panorama", "homing_gym.render.perspective"}


def _modules() -> dict[str, str]:
    """Module name -> source file of every module of the three packages."""
    out = {}
    for package in PACKAGES:
        spec = importlib.util.find_spec(package)
        out[package] = spec.origin
        for info in pkgutil.walk_packages(spec.submodule_search_locations, package + "."):
            out[info.name] = importlib.util.find_spec(info.name).origin
    return out


def _imported(module: str, path: str, known: set[str]) -> set[str]:
    """The known modules that ``module`` imports (a ``from P import name`` counts as an
    import of ``P.name`` when that is a module, else of ``P``)."""
    is_package = path.endswith("__init__.py")
    tree = ast.parse(open(path).read(), path)
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = module.split(".")
                anchor = parts if is_package else parts[:-1]
                anchor = anchor[:len(anchor) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            names = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base
                     for alias in node.names]
        else:
            continue
        for name in names:
            while name and name not in known:
                name = name.rpartition(".")[0]
            if name:
                found.add(name)
    found.discard(module)
    return found


@pytest.fixture(scope="module")
def graph() -> nx.DiGraph:
    modules = _modules()
    g = nx.DiGraph()
    g.add_nodes_from(modules)
    for module, path in modules.items():
        g.add_edges_from((module, dep) for dep in _imported(module, path, set(modules)))
    return g


def test_every_package_is_walked(graph):
    assert {"homing_gym.env", "homing_gym.tasks.base", "homing_baselines.snapshot",
            "homing_train.harness.evaluate", "homing_train.figures.hong"} <= set(graph)


def test_no_import_points_up_the_layers(graph):
    upward = [(a, b) for a, b in graph.edges
              if LAYER[b.split(".")[0]] > LAYER[a.split(".")[0]]]
    assert upward == [], f"imports against the layers (core <- controllers <- harness): {upward}"


def test_no_import_cycles(graph):
    # a package's __init__ importing its own submodules is the package's API, not a cycle
    g = graph.copy()
    g.remove_edges_from([(a, b) for a, b in graph.edges if b.startswith(a + ".")])
    cycles = list(nx.simple_cycles(g))
    assert cycles == [], f"import cycles: {cycles[:5]}"


def test_tasks_never_reach_the_env(graph):
    g = graph.copy()
    g.remove_edges_from([(a, b) for a, b in graph.edges if b.startswith(a + ".")])
    tasks = [m for m in g if m.startswith("homing_gym.tasks")]
    reached = {m for t in tasks for m in nx.descendants(g, t)}
    assert "homing_gym.env" not in reached and "homing_gym.sim.simulator" not in reached


def _part(module: str) -> str | None:
    """The part of homing_gym (a PARTS key, or "shared") that ``module`` belongs to."""
    if module in SHARED:
        return "shared"
    return next((part for part in PARTS if module == part or module.startswith(part + ".")),
                None)


def test_render_sim_and_scenes_never_import_the_env_core(graph):
    assert {"homing_gym.render.raycast", "homing_gym.sim.simulator",
            "homing_gym.scenes.solids"} <= set(graph)
    allowed = {part: {part, "shared"} | below for part, below in PARTS.items()}
    allowed["shared"] = {"shared"}
    wrong = [(a, b) for a, b in graph.edges
             if _part(a) and b.startswith("homing_gym") and _part(b) not in allowed[_part(a)]]
    assert wrong == [], f"imports out of the parts (scenes <- render <- sim <- core): {wrong}"


def test_only_the_world_and_the_tinyrenderer_bridges_import_pybullet():
    users = set()
    for module, path in _modules().items():
        if module.startswith("homing_gym"):
            tree = ast.parse(open(path).read(), path)
            names = [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import)
                     for alias in node.names]
            names += [node.module or "" for node in ast.walk(tree)
                      if isinstance(node, ast.ImportFrom)]
            if any(n.split(".")[0] in ("pybullet", "pybullet_utils") for n in names):
                users.add(module)
    assert users == PYBULLET_USERS


def test_generic_top_level_names_are_not_installed(tmp_path):
    code = ("import importlib.util as u; "
            "print([n for n in ('train', 'baselines') if u.find_spec(n)], "
            "[n for n in ('homing_train', 'homing_baselines') if not u.find_spec(n)])")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True, timeout=60)
    assert out.stdout.strip() == "[] []"


def test_the_rllib_command_imports_without_stable_baselines3():
    """.ci/rllib's environment has RLlib but not the [train] extra: the RLlib module (and
    what it imports of homing-train's) must import with stable-baselines3 absent."""
    code = ("import sys; sys.modules['stable_baselines3'] = None; "
            "import homing_train.learning.rllib_ppo")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
