"""Errors the command line turns into one line: exit status 2 for bad input, 130 for an
interrupt."""


class InputError(ValueError):
    """Bad input: names what failed on which value."""


class DomainError(InputError):
    """A parameter outside a method's validity (no periodic orbit, beyond a series' radius)."""


class Interrupted(Exception):
    """Ctrl-C or SIGTERM stopped a long command: says what was saved and how to resume."""
