"""The one error type a user sees: a failure they can act on, said in one line."""


class RocketmcError(Exception):
    """A campaign, file, partial run or cluster that cannot be used, or a result that cannot be
    written; the message is one line naming the field or file. The CLI prints it and exits with 2."""
