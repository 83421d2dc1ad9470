"""The command line as a user runs it: ``python -m lindstedt ARGS`` in a fresh process."""

from __future__ import annotations

import subprocess
import sys


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    """``lindstedt *args`` (text output captured, no exception on a non-zero status)."""
    return subprocess.run([sys.executable, "-m", "lindstedt", *args], capture_output=True,
                          text=True, check=False, cwd=cwd)
