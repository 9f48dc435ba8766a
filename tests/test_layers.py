"""The packages import downward only, with no cycle, and every module imports.

Layers, bottom to top (docs/architecture.md):

    core      swarm.core: random numbers, compile cache, kernels, errors, zenoh, the generic wire, tables
    worlds    world_server: one folder per world kind (its world, server, controller face), the world process
    agents    agents: the controllers and the agent process; of the worlds only a kind's face and the
              world kinds' declarations (world_server.WORLD_KINDS: plain data, found by the runtimes)
    runners   engines, envs, launcher, monitor, recording, review, scenario loading
    top       experiments, benchmarks, sweeps, the command line, the Python API

Imports are read by grimp from the source, those inside functions included.
"""

from __future__ import annotations

import importlib
import pkgutil
from graphlib import CycleError, TopologicalSorter
from pathlib import Path

import grimp
import pytest

PACKAGES = ("swarm", "agents", "world_server")
LAYERS = {  # module prefix -> layer (the longest prefix wins)
    "swarm": 0,
    "swarm.core": 0,
    "world_server": 1,
    "agents": 2,
    "swarm.engines": 3,
    "swarm.envs": 3,
    "swarm.launcher": 3,
    "swarm.world_process": 3,
    "swarm.monitor": 3,
    "swarm.recording": 3,
    "swarm.review": 3,
    "swarm.scenario": 3,
    "swarm.experiments": 4,
    "swarm.bench": 4,
    "swarm.cli": 4,
    "swarm.cli_arena": 4,
    "swarm.cli_reproduce": 4,
    "swarm.cli_sweep": 4,
    "swarm.sweeps": 4,
    "swarm.cli_grid": 4,
    "swarm.cli_check": 4,
    "swarm.api": 4,
    "swarm.__main__": 4,
}
NAMES = ("core", "worlds", "agents", "runners", "top")


def layer_of(module: str) -> int:
    if module == "swarm":  # the package's own face: `swarm.run` and the rest of the Python API, loaded when used
        return LAYERS["swarm.api"]
    prefix = max((p for p in LAYERS if module == p or module.startswith(p + ".")), key=len, default=None)
    if prefix is None:
        raise AssertionError(f"{module} is in no layer: add its package to LAYERS in {__file__}")
    return LAYERS[prefix]


def is_face(module: str) -> bool:
    """A world kind's controller face (world_server.<kind>.face...): what its controllers may import."""
    parts = module.split(".")
    return len(parts) >= 3 and parts[0] == "world_server" and parts[2] == "face"


def is_declaration(module: str) -> bool:
    """The world kinds' registry (world_server) or a kind's declaration (world_server.<kind>, its
    package's __init__: a WorldKindSpec, plain data): what the agent runtimes may read to find theirs."""
    parts = module.split(".")
    return parts == ["world_server"] or (
        len(parts) == 2 and parts[0] == "world_server" and (WORLDS / parts[1] / "__init__.py").is_file()
    )


WORLDS = Path(__file__).resolve().parent.parent / "world_server"


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph(*PACKAGES, cache_dir=None)


def imports(graph) -> list[tuple[str, str]]:
    return sorted(
        (m, t)
        for m in graph.modules
        for t in graph.find_modules_directly_imported_by(m)
        if t.split(".")[0] in PACKAGES and t != m
    )


def upward(graph) -> set[tuple[str, str]]:
    """Imports of a higher layer, and agents' imports of a world beyond its face."""
    found = set()
    for m, t in imports(graph):
        lm, lt = layer_of(m), layer_of(t)
        if lt > lm or (NAMES[lm] == "agents" and NAMES[lt] == "worlds" and not (is_face(t) or is_declaration(t))):
            found.add((m, t))
    return found


def test_no_module_imports_upward(graph):
    found = sorted(upward(graph))
    assert not found, "upward imports (turn them around, or move the code to the layer it belongs to):\n" + "\n".join(
        f"  {m} ({NAMES[layer_of(m)]}) -> {t} ({NAMES[layer_of(t)]})" for m, t in found
    )


def test_no_import_cycles(graph):
    deps: dict[str, set[str]] = {m: set() for m in graph.modules}
    for m, t in imports(graph):
        deps[m].add(t)
    # A package imports its __init__'s children only by name: a module and its own package are not a cycle.
    for m in deps:
        deps[m] -= {p for p in deps[m] if m.startswith(p + ".")}
    try:
        TopologicalSorter(deps).prepare()
    except CycleError as exc:
        raise AssertionError(f"an import cycle: {' -> '.join(exc.args[1])}") from None


def test_every_module_imports():
    """A module moved or renamed without its importers fails here, not in a user's run."""
    failed = []
    for name in PACKAGES:
        package = importlib.import_module(name)
        for info in pkgutil.walk_packages(package.__path__, f"{name}."):
            if info.name.endswith("__main__"):
                continue
            try:
                importlib.import_module(info.name)
            except Exception as exc:
                failed.append(f"{info.name}: {exc!r}")
    assert not failed, "\n".join(failed)


def test_the_layer_table_checks_what_it_claims(graph):
    """The rules themselves: an import from agents into a world's insides is upward, into its face is not."""
    assert layer_of("swarm.core.rng") == 0 and layer_of("swarm.cli") == 4 and layer_of("swarm") == 4  # the API
    assert is_face("world_server.grid.face.layout") and not is_face("world_server.grid.world")
    assert ("agents.controllers.grid.dispatch", "world_server.grid.face.layout") not in upward(graph)
    assert is_declaration("world_server") and is_declaration("world_server.arena")
    assert not is_declaration("world_server.arena.world") and not is_declaration("world_server.server")


def test_the_compile_cache_is_keyed_on_every_source_file():
    from swarm.core import jitcache

    files = {p.as_posix() for p in jitcache.source_files()}
    for path in ("swarm/core/jitcache.py", "agents/controllers/grid/dispatch.py", "world_server/grid/world.py"):
        assert any(f.endswith(path) for f in files), path


def test_an_agent_process_starts_without_numba_or_scipy():
    """`swarm agent` imports the command line and the runtimes: neither may pull a world kind's
    kernels in (an agent process runs the ahead-of-time build, under 80 MB)."""
    import subprocess
    import sys

    child = ("import sys, swarm.cli, agents.runtimes, agents.controllers; agents.controllers.CONTROLLERS.names(); "
             "import world_server; [world_server.WORLD_KINDS[k.name] for k in world_server.WORLD_KINDS]; "
             "swarm.cli.build_parser(); "
             "print(sorted({m.split('.')[0] for m in sys.modules} & {'numba', 'scipy', 'rerun'}))")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "[]", out.stdout + out.stderr[-2000:]
