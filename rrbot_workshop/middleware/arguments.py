"""Checks of the arguments a learner hands the library's calls: one :class:`~rrbot_workshop.exceptions.ArgumentError`
that names the call, the argument and what would be valid, before anything changes.

ROS 2 refuses such values at its own boundaries (a parameter of the wrong type, a message field of the wrong type,
a negative duration); these helpers are that boundary for the Python calls.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from rrbot_workshop.exceptions import ArgumentError

__all__ = ["number", "whole_number", "callable_argument", "mapping", "name_list"]


def number(function: str, argument: str, value: Any, *, low: float | None = None, high: float | None = None,
           low_open: bool = False, finite: bool = True) -> float:
    """``value`` as a float, refused unless it is a real number (not a bool) within ``[low, high]``.

    Args:
        function: The call, for the message.
        argument: The argument's name, for the message.
        value: What was given.
        low: The smallest valid value (None: no bound).
        high: The largest valid value (None: no bound).
        low_open: ``low`` itself is not valid (``> low`` instead of ``>= low``).
        finite: NaN and infinities are refused.

    Raises:
        ArgumentError: If ``value`` is not a number, is NaN or infinite (with ``finite``) or out of bounds.
    """
    valid = "a finite number" if finite else "a number"
    if low is not None:
        valid += f" {'>' if low_open else '>='} {low:g}"
    if high is not None:
        valid += f"{' and' if low is not None else ''} <= {high:g}"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ArgumentError(function, argument, value, valid)
    try:
        result = float(value)
    except OverflowError:
        raise ArgumentError(function, argument, value, valid) from None
    if math.isnan(result) or (finite and math.isinf(result)):
        raise ArgumentError(function, argument, value, valid)
    if low is not None and (result < low or (low_open and result == low)):
        raise ArgumentError(function, argument, value, valid)
    if high is not None and result > high:
        raise ArgumentError(function, argument, value, valid)
    return result


def whole_number(function: str, argument: str, value: Any, *, low: int = 0, high: int | None = None) -> int:
    """``value`` as an int, refused unless it is a whole number (an int, not a bool) within ``[low, high]``.

    Raises:
        ArgumentError: If ``value`` is not an int or is out of bounds.
    """
    valid = f"a whole number >= {low}" + (f" and <= {high:,}" if high is not None else "")
    if isinstance(value, bool) or not isinstance(value, int):
        raise ArgumentError(function, argument, value, valid)
    if value < low or (high is not None and value > high):
        raise ArgumentError(function, argument, value, valid)
    return int(value)


def callable_argument(function: str, argument: str, value: Any, what: str = "a function") -> Any:
    """``value`` itself, refused unless it can be called.

    Raises:
        ArgumentError: If ``value`` is not callable.
    """
    if not callable(value):
        raise ArgumentError(function, argument, value, what)
    return value


def mapping(function: str, argument: str, value: Any, what: str = "a mapping (dict)",
            keys: type | tuple[type, ...] = str) -> Mapping[Any, Any]:
    """``value`` itself, refused unless it is a mapping whose keys are of type ``keys``; None is an empty one.

    Raises:
        ArgumentError: If ``value`` is not a mapping, or a key is of another type.
    """
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ArgumentError(function, argument, value, what)
    for key in value:
        if not isinstance(key, keys):
            raise ArgumentError(function, f"{argument}[{key!r}]", key, f"{what} with keys of type "
                                f"{keys.__name__ if isinstance(keys, type) else ' or '.join(k.__name__ for k in keys)}")
    return value


def name_list(function: str, argument: str, value: Any, *, single: bool = True) -> list[str]:
    """``value`` as a list of names (non-empty strings): a string is one name when ``single``.

    Raises:
        ArgumentError: If ``value`` is not an iterable of non-empty strings (a mapping and bytes are refused too).
    """
    valid = "a list of names (non-empty strings)" + (" or one name" if single else "")
    if isinstance(value, str):
        if single and value:
            return [value]
        raise ArgumentError(function, argument, value, valid)
    if isinstance(value, (bytes, Mapping)) or not isinstance(value, Iterable):
        raise ArgumentError(function, argument, value, valid)
    items = list(value)
    for index, item in enumerate(items):
        if not isinstance(item, str) or not item:
            raise ArgumentError(function, f"{argument}[{index}]", item, "a name (a non-empty string)")
    return items
