"""The command line as a user runs it.

``run`` calls ``lindstedt.cli.main`` in this process, its stdout and stderr captured and the
working folder changed for the call: the same parse, cost check, command and exit status as
``python -m lindstedt``, without a second of imports per call.  An exception that the command
line would print as a traceback propagates and fails the test outright.

``run_fresh`` starts ``python -m lindstedt`` in a new process: for what only a process shows
(the modules a command imports, signals, what an emitted module does on its first import)."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    """``lindstedt *args`` in-process (text output captured, no exception on a non-zero
    status)."""
    from lindstedt.cli import main

    out, err = io.StringIO(), io.StringIO()
    with (contextlib.chdir(cwd or os.getcwd()), contextlib.redirect_stdout(out),
          contextlib.redirect_stderr(err)):
        try:
            status = main([str(a) for a in args])
        except SystemExit as exc:  # argparse's own errors and --help, --version
            status = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    return subprocess.CompletedProcess([sys.executable, "-m", "lindstedt", *args], status,
                                       out.getvalue(), err.getvalue())


def run_fresh(*args: str, cwd=None) -> subprocess.CompletedProcess:
    """``lindstedt *args`` in a fresh process (text output captured, no exception on a
    non-zero status)."""
    return subprocess.run([sys.executable, "-m", "lindstedt", *[str(a) for a in args]],
                          capture_output=True, text=True, check=False, cwd=cwd)
