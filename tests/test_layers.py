"""No import circle in the package, read from the source with ``ast``: every import of every module of
``src/rocketmc`` (at module level, inside functions and under ``TYPE_CHECKING`` alike, relative ones resolved) is
followed, and no modules import each other in a circle. That every import goes down the floors of
docs/architecture.md is checked by tests/test_docs.py, against the page's table. And pyflakes reads every file for
a name used but never defined, or imported and never used.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).parents[1] / "src"
PACKAGE = "rocketmc"
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


def test_every_import_resolves_to_a_module():
    """The resolution the other tests rely on: every import of the package names one of its modules."""
    unknown = sorted((name, target) for name, targets in GRAPH.items() for target in targets if target not in MODULES)
    assert not unknown, unknown


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


def test_no_private_name_is_imported_from_another_module():
    """A leading underscore means 'this module's own': another module of the package that needs the name gets it
    under a public one (``from .plots import save_figure``, not ``_save``)."""
    private = sorted(
        (name, f"{node.module}.{alias.name}")
        for name, path in MODULES.items()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path)))
        if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith(PACKAGE))
        for alias in node.names
        if alias.name.startswith("_") and alias.name != "__version__"
    )
    assert not private, private


class _Findings:
    """A pyflakes reporter that keeps what it is told."""

    def __init__(self):
        self.found: list = []

    def flake(self, message):
        self.found.append(message)

    def unexpectedError(self, filename, message):
        self.found.append(f"{filename}: {message}")

    def syntaxError(self, filename, message, lineno, offset, text):
        self.found.append(f"{filename}:{lineno}: {message}")


def test_pyflakes_finds_no_undefined_name_and_no_unused_import():
    """pyflakes over the package, the tests and the benchmarks: a name used but never imported fails here, not on
    the one path no other test walks (it once did: a parachute flight's printed summary). Left alone: a package
    ``__init__``'s re-exports (``from .x import y as y``) and an import kept for its side effect, marked noqa."""
    from pyflakes.api import checkRecursive
    from pyflakes.messages import UnusedImport

    def kept(message) -> bool:
        path = Path(message.filename)
        line = path.read_text(encoding="utf-8").splitlines()[message.lineno - 1]
        return isinstance(message, UnusedImport) and (path.name == "__init__.py" or "noqa" in line)

    findings = _Findings()
    checkRecursive([str(SRC), str(SRC.parent / "tests"), str(SRC.parent / "benchmarks")], findings)
    problems = [str(m) for m in findings.found if isinstance(m, str) or not kept(m)]
    assert not problems, "\n".join(problems)
