"""Errors the command line turns into one line and exit status 2."""


class InputError(ValueError):
    """Bad input: names what failed on which value."""


class DomainError(InputError):
    """A parameter outside a method's validity (no periodic orbit, beyond a series' radius)."""
