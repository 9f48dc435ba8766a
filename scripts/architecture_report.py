"""The architecture's numbers: import cycles, upward imports, generic modules that name a controller,
generic modules that branch on a world kind, and functions over 60 lines.

    python scripts/architecture_report.py          # a table; tests/test_layers.py enforces the first two

Generic modules are the ones every controller passes through: the world process and servers, the
agent runtimes, the engines, the recorder, the review, the command line and the scenario loader.
A module "names a controller" when a controller's name appears in it as a string literal.  A module
"branches on a world kind" when it compares with a kind's name (`kind == "arena"`, `kind in (...)`) or
tests a predicate named after a kind (`is_arena(...)`); a world kind's own modules (its folder
world_server/<kind>/, and the modules named after it: swarm/engines/<kind>.py, agents/<kind>_runtime.py,
swarm/cli_<kind>.py, ...) are left out, since they are that kind's.
Kernels (functions compiled with numba) are left out of the length count: one loop each by design.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

GENERIC = ("world_server/server.py", "world_server/grid/server.py", "world_server/arena/server.py",
           "agents/runtime.py", "agents/grid_runtime.py", "agents/arena_runtime.py", "agents/runtimes.py",
           "swarm/world_process.py", "swarm/engines", "swarm/launcher.py", "swarm/monitor.py", "swarm/recording",
           "swarm/review", "swarm/cli.py", "swarm/cli_arena.py", "swarm/cli_grid.py", "swarm/cli_reproduce.py",
           "swarm/scenario.py")  # fmt: skip
LONG = 60


def python_files() -> list[Path]:
    return sorted(p for pkg in ("swarm", "agents", "world_server") for p in (ROOT / pkg).rglob("*.py"))


def is_kernel(node: ast.FunctionDef) -> bool:
    return any("njit" in ast.unparse(d) or "jit" in ast.unparse(d) for d in node.decorator_list)


def long_functions() -> list[tuple[int, str]]:
    out = []
    for path in python_files():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and not is_kernel(node):
                length = node.end_lineno - node.lineno + 1
                if length > LONG:
                    out.append((length, f"{path.relative_to(ROOT)}:{node.lineno} {node.name}"))
    return sorted(out, reverse=True)


def generic_naming_controllers() -> list[str]:
    from agents.controllers import CONTROLLERS

    names = set(CONTROLLERS.names())
    out = []
    for path in python_files():
        rel = path.relative_to(ROOT).as_posix()
        if not any(rel == g or rel.startswith(g + "/") for g in GENERIC):
            continue
        literals = {n.value for n in ast.walk(ast.parse(path.read_text())) if isinstance(n, ast.Constant)}
        if named := sorted(names & literals):
            out.append(f"{rel} ({', '.join(named)})")
    return out


def is_kinds_own(rel: str, kinds: set[str]) -> bool:
    """A module of one world kind: in its folder, or named after it (grid.py, arena_runtime.py, cli_arena.py)."""
    parts = rel.removesuffix(".py").split("/")
    return (parts[0] == "world_server" and len(parts) > 2 and parts[1] in kinds) or bool(
        kinds & set(parts[-1].split("_"))
    )


def generic_branching_on_a_kind() -> list[str]:
    from world_server import WORLD_KINDS

    kinds = set(WORLD_KINDS.names())
    predicates = {f"is_{k}" for k in kinds}
    out = []
    for path in python_files():
        rel = path.relative_to(ROOT).as_posix()
        if not any(rel == g or rel.startswith(g + "/") for g in GENERIC) or is_kinds_own(rel, kinds):
            continue
        found = []
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Compare):
                sides = [node.left, *node.comparators]
                named = {c.value for side in sides for c in ast.walk(side) if isinstance(c, ast.Constant)} & kinds
                found += [f"{node.lineno}: compares with {', '.join(sorted(named))}"] if named else []
            elif isinstance(node, ast.Call):
                name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
                found += [f"{node.lineno}: {name}()"] if name in predicates else []
        if found:
            out.append(f"{rel} ({'; '.join(found)})")
    return out


def main() -> None:
    import grimp
    from test_layers import PACKAGES, imports, upward

    graph = grimp.build_graph(*PACKAGES, cache_dir=None)
    from graphlib import CycleError, TopologicalSorter

    deps: dict[str, set[str]] = {m: set() for m in graph.modules}
    for m, t in imports(graph):
        if not m.startswith(t + "."):
            deps[m].add(t)
    try:
        TopologicalSorter(deps).prepare()
        cycles = "0"
    except CycleError as exc:
        cycles = f"at least 1: {' -> '.join(exc.args[1])}"
    ups = sorted(upward(graph))
    generic = generic_naming_controllers()
    branching = generic_branching_on_a_kind()
    longs = long_functions()
    print(f"modules: {len(graph.modules)}")
    print(f"import cycles (function-level imports included): {cycles}")
    print(f"upward imports: {len(ups)}" + "".join(f"\n  {m} -> {t}" for m, t in ups))
    print(f"generic modules naming a controller: {len(generic)}" + "".join(f"\n  {g}" for g in generic))
    print(f"generic modules that branch on a world kind: {len(branching)}" + "".join(f"\n  {b}" for b in branching))
    print(f"non-kernel functions over {LONG} lines: {len(longs)}" + "".join(f"\n  {n} {w}" for n, w in longs))


if __name__ == "__main__":
    main()
