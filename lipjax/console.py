"""Command-line plumbing shared by `lipjax` and the `python -m experiments.*` entry points.

A problem the user can fix (a bad argument, an unreadable or mismatched file, ...) is printed as one line,
"PROG: error: ...", with exit status 1; warnings as one line "PROG: warning: ..."; argparse usage errors as one
line too, with exit status 2. LIPJAX_DEBUG=1 shows the Python traceback instead.

    PROG = f"python -m {__spec__.name}"          # the same name when imported and when run with -m
    ...
    if __name__ == "__main__":
        sys.exit(run_main(PROG, main))
"""
from __future__ import annotations

import argparse
import functools
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from typing import Any

# What a user's mistake raises: InputError, DatasetError, ModelFileError, CheckpointError are ValueErrors;
# a missing or unreadable file is an OSError.
USER_ERRORS = (ValueError, OSError)


class UserError(Exception):
    """A problem the user can fix, found by a command line itself; printed as one line, no traceback."""


class ArgumentParser(argparse.ArgumentParser):
    """argparse with a one-line usage error: "PROG: error: MESSAGE (see PROG --help)", exit status 2."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text}")
    return value


def argument_type(parse: Callable[[str], Any]) -> Callable[[str], Any]:
    """`parse` as an argparse type: its ValueError becomes the usage error's message (argparse would otherwise print
    only "invalid <name> value")."""

    @functools.wraps(parse)
    def convert(text: str):
        try:
            return parse(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    return convert


def positive_int_list(text: str) -> list[int]:
    """argparse type: comma-separated integers >= 1, e.g. "1,2,3,5"."""
    try:
        return [positive_int(item) for item in text.split(",")]
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated positive integers, e.g. 1,2,3, got {text!r}") from None


def one_line(exc: BaseException) -> str:
    """The exception's message on one line (its lines joined by " | ")."""
    lines = [line.strip() for line in (str(exc) or type(exc).__name__).splitlines() if line.strip()]
    return " | ".join(lines)


def say(line: str) -> None:
    """A status line for the user, on stderr (stdout stays for results)."""
    print(line, file=sys.stderr)


def warn(prog: str, message: str) -> None:
    print(f"{prog}: warning: {message}", file=sys.stderr)


def run_main(prog: str, main: Callable[[Sequence[str] | None], object], argv: Sequence[str] | None = None) -> int:
    """Runs main(argv) and returns the exit status: 0, 1 for a user error (one line), 2 for a usage error, 130 on
    Ctrl-C. Python warnings raised meanwhile print as one line each."""
    def show(message, category, filename, lineno, file=None, line=None):
        warn(prog, str(message))

    with warnings.catch_warnings():
        warnings.showwarning = show
        try:
            result = main(argv)
        except SystemExit as exit_:  # argparse: --help (0) or a usage error it has printed (2)
            return exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else 2)
        except (UserError, *USER_ERRORS) as exc:
            if os.environ.get("LIPJAX_DEBUG"):
                raise
            print(f"{prog}: error: {one_line(exc)}", file=sys.stderr)
            return 1
        except KeyboardInterrupt:
            print(f"{prog}: interrupted", file=sys.stderr)
            return 130
    return result if isinstance(result, int) else 0
