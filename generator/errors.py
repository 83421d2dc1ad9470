"""Errors the command line turns into one line: exit status 2 for bad input, 130 for an
interrupt."""

import re

LONGEST_NUMBER = 24
# NOTE: a number longer than this many digits is shown by its ends and its length in an error
# line (``1000000000…0000 (401 digits)``): the line names the input without echoing it whole.


def clipped(message: str) -> str:
    """``message`` with every run of more than :data:`LONGEST_NUMBER` digits shortened to its
    first ten and last four digits and its length."""
    return re.sub(rf"\d{{{LONGEST_NUMBER + 1},}}",
                  lambda m: f"{m[0][:10]}…{m[0][-4:]} ({len(m[0])} digits)", message)


class InputError(ValueError):
    """Bad input: names what failed on which value."""


class DomainError(InputError):
    """A parameter outside a method's validity (no periodic orbit, beyond a series' radius)."""


class Interrupted(Exception):
    """Ctrl-C or SIGTERM stopped a long command: says what was saved and how to resume."""
