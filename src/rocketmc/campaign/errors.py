"""The error of a campaign that cannot be flown, and how a refused value is shown in its message."""

from ..errors import RocketmcError


class ConfigError(RocketmcError, ValueError):
    """A campaign that cannot be flown; the message is one line naming the field."""


SHOWN_INPUT_LENGTH = 60
"""Characters of a refused value that an error message shows (a 10 000-character name is not repeated)."""


def shown(value) -> str:
    """``repr(value)``, cut to ``SHOWN_INPUT_LENGTH`` characters with the full length said."""
    text = repr(value)
    return text if len(text) <= SHOWN_INPUT_LENGTH else f"{text[:SHOWN_INPUT_LENGTH]}... ({len(text)} characters)"
