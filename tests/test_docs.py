"""The repository points only inside itself: no text file names a design note, a data folder or a tracker
entry that lives elsewhere (the notes the code cites are vendored as docs/gnc.md and docs/lynx.md), and
every "docs/gnc.md §n" names a section the note has. Reads text only: nothing is imported or flown."""

from __future__ import annotations

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
