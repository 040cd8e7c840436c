"""Warnings attributed to the user's own line, wherever in rockdem they are raised."""

from __future__ import annotations

import os
import sys
import warnings

_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def warn_user(message: str, category: type[Warning] = UserWarning) -> None:
    """``warnings.warn(message, category)`` with the stack level of the first caller outside the
    rockdem package (the user's script, notebook cell or test), so that the warning names the
    line that asked for the thing warned about. Called from rockdem alone (the command line), it
    names the outermost rockdem frame."""
    frame = sys._getframe(1)
    level = 2  # warn's stacklevel of this function's caller
    while frame.f_back is not None and os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE):
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=level)
