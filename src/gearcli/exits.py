"""How a ``gearcli`` command ends: one line on stderr per problem and an exit status.

Every failure that is not a bug ends in a status of its own, without a traceback: bad
input or an unwritable output 2 (:class:`~gearcli.errors.GearcliError`, one line per
problem), a full stdout 2, a closed pipe 141, Ctrl-C 130, SIGTERM 143 (temporary files
are removed first).  A stderr that cannot be written (``2>/dev/full``) loses the lines,
never the status.  Used by :mod:`gearcli.cli` only (the one module that imports typer).
"""
from __future__ import annotations

import functools
import os
import signal
import sys
import warnings
from contextlib import contextmanager
from typing import Iterator

import typer

from .errors import GearcliError, shown

EXIT_CHECK_FAILED = 1     # verify: a check failed
EXIT_BAD_INPUT = 2
EXIT_BROKEN_PIPE = 141    # 128 + SIGPIPE, what a shell reports for a writer killed by it
EXIT_INTERRUPTED = 130    # 128 + SIGINT
EXIT_TERMINATED = 143     # 128 + SIGTERM


def print_problems(lines: list[str]) -> None:
    """Write each problem line verbatim to stderr (no markup, no wrapping).

    A stderr that fails (full device, closed) never raises here: the lines are lost, the
    caller's exit status stands, and the stream is pointed at /dev/null so that the
    interpreter's final flush stays quiet.
    """
    try:
        for line in lines:
            typer.echo(line, err=True)
    except (OSError, ValueError):   # ENOSPC, EIO, EPIPE; ValueError: a closed file
        _silence(sys.stderr)


@contextmanager
def stderr_may_fail() -> Iterator[None]:
    """For a block that writes only informative text to stderr (the summary of a table
    written to stdout): a stderr that fails ends the block quietly (the stream pointed at
    /dev/null) instead of failing a run whose output was written."""
    try:
        yield
    except (OSError, ValueError):   # ENOSPC, EIO, EPIPE; ValueError: a closed file
        _silence(sys.stderr)


class Terminated(BaseException):
    """SIGTERM, raised as an exception so that every ``finally`` (temporary files) runs."""


def _raise_terminated(signum, frame):
    raise Terminated()


@contextmanager
def _sigterm_raises() -> Iterator[None]:
    try:
        old = signal.signal(signal.SIGTERM, _raise_terminated)
    except ValueError:   # not the main thread: leave signals alone
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def _silence(stream) -> None:
    """Point the descriptor of ``stream`` (stdout, stderr) at /dev/null, so that the
    interpreter's final flush of a broken or full stream does not print an error or
    change the exit status (no-op when the stream is not a file)."""
    try:
        fd = stream.fileno()
    except (AttributeError, OSError, ValueError):
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, fd)
    os.close(devnull)


@contextmanager
def bad_input_exits() -> Iterator[None]:
    """Turn every failure that is not a bug into one line on stderr and an exit status.

    :class:`~gearcli.errors.GearcliError` (bad input, an unwritable output): its lines
    (at most :data:`~gearcli.errors.MAX_SHOWN`, then a count of the rest), status 2.  A failing stdout (a full device): ``stdout: cannot write: ...``, status 2.
    A closed pipe (``gearcli ... | head -1``): no message, status 141.  Ctrl-C: one line,
    status 130; SIGTERM: one line, status 143 (temporary files are removed first).
    """
    try:
        with _sigterm_raises(), warnings.catch_warnings():
            # numpy's overflow/invalid-value warnings are not for users: every number
            # written is checked finite, and a non-finite one is an error
            warnings.simplefilter("ignore", RuntimeWarning)
            yield
            sys.stdout.flush()
    except GearcliError as exc:
        print_problems(shown(exc.lines()))
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except BrokenPipeError:
        _silence(sys.stdout)
        raise typer.Exit(EXIT_BROKEN_PIPE) from None
    except OSError as exc:   # readers report their own files; what is left is stdout
        _silence(sys.stdout)
        where = f"{exc.filename}: cannot access" if exc.filename else "stdout: cannot write"
        print_problems([f"{where}: {exc.strerror or exc}"])
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except KeyboardInterrupt:
        print_problems(["gearcli: interrupted"])
        raise typer.Exit(EXIT_INTERRUPTED) from None
    except Terminated:
        print_problems(["gearcli: terminated (SIGTERM)"])
        raise typer.Exit(EXIT_TERMINATED) from None


def reports_bad_input(command):
    """Decorator for commands: bad input is reported by :func:`bad_input_exits`."""
    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        with bad_input_exits():
            return command(*args, **kwargs)
    return wrapper
