"""Warnings attributed to the user's own line, wherever in rockdem they are raised."""

from __future__ import annotations

import contextlib
import os
import sys
import warnings

_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep
_CONTEXTLIB = os.path.abspath(contextlib.__file__)


def warn_user(message: str, category: type[Warning] = UserWarning) -> None:
    """``warnings.warn(message, category)`` with the stack level of the first caller outside the
    rockdem package (the user's script, notebook cell or test), so that the warning names the
    line that asked for the thing warned about (frames of :mod:`contextlib` are passed too: a
    rockdem context manager's exit). Called from rockdem alone (the command line), it names the
    outermost rockdem frame."""
    frame = sys._getframe(1)
    level = 2  # warn's stacklevel of this function's caller
    while frame.f_back is not None and _inside(os.path.abspath(frame.f_code.co_filename)):
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level)


def _inside(path: str) -> bool:
    """Whether a frame of this file is rockdem's own (or contextlib's, between two of rockdem's)."""
    return path.startswith(_PACKAGE) or path == _CONTEXTLIB
