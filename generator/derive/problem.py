"""The one problem record: what a command is asked about, read once from its text.

A text is one equation (one coordinate), a system (one equation per coordinate, separated by
``;``: any number n ≥ 1) or a preset's name (``duffing``, ``pendulum``, ``vdp``: the registry's
texts, :data:`derive.models.REGISTRY`).  :func:`read_problem` is the only place that splits a
text into its equations; the methods lower the record themselves — the polynomial form of any
n (:func:`derive.system.parse_system`: mass, damping, stiffness, force, drive), one
coordinate's analytic force (:func:`derive.models.oscillator`) — and a command's route to a
method asks the record, never the text (:data:`cli.COMMANDS`)."""

from __future__ import annotations

import re
from dataclasses import dataclass

SEPARATOR = ";"
# NOTE: between the equations of a system; the walker refuses it inside an equation.
NOTES_PRESET = "duffing"
# NOTE: the preset whose driven, damped form is the notes' eq. 10.60, the problem of driven,
# response, subharmonic, mixing and sweep without MODEL: its name there takes the notes' flags.


@dataclass(frozen=True)
class Problem:
    """A command's text as its equations: ``equations`` holds one per coordinate (a system),
    the one equation, or a preset's own equation (``preset`` its name); a name that is no
    preset (``generate driven``: an emitted module of the notes' driven Duffing) holds
    none."""

    text: str
    equations: tuple[str, ...]
    preset: str | None = None

    @property
    def size(self) -> int:
        """The number of coordinates (0 for a name that is no preset)."""
        return len(self.equations)

    @property
    def one_coordinate(self) -> bool:
        """One equation, a preset or a name: the one-coordinate kernels' fast path."""
        return self.size <= 1


def read_problem(text: str) -> Problem:
    """The :class:`Problem` of ``text``: a preset's name, or its equations as written (each
    stripped; an empty one stays, for its method's parser to refuse with its place)."""
    if re.fullmatch(r"\w+", text):  # no equation: a preset's name, or a name that is none
        from .models import NAME, registry_entry  # SymPy: only where a name is read

        entry = registry_entry(text) if NAME.fullmatch(text) else None
        return Problem(text, ()) if entry is None else Problem(text, (entry.equation,),
                                                               entry.name)
    return Problem(text, tuple(part.strip() for part in text.split(SEPARATOR)))
