"""stdout that says so when it cannot be written: a full disk or device (``> /dev/full``), a closed
terminal.

A report printed to a stdout that cannot take it fails deep inside ``print`` or at the final flush
with an :class:`OSError` that names no file; the command line would blame a field of the rig for it.
:func:`guarded` wraps stdout so that such a failure is a :class:`StdoutFailed` instead, which the
command line prints as one line naming stdout and the operating system's reason (exit status 2, as
for any output that cannot be written). A closed pipe (``| head``) stays a :class:`BrokenPipeError`:
that is the reader's choice, not a failure (exit status 141).
"""

from __future__ import annotations

import errno
import sys
from contextlib import contextmanager


class StdoutFailed(Exception):
    """stdout could not be written; the message is the operating system's reason."""


class _Guard:
    """A text stream whose ``write`` and ``flush`` turn an OSError (but a closed pipe's) into
    :class:`StdoutFailed`; everything else is the wrapped stream's."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except OSError as exc:
            raise _failed(exc) from None

    def flush(self) -> None:
        try:
            self._stream.flush()
        except OSError as exc:
            raise _failed(exc) from None

    def __getattr__(self, name):
        return getattr(self._stream, name)


def _failed(exc: OSError) -> Exception:
    if isinstance(exc, BrokenPipeError) or exc.errno == errno.EPIPE:
        return exc
    return StdoutFailed(exc.strerror or str(exc))


@contextmanager
def guarded():
    """``sys.stdout`` wrapped by :class:`_Guard` inside the block, restored after it."""
    stream = sys.stdout
    sys.stdout = _Guard(stream)
    try:
        yield
    finally:
        sys.stdout = stream
