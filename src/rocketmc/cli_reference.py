"""The reference of every ``rocketmc`` command and option, generated from the argument parser (``cli.build_parser``)
so that it cannot drift from it. Regenerate the committed page with

    python -m rocketmc.cli_reference > docs/cli_reference.md

(tests/test_cli_reference.py fails until the page equals this module's output)."""

from __future__ import annotations

import argparse
from collections.abc import Iterator

from .cli import build_parser

HEADER = """# Command-line reference

Every `rocketmc` command and option, generated from the argument parser (`python -m rocketmc.cli_reference >
docs/cli_reference.md`; a test fails when this page is stale). What the commands are for, with examples:
[guide.md](guide.md). Errors you can act on are one line, `rocketmc: error: ...`, naming the option, field or file,
with exit code 2.
"""


def _commands(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], str, argparse.ArgumentParser]]:
    """(command words, help, parser) of every leaf command under ``parser``, in the parser's order."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help for choice in action._choices_actions}
            for name, sub in action.choices.items():
                if any(isinstance(a, argparse._SubParsersAction) for a in sub._actions):
                    yield from _commands(sub, (*path, name))
                else:
                    yield (*path, name), helps.get(name) or "", sub


def _option(action: argparse.Action) -> str:
    """A table row: the option's spellings with its value, and its help with the choices and default."""
    if action.option_strings:
        metavar = "" if action.nargs == 0 else " " + " ".join(_metavars(action))
        names = ", ".join(f"`{o}{metavar}`" for o in action.option_strings)
    else:
        names = f"`{' '.join(_metavars(action))}`"
    text = (action.help or "") % {"default": action.default} if action.help else ""
    if action.choices and not action.metavar:
        text = text.rstrip(".") + f". One of: {', '.join(map(str, action.choices))}."
    if action.required and action.option_strings:
        text = text.rstrip(".") + ". Required."
    text = " ".join(text.split()).replace("<", "&lt;").replace("|", "\\|")  # Markdown table cells
    return f"| {names} | {text} |"


def _metavars(action: argparse.Action) -> list[str]:
    if isinstance(action.metavar, tuple):
        return list(action.metavar)
    if action.metavar:
        return [action.metavar]
    if action.choices:
        return ["{" + ",".join(map(str, action.choices)) + "}"]
    return [action.dest.upper()]


def reference() -> str:
    """The Markdown page: per command, its purpose, its usage line and its options."""
    parser = build_parser()
    parser.formatter_class = lambda prog: argparse.HelpFormatter(prog, width=100)
    parts = [HEADER]
    for words, help_text, sub in _commands(parser):
        sub.formatter_class = lambda prog: argparse.HelpFormatter(prog, width=100)
        usage = sub.format_usage().removeprefix("usage: ").strip()
        parts.append(f"## rocketmc {' '.join(words)}\n\n{help_text[0].upper() + help_text[1:]}.\n")
        if sub.description and sub.description != help_text:
            parts.append(" ".join(sub.description.split()) + "\n")
        parts.append(f"```\n{usage}\n```\n")
        rows = [_option(a) for a in sub._actions if not isinstance(a, argparse._HelpAction)]
        parts.append("| argument | meaning |\n|---|---|\n" + "\n".join(rows) + "\n")
    return "\n".join(parts)


if __name__ == "__main__":
    print(reference(), end="")
