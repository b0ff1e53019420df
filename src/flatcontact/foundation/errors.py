"""Errors that are the user's to fix.

Raise :class:`InputError` for bad input (a wrong value, a missing file, a
malformed dataset). The CLI prints its message as one line, without a
traceback, and exits with status 2. The message names the field, file or
value and says what was expected.
"""


class InputError(ValueError):
    """Bad user input; the message is a single line that names what is wrong."""


def require(condition: bool, message: str) -> None:
    """Raise :class:`InputError` with ``message`` unless ``condition`` holds."""
    if not condition:
        raise InputError(message)
