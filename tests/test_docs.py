"""The repository points only inside itself: no text file names a design note, a data folder or a tracker
entry that lives elsewhere (the notes the code cites are vendored as docs/gnc.md and docs/lynx.md), and
every "docs/gnc.md §n" names a section the note has. The docs hold together: every relative link of the README
and of docs/ resolves (file and heading anchor), docs/index.md lists every page, and the code's imports keep to
docs/architecture.md's floors. Reads text only: nothing is imported or flown."""

from __future__ import annotations

import ast
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
FOLDERS = ("src", "tests", "docs", "campaigns", "notebooks", "benchmarks", ".ci")
ROOT_FILES = ("README.md", "Makefile", "pyproject.toml")
SUFFIXES = {".py", ".md", ".toml", ".ipynb", ".cfg", ".txt", ".sh", ""}

# Each pattern is written so that it does not match its own source line.
OUTSIDE = re.compile(
    r"GNC\.md|LYNX\.md|ARCHITECTURE\.md|STYLE\.md|PERFORMANCE_NOTES\.md"  # the notes outside the repository
    r"|\.\./shared|/work/(?:shared|wt|main)"  # paths out of the repository
    r"|\b[Ii]ssues?\s+#?[0-9]"  # tracker entries by number, also across a line break
)
GNC_SECTION = re.compile(r"gnc\.md §\s*([0-9]+)(?:\s*-\s*([0-9]+))?")


def text_files(root: Path) -> list[Path]:
    """The repository's text files under ``root``: the named folders' files by suffix (no caches, no egg-info that
    the install writes), the root's."""
    files = [root / name for name in ROOT_FILES]
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*")):
            built = any(part == "__pycache__" or part.endswith(".egg-info") for part in path.parts)  # install's
            if path.is_file() and path.suffix in SUFFIXES and not built:
                files.append(path)
    return files


def pointers_outside(root: Path) -> list[str]:
    """``file:line: match`` for every pointer outside the repository in the text files under ``root``."""
    found = []
    for path in text_files(root):
        text = path.read_text(encoding="utf-8", errors="replace")
        for match in OUTSIDE.finditer(text):
            line = text.count("\n", 0, match.start()) + 1
            found.append(f"{path.relative_to(root)}:{line}: {match.group(0)!r}")
    return found


def test_nothing_points_outside_the_repository():
    found = pointers_outside(REPO)
    assert not found, "pointers outside the repository (vendor the facts into docs/):\n" + "\n".join(found)


def test_the_scan_reads_the_files_that_cite_the_notes():
    # The scan must cover the code, the tests, the docs and the campaigns, or the test above passes vacuously.
    names = {path.relative_to(REPO).as_posix() for path in text_files(REPO)}
    assert {"README.md", "src/rocketmc/gnc/guidance.py", "tests/gnc/test_design.py", "docs/validation.md",
            "campaigns/lynx_ballistic_gnc_1s.toml", "notebooks/landing_ellipses.ipynb"} <= names  # fmt: skip


def test_every_gnc_section_cited_exists():
    sections = {int(n) for n in re.findall(r"^## ([0-9]+)\.", (REPO / "docs" / "gnc.md").read_text(), re.M)}
    assert sections == set(range(1, 7))
    cited = set()
    for path in text_files(REPO):
        for first, last in GNC_SECTION.findall(path.read_text(encoding="utf-8", errors="replace")):
            cited |= set(range(int(first), int(last or first) + 1))
    assert cited and cited <= sections, f"sections cited but not in docs/gnc.md: {sorted(cited - sections)}"


LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")  # [text](target) and ![alt](target); a target has no spaces
FENCE = re.compile(r"^(```|~~~)")
HEADING = re.compile(r"^(#{1,6})\s+(.+?)\s*#*\s*$")


def markdown_pages(root: Path) -> list[Path]:
    """The pages whose links must resolve: the README and every page of docs/."""
    return [root / "README.md", *sorted((root / "docs").glob("*.md"))]


def prose_lines(text: str) -> list[str]:
    """The lines of a markdown text outside fenced code blocks."""
    lines, fenced = [], False
    for line in text.splitlines():
        if FENCE.match(line.strip()):
            fenced = not fenced
        elif not fenced:
            lines.append(line)
    return lines


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: its text (a link's text, not its target), lower case, every character but
    letters, digits, ``_``, ``-`` and spaces dropped (backticks, punctuation, symbols), each space a ``-``."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)
    return re.sub(r"[^\w\- ]", "", text.lower()).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    """The anchors of a page's headings, repeated slugs numbered as GitHub numbers them (``x``, ``x-1``, ...)."""
    seen: dict[str, int] = {}
    found = set()
    for line in prose_lines(page.read_text(encoding="utf-8")):
        match = HEADING.match(line)
        if match:
            base = slug(match.group(2))
            n = seen.get(base, 0)
            seen[base] = n + 1
            found.add(base if n == 0 else f"{base}-{n}")
    return found


def broken_links(root: Path) -> list[str]:
    """``page: target (why)`` for every relative link of ``markdown_pages`` whose file, or heading anchor in a
    markdown file, does not exist. A link's text may run over lines."""
    broken = []
    for page in markdown_pages(root):
        for target in LINK.findall("\n".join(prose_lines(page.read_text(encoding="utf-8")))):
            if re.match(r"[a-z][a-z0-9+.-]*:", target, re.I):  # https:, mailto:: not relative
                continue
            path, _, anchor = target.partition("#")
            file = (page.parent / path).resolve() if path else page
            where = f"{page.relative_to(root)}: {target}"
            if not file.exists():
                broken.append(f"{where} (no such file)")
            elif anchor and file.suffix == ".md" and anchor not in anchors(file):
                broken.append(f"{where} (no heading with that anchor)")
    return broken


def test_the_slug_is_githubs():
    assert slug("The flight record (`rocketmc fly`)") == "the-flight-record-rocketmc-fly"
    assert slug("The thesis's Monte Carlo") == "the-thesiss-monte-carlo"
    assert slug("Navigation health: `navigation_diverged`") == "navigation-health-navigation_diverged"
    assert slug("A 3° canard pitch step at t = 4 s") == "a-3-canard-pitch-step-at-t--4-s"


def test_every_relative_link_resolves():
    broken = broken_links(REPO)
    assert not broken, "links to files or headings that do not exist:\n" + "\n".join(broken)


def test_the_link_check_sees_a_broken_link(tmp_path):
    # A README with a good and two broken links, a docs page with a heading: only the broken two are reported.
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "page.md").write_text("# A page\n\n## Some heading (`code`)\n```\n## not a heading\n```\n")
    (tmp_path / "README.md").write_text("[ok](docs/page.md#some-heading-code) [gone](docs/none.md) [over\ntwo "
                                        "lines](docs/page.md#not-a-heading) [web](https://example.org)\n")
    assert broken_links(tmp_path) == ["README.md: docs/none.md (no such file)",  # the fenced "heading" is none
                                      "README.md: docs/page.md#not-a-heading (no heading with that anchor)"]


def test_the_index_lists_every_page():
    index = REPO / "docs" / "index.md"
    listed = {(index.parent / target.partition("#")[0]).resolve() for target in LINK.findall(index.read_text())}
    pages = {page.resolve() for page in (REPO / "docs").glob("*.md") if page != index}
    missing = sorted(page.name for page in pages - listed)
    assert not missing, f"docs/index.md does not list: {missing}"


FLOOR_ROW = re.compile(r"^\| (\d+) \| ([^|]+) \|", re.M)
ROOT_PACKAGE = REPO / "src" / "rocketmc"


def floors() -> dict[str, int]:
    """docs/architecture.md's floors (the table of its section "Floors"): package or root module name -> floor."""
    text = (REPO / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text.partition("\n## Floors")[2].partition("\n## ")[0]
    table = FLOOR_ROW.findall(section)
    return {name: int(floor) for floor, names in table for name in re.findall(r"`(\w+)`", names)}


def imported_units(path: Path) -> set[str]:
    """The packages and root modules of rocketmc that the module at ``path`` imports (relative or absolute; a name
    imported from the root package, such as ``__version__``, counts as ``__init__``)."""
    parts = path.relative_to(ROOT_PACKAGE).with_suffix("").parts
    package = list(parts[:-1])  # the module's package, from the root
    units = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package[: len(package) - (node.level - 1)] + (node.module.split(".") if node.module else [])
            names = [base[0]] if base else [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("rocketmc"):
            base = node.module.split(".")[1:]
            names = [base[0]] if base else [alias.name for alias in node.names]
        elif isinstance(node, ast.Import):
            names = [alias.name.split(".")[1] for alias in node.names if alias.name.startswith("rocketmc.")]
        else:
            continue
        units |= {name if (ROOT_PACKAGE / name).is_dir() or (ROOT_PACKAGE / f"{name}.py").is_file() else "__init__"
                  for name in names}  # fmt: skip
    return units


def test_every_import_goes_down_a_floor():
    floor = floors()
    packages = {init.parent.name for init in ROOT_PACKAGE.glob("*/__init__.py")}
    units = packages | {module.stem for module in ROOT_PACKAGE.glob("*.py")}
    assert units <= set(floor), f"on no floor of docs/architecture.md: {sorted(units - set(floor))}"
    upward = []
    for path in sorted(ROOT_PACKAGE.rglob("*.py")):
        own = path.relative_to(ROOT_PACKAGE).with_suffix("").parts[0]
        for unit in sorted(imported_units(path) - {own}):
            if floor[unit] >= floor[own]:
                upward.append(f"{path.relative_to(REPO)} ({own}, floor {floor[own]}): {unit} (floor {floor[unit]})")
    assert not upward, "imports that do not go down a floor (docs/architecture.md):\n" + "\n".join(upward)
