"""The package's layering, read from the source with ``ast``: every import of every module of ``src/rocketmc``
(at module level, inside functions and under ``TYPE_CHECKING`` alike, relative ones resolved) goes to the
module's own layer or a lower one, and no modules import each other in a circle.

Layers, by package (a module's layer is its package's, whatever files the package holds), lowest first: the
root's utilities (``rocketmc/__init__.py``, ``errors.py``, ``files.py``, ``pytree.py``), math, the environment and
the dynamics, the aerodynamics and the sensors, GNC, the simulation, campaigns, analysis, the benchmark, the CLI.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).parents[1] / "src"
PACKAGE = "rocketmc"
LAYERS = [
    {"root"},
    {"math"},
    {"env", "dynamics"},
    {"aero", "sensors"},
    {"gnc"},
    {"sim"},
    {"campaign"},
    {"analysis"},
    {"bench"},
    {"cli"},
]
"""Lowest first: a module may import from its own layer and the ones below."""
ROOT_MODULES = {"errors", "files", "pytree"}
"""The root's utilities: top-level modules of the root layer (with the package's ``__init__``)."""
RANK = {group: rank for rank, groups in enumerate(LAYERS) for group in groups}


def module_files() -> dict[str, Path]:
    """Dotted name -> file of every module of the package (a package's ``__init__`` under the package's name)."""
    modules = {}
    for path in sorted((SRC / PACKAGE).rglob("*.py")):
        parts = path.relative_to(SRC).with_suffix("").parts
        modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return modules


MODULES = module_files()


def imports(name: str, path: Path) -> set[str]:
    """The modules of the package that module ``name`` (file ``path``) imports, anywhere in its body: for
    ``from X import y``, ``X.y`` when that is a module, else ``X``."""
    is_package = path.name == "__init__.py"
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".")[: len(name.split(".")) - node.level + (1 if is_package else 0)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module
            targets = [f"{source}.{alias.name}" if f"{source}.{alias.name}" in MODULES else source for alias in node.names]
        else:
            continue
        found.update(target for target in targets if target == PACKAGE or target.startswith(PACKAGE + "."))
    return found


GRAPH = {name: imports(name, path) for name, path in MODULES.items()}


def layer(name: str) -> str:
    """The layer group of a module: its package under ``rocketmc``, ``root`` for the root's utilities."""
    parts = name.split(".")
    if len(parts) == 1 or (len(parts) == 2 and parts[1] in ROOT_MODULES):
        return "root"
    return parts[1]


def test_every_module_has_a_layer():
    """A new package or top-level module is placed in ``LAYERS`` (or ``ROOT_MODULES``) before it is used."""
    unplaced = sorted(name for name in MODULES if layer(name) not in RANK)
    assert not unplaced, f"modules of no layer (add their package to LAYERS): {unplaced}"


def test_every_import_resolves_to_a_module():
    """The resolution the other tests rely on: every import of the package names one of its modules."""
    unknown = sorted((name, target) for name, targets in GRAPH.items() for target in targets if target not in MODULES)
    assert not unknown, unknown


@pytest.mark.parametrize("name", sorted(MODULES))
def test_imports_go_down_the_layers(name):
    upward = sorted(t for t in GRAPH[name] if t in MODULES and RANK.get(layer(t), -1) > RANK.get(layer(name), -1))
    assert not upward, f"{name} ({layer(name)}) imports from a higher layer: {[(t, layer(t)) for t in upward]}"


def test_no_import_cycle():
    """Depth-first search for a back edge; the cycle found is reported as its modules in order."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(name: str) -> list[str] | None:
        state[name] = 1
        path.append(name)
        for target in sorted(GRAPH.get(name, ())):
            if state.get(target) == 1:
                return path[path.index(target) :] + [target]
            if target not in state and (cycle := visit(target)) is not None:
                return cycle
        path.pop()
        state[name] = 2
        return None

    for name in sorted(MODULES):
        if name not in state:
            cycle = visit(name)
            assert cycle is None, " -> ".join(cycle)


def test_the_resolution_sees_relative_and_function_level_imports():
    """The parser finds what the tests above need: a relative import at module level and one inside a function."""
    assert "rocketmc.campaign.record" in GRAPH["rocketmc.campaign.model"]  # from .record import Campaign
    assert "rocketmc.campaign" in GRAPH["rocketmc.cli"]  # from .campaign import ..., inside the commands
