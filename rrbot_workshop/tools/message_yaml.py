"""Messages as ``ros2 topic`` reads and writes them: YAML in, YAML out, stamps as ``sec``/``nanosec``.

The library keeps times as float seconds; ROS 2 messages carry ``builtin_interfaces/Time`` and
``Duration`` (``sec``, ``nanosec``). ``%topic echo`` prints them the ROS 2 way and ``%topic pub`` accepts
both spellings, and ``header: auto`` and ``stamp: now`` as ``ros2 topic pub`` does.
"""

from __future__ import annotations

import dataclasses
import typing
from typing import Any

import yaml

from rrbot_workshop import msgs
from rrbot_workshop.exceptions import MessageError

__all__ = ["message_type", "message_from_dict", "message_to_yaml", "ros_time"]


def message_type(name: str) -> type:
    """The message class of ``name`` (``std_msgs/msg/Float64MultiArray`` or just ``Float64MultiArray``).

    Raises:
        MessageError: If there is no such message; the error lists the valid ones.
    """
    short = name.split("/")[-1]
    cls = getattr(msgs, short, None)
    if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
        valid = sorted(n for n in msgs.__all__ if dataclasses.is_dataclass(getattr(msgs, n)))
        raise MessageError(f"unknown message type '{name}' (valid: {', '.join(valid)})")
    return cls


#: Fields the library keeps as float seconds and ROS 2 as ``builtin_interfaces/Time`` or ``Duration``.
_TIME_FIELDS = ("stamp", "time_from_start")


def _seconds_from_ros(cls: type, key: str, value: dict[str, Any]) -> float:
    unknown = sorted(set(value) - {"sec", "nanosec"})
    if unknown:
        raise MessageError(f"{cls.__name__}.{key} has no field {unknown[0]!r} (valid: sec, nanosec)")
    sec, nanosec = value.get("sec", 0), value.get("nanosec", 0)
    if not all(isinstance(v, int) and not isinstance(v, bool) for v in (sec, nanosec)) or not 0 <= nanosec < 10**9:
        raise MessageError(f"{cls.__name__}.{key} needs integers sec and nanosec (0 <= nanosec < 1e9), got {value}")
    return sec + nanosec * 1e-9


def ros_time(seconds: float) -> dict[str, int]:
    """``{"sec": ..., "nanosec": ...}`` of a time or duration in [s], as ``builtin_interfaces`` has it."""
    total = round(seconds * 1e9)
    sec, nanosec = divmod(total, 10**9)
    return {"sec": int(sec), "nanosec": int(nanosec)}


def _ros_shaped(data: Any) -> Any:
    if isinstance(data, dict):
        return {
            k: ros_time(v) if k in _TIME_FIELDS and isinstance(v, (int, float)) and not isinstance(v, bool)
            else _ros_shaped(v)
            for k, v in data.items()
        }
    if isinstance(data, list):
        return [_ros_shaped(v) for v in data]
    return data


def message_from_dict(cls: type, data: Any, now: float | None = None) -> Any:
    """Build message ``cls`` from a (YAML) mapping, recursively; unknown fields are an error.

    Times and durations may be given as ROS 2 writes them (``stamp: {sec: 1, nanosec: 500000000}``,
    ``time_from_start: {sec: 3}``) or as seconds.

    With ``now`` (what ``ros2 topic pub`` does with its node's clock): ``header: auto`` is a header stamped ``now``
    with an empty ``frame_id``, and ``stamp: now`` (any ``builtin_interfaces/Time``) is ``now``.

    Args:
        cls: The message class.
        data: The mapping of its fields.
        now: The time in [s] that ``auto`` and ``now`` stand for; None accepts neither word.

    Raises:
        MessageError: If a field does not exist; the message lists the valid ones.
    """
    if data is None:
        return cls()
    if cls is msgs.Header and data == "auto":
        if now is None:
            raise MessageError("'header: auto' needs a clock: it is expanded by %topic pub (the system's time)")
        return msgs.Header(stamp=now, frame_id="")
    if not isinstance(data, dict):
        hint = " (or 'auto', which sets the stamp to now and frame_id to '')" if cls is msgs.Header else ""
        raise MessageError(f"{cls.__name__} must be given as a mapping of its fields{hint}, got {data!r}")
    hints = typing.get_type_hints(cls)
    names = [f.name for f in dataclasses.fields(cls)]
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        if key not in names:
            raise MessageError(f"{cls.__name__} has no field '{key}' (valid: {', '.join(names)})")
        hint = hints[key]
        origin = typing.get_origin(hint)
        if isinstance(hint, type) and dataclasses.is_dataclass(hint):
            kwargs[key] = message_from_dict(hint, value, now)
        elif origin is list and typing.get_args(hint) and dataclasses.is_dataclass(typing.get_args(hint)[0]):
            kwargs[key] = [message_from_dict(typing.get_args(hint)[0], v, now) for v in value or []]
        elif key == "stamp" and hint is float and value == "now":
            if now is None:
                raise MessageError(f"{cls.__name__}.stamp: 'now' needs a clock: it is expanded by %topic pub")
            kwargs[key] = float(now)
        elif hint is float and isinstance(value, dict) and key in _TIME_FIELDS:
            kwargs[key] = _seconds_from_ros(cls, key, value)
        elif hint is float and isinstance(value, int) and not isinstance(value, bool):
            kwargs[key] = float(value)
        elif origin is list and typing.get_args(hint) == (float,) and isinstance(value, list):
            kwargs[key] = [float(v) if isinstance(v, int) and not isinstance(v, bool) else v for v in value]
        else:
            kwargs[key] = value
    return cls(**kwargs)


def message_to_yaml(msg: Any) -> str:
    """A message as ``ros2 topic echo`` prints it (YAML, block style), without the trailing ``---``.

    Stamps and durations are written as ROS 2 does, ``sec`` and ``nanosec``.
    """
    data = dataclasses.asdict(msg) if dataclasses.is_dataclass(msg) and not isinstance(msg, type) else msg
    return yaml.safe_dump(_ros_shaped(data), sort_keys=False, default_flow_style=False).rstrip("\n")
