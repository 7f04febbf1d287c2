"""Exceptions raised by granulate.

``InputError`` (a ``ValueError``) means the input is wrong and says how to fix it;
``InstabilityError`` (a ``RuntimeError``) means the time integration blew up. Both are raised
by the C++ core and by the Python layer alike.
"""

from granulate._core import InputError, InstabilityError


class GranulateWarning(UserWarning):
    """Something is allowed but probably not what you want (e.g. dt above the stable estimate)."""


__all__ = ["GranulateWarning", "InputError", "InstabilityError"]
