"""docs/cli_reference.md is the argument parser's reference, regenerated; it names every command and option."""

import argparse

from rocketmc.cli import build_parser
from rocketmc.cli_reference import reference

from .conftest import REPO


def test_the_page_is_current():
    """Regenerate with `python -m rocketmc.cli_reference > docs/cli_reference.md`."""
    assert (REPO / "docs" / "cli_reference.md").read_text() == reference()


def test_every_option_of_every_command_is_there():
    text = reference()
    commands = [a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)][0]
    for name, sub in commands.choices.items():
        assert f"## rocketmc {name}" in text
        options = [o for a in sub._actions for o in a.option_strings if o != "-h" and o != "--help"]
        assert all(f"`{o}" in text for o in options), name
