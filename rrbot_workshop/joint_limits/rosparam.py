"""Joint limits from parameters: the ``joint_limits.<joint>.*`` layout of Jazzy's ``joint_limits_rosparam.hpp``.

A node's parameters (a controller's, a hardware component's, the controller manager's) may hold, nested or dotted::

    joint_limits:
      joint1:
        has_position_limits: true
        min_position: -1.57
        max_position: 1.57
        has_velocity_limits: true
        max_velocity: 1.0
        has_soft_limits: true        # soft limits: all four values below are needed
        k_position: 10.0
        k_velocity: 5.0
        soft_lower_limit: -1.4
        soft_upper_limit: 1.4

The rules Jazzy applies (and this module keeps):

* Parameters **override** the limits they are given (from the URDF); they may widen them as well as tighten them.
  A joint without any ``joint_limits.<joint>`` parameter keeps its limits.
* A value counts only with its flag: ``max_velocity`` is read only if ``has_velocity_limits`` is given, and only if
  it is true; ``has_velocity_limits: true`` without ``max_velocity`` (or ``has_velocity_limits: false``) removes the
  velocity limit. Position limits need both ``min_position`` and ``max_position``. ``angle_wraparound`` is read
  only when ``has_position_limits`` is given and false. A value without its flag is ignored (logged as a warning).
* Soft limits are taken only as a whole: ``has_soft_limits: true`` with ``k_position``, ``k_velocity``,
  ``soft_lower_limit`` and ``soft_upper_limit``; otherwise the soft limits given (from the URDF) stay.

Where this library is stricter than Jazzy (which would take the value or ignore it): an unknown key, a value of the
wrong type, ``min_position >= max_position``, a negative maximum, or ``soft_lower_limit > soft_upper_limit`` raise a
:class:`~rrbot_workshop.exceptions.ParameterError` naming the joint, the key and what is valid. Integers are taken
for numbers (as the rest of the library does, and as ROS 1's ``joint_limits.yaml`` files write them).
"""

from __future__ import annotations

import copy
import difflib
import logging
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from rrbot_workshop.description.info import JointLimits, SoftJointLimits
from rrbot_workshop.exceptions import ParameterError

__all__ = [
    "HARD_LIMIT_PARAMETERS",
    "SOFT_LIMIT_PARAMETERS",
    "declare_parameters",
    "joint_limits_parameters",
    "get_joint_limits",
    "get_soft_joint_limits",
    "load_joint_limits_yaml",
]

_log = logging.getLogger(__name__)

#: Hard limit parameters under ``joint_limits.<joint>`` -> type (``bool`` or ``float``), in Jazzy's order.
HARD_LIMIT_PARAMETERS: dict[str, type] = {
    "has_position_limits": bool, "min_position": float, "max_position": float,
    "has_velocity_limits": bool, "max_velocity": float,
    "has_acceleration_limits": bool, "max_acceleration": float,
    "has_deceleration_limits": bool, "max_deceleration": float,
    "has_jerk_limits": bool, "max_jerk": float,
    "has_effort_limits": bool, "max_effort": float,
    "angle_wraparound": bool,
}
#: Soft limit parameters under ``joint_limits.<joint>`` -> type.
SOFT_LIMIT_PARAMETERS: dict[str, type] = {
    "has_soft_limits": bool, "k_position": float, "k_velocity": float,
    "soft_lower_limit": float, "soft_upper_limit": float,
}
_ALL = {**HARD_LIMIT_PARAMETERS, **SOFT_LIMIT_PARAMETERS}
_UNITS = {"position": "[rad] or [m]", "velocity": "[rad/s] or [m/s]", "acceleration": "[rad/s^2] or [m/s^2]",
          "deceleration": "[rad/s^2] or [m/s^2]", "jerk": "[rad/s^3] or [m/s^3]", "effort": "[N m] or [N]"}
_SOFT = ("k_position", "k_velocity", "soft_lower_limit", "soft_upper_limit")

#: ``joint -> key -> value`` as :func:`joint_limits_parameters` returns it.
JointLimitsSection = dict[str, dict[str, Any]]


def declare_parameters(joint_name: str) -> dict[str, bool | float]:
    """The parameters Jazzy declares for a joint, with their defaults (flags false, values NaN).

    Args:
        joint_name: Name of the joint.

    Returns:
        Dotted name (``joint_limits.<joint>.<key>``) -> default value.
    """
    return {f"joint_limits.{joint_name}.{key}": (False if kind is bool else math.nan) for key, kind in _ALL.items()}


def _collect(params: Mapping[str, Any], owner: str) -> dict[str, Any]:
    """Every ``joint_limits.*`` value of ``params`` under its dotted name (nested, dotted or mixed spellings)."""
    out: dict[str, Any] = {}

    def walk(value: Any, name: str) -> None:
        if isinstance(value, Mapping):
            for key, sub in value.items():
                walk(sub, f"{name}.{key}")
        else:
            out[name] = value

    for key, value in params.items():
        key = str(key)
        if key == "joint_limits" or key.startswith("joint_limits."):
            if key == "joint_limits" and not isinstance(value, Mapping):
                raise ParameterError(owner, key, f"must be a mapping of joint names to limits, got {value!r}")
            walk(value, key)
    return out


def _check_value(owner: str, joint: str, key: str, value: Any) -> bool | float:
    name = f"joint_limits.{joint}.{key}"
    if _ALL[key] is bool:
        if not isinstance(value, bool):
            raise ParameterError(owner, name, f"joint '{joint}': '{key}' must be true or false, got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        unit = next((u for word, u in _UNITS.items() if word in key), "")
        what = f"a number{' in ' + unit if unit else ''}"
        raise ParameterError(owner, name, f"joint '{joint}': '{key}' must be {what}, got {value!r}")
    if math.isnan(value):
        raise ParameterError(owner, name, f"joint '{joint}': '{key}' must be a number, got NaN")
    return float(value)


def _check_consistency(owner: str, joint: str, values: Mapping[str, Any]) -> None:
    def flag(name: str) -> bool:
        return bool(values.get(name, False))

    if flag("has_position_limits") and "min_position" in values and "max_position" in values:
        if not values["min_position"] < values["max_position"]:
            raise ParameterError(owner, f"joint_limits.{joint}.min_position",
                                 f"joint '{joint}': min_position ({values['min_position']}) must be below "
                                 f"max_position ({values['max_position']})")
    for kind in ("velocity", "acceleration", "deceleration", "jerk", "effort"):
        key = f"max_{kind}"
        if flag(f"has_{kind}_limits") and key in values and values[key] < 0.0:
            raise ParameterError(owner, f"joint_limits.{joint}.{key}",
                                 f"joint '{joint}': {key} must be 0 or more (a magnitude), got {values[key]}")
    if flag("has_soft_limits") and "soft_lower_limit" in values and "soft_upper_limit" in values:
        if values["soft_lower_limit"] > values["soft_upper_limit"]:
            raise ParameterError(owner, f"joint_limits.{joint}.soft_lower_limit",
                                 f"joint '{joint}': soft_lower_limit ({values['soft_lower_limit']}) must not be above "
                                 f"soft_upper_limit ({values['soft_upper_limit']})")


def joint_limits_parameters(params: Mapping[str, Any], source: str = "") -> JointLimitsSection:
    """The ``joint_limits`` section of a node's parameters, checked, as ``joint -> key -> value``.

    Args:
        params: The node's parameters (``ros__parameters``), nested (``{"joint_limits": {"j1": {...}}}``) or dotted
            (``{"joint_limits.j1.max_velocity": 1.0}``).
        source: The node or file the parameters come from, for error messages.

    Returns:
        Joint name -> parameter name -> value (numbers as float); empty if there is no ``joint_limits`` section.

    Raises:
        ParameterError: On an unknown key, a value of the wrong type, or inconsistent values; the message names the
            joint, the key, and the valid keys or values.
    """
    owner = source or "joint_limits"
    section: JointLimitsSection = {}
    for name, value in _collect(params, owner).items():
        rest = name[len("joint_limits."):]
        joint, dot, key = rest.rpartition(".")
        if not dot or not joint:
            raise ParameterError(owner, name, f"'{rest}' must be a mapping of limit parameters "
                                              f"(joint_limits.<joint>.<key>, keys: {', '.join(_ALL)})")
        if key not in _ALL:
            close = difflib.get_close_matches(key, list(_ALL), n=1, cutoff=0.6)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            raise ParameterError(owner, name, f"joint '{joint}': '{key}' is not a joint limits parameter{hint}; "
                                              f"valid keys: {', '.join(_ALL)}")
        section.setdefault(joint, {})[key] = _check_value(owner, joint, key, value)
    for joint, values in section.items():
        _check_consistency(owner, joint, values)
    return section


def _read_limit(out: JointLimits, values: Mapping[str, Any], kind: str, joint: str) -> None:
    flag, key = f"has_{kind}_limits", f"max_{kind}"
    if flag not in values:
        if key in values:
            _log.warning("joint '%s': joint_limits.%s.%s is set but %s is not; it is ignored (as in Jazzy)",
                         joint, joint, key, flag)
        return
    has = bool(values[flag]) and key in values
    setattr(out, flag, has)
    if has:
        setattr(out, key, values[key])


def get_joint_limits(
    joint_name: str, params: Mapping[str, Any], limits: JointLimits | None = None, *, source: str = ""
) -> JointLimits:
    """A joint's hard limits: ``limits`` overridden by the ``joint_limits.<joint_name>.*`` parameters.

    Args:
        joint_name: Name of the joint.
        params: The node's parameters (nested or dotted ``joint_limits`` section; see the module docstring).
        limits: Limits to start from (from the URDF, for instance); not modified. None: no limits.
        source: The node or file the parameters come from, for error messages.

    Returns:
        A new :class:`~rrbot_workshop.description.info.JointLimits`; a copy of ``limits`` if the parameters say
        nothing about the joint.

    Raises:
        ParameterError: See :func:`joint_limits_parameters`; also if ``joint_name`` is not a non-empty string.
    """
    if not isinstance(joint_name, str) or not joint_name:
        raise ParameterError(source or "get_joint_limits", "joint_name",
                             f"must be a joint's name (a non-empty string), got {joint_name!r}")
    out = copy.copy(limits) if limits is not None else JointLimits()
    values = joint_limits_parameters(params, source).get(joint_name, {})
    if not any(key in values for key in HARD_LIMIT_PARAMETERS):
        return out
    if "has_position_limits" in values:
        has = bool(values["has_position_limits"]) and "min_position" in values and "max_position" in values
        out.has_position_limits = has
        if has:
            out.min_position, out.max_position = values["min_position"], values["max_position"]
        elif "angle_wraparound" in values:
            out.angle_wraparound = bool(values["angle_wraparound"])
    elif "min_position" in values or "max_position" in values:
        _log.warning("joint '%s': joint_limits.%s.min_position/max_position are set but has_position_limits is not; "
                     "they are ignored (as in Jazzy)", joint_name, joint_name)
    for kind in ("velocity", "acceleration", "deceleration", "jerk", "effort"):
        _read_limit(out, values, kind, joint_name)
    return out


def get_soft_joint_limits(
    joint_name: str, params: Mapping[str, Any], soft: SoftJointLimits | None = None, *, source: str = ""
) -> SoftJointLimits | None:
    """A joint's soft limits: those of the parameters if they are complete, else ``soft``.

    Args:
        joint_name: Name of the joint.
        params: The node's parameters (see :func:`get_joint_limits`).
        soft: Soft limits to fall back on (from the URDF's ``<safety_controller>``, for instance), or None.
        source: The node or file the parameters come from, for error messages.

    Returns:
        New soft limits from ``has_soft_limits: true`` with ``k_position``, ``k_velocity``, ``soft_lower_limit`` and
        ``soft_upper_limit``; otherwise ``soft`` (a copy), or None.

    Raises:
        ParameterError: See :func:`joint_limits_parameters`.
    """
    values = joint_limits_parameters(params, source).get(joint_name, {})
    given = [key for key in SOFT_LIMIT_PARAMETERS if key in values]
    if values.get("has_soft_limits") is True and all(key in values for key in _SOFT):
        return SoftJointLimits(min_position=values["soft_lower_limit"], max_position=values["soft_upper_limit"],
                               k_position=values["k_position"], k_velocity=values["k_velocity"])
    if given and values.get("has_soft_limits") is not False:
        missing = [key for key in SOFT_LIMIT_PARAMETERS if key not in values or values[key] is False]
        _log.warning("joint '%s': incomplete soft limits in joint_limits.%s (missing or false: %s); they are ignored "
                     "(as in Jazzy)", joint_name, joint_name, ", ".join(missing))
    return copy.copy(soft) if soft is not None else None


def _node_sections(data: Mapping[str, Any], where: str) -> dict[str, Mapping[str, Any]]:
    """ROS 2 layout: node name -> its ``ros__parameters`` that hold ``joint_limits``."""
    out: dict[str, Mapping[str, Any]] = {}
    for node, body in data.items():
        if isinstance(body, Mapping) and "ros__parameters" in body:
            params = body["ros__parameters"] or {}
            if not isinstance(params, Mapping):
                raise ParameterError(where, f"{node}.ros__parameters", "must be a mapping")
            if any(str(k) == "joint_limits" or str(k).startswith("joint_limits.") for k in params):
                out[str(node)] = params
    return out


def load_joint_limits_yaml(path: str | Path, node: str | None = None) -> dict[str, Any]:
    """Read a ``joint_limits.yaml``, in ROS 1's layout or ROS 2's.

    ROS 1 (``rosparam load``) puts ``joint_limits:`` at the top of the file; ROS 2 puts it in a node's parameters
    (``<node>: {ros__parameters: {joint_limits: ...}}``). Merge the result into the parameters of the node that
    reads it, for instance the controller manager's::

        config["controller_manager"]["ros__parameters"].update(load_joint_limits_yaml("config/joint_limits.yaml"))

    Args:
        path: The YAML file.
        node: ROS 2 layout: the node whose section to take, needed only when several nodes have different
            ``joint_limits`` sections (a leading ``/`` is ignored).

    Returns:
        ``{"joint_limits": {joint: {key: value}}}``, checked as :func:`joint_limits_parameters` checks it.

    Raises:
        ParameterError: If the file cannot be read or parsed, has no ``joint_limits`` section, or its values are
            wrong; the message names the file.
    """
    where = str(path)
    if not isinstance(path, str | Path) or not str(path):
        raise ParameterError(where, "path", "the joint limits file must be a path (a str or Path), got "
                             f"{type(path).__name__} {path!r}")
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise ParameterError(where, "joint_limits", f"cannot read the joint limits file: {exc.strerror or exc}") from exc
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = f" (line {mark.line + 1})" if mark is not None else ""
        raise ParameterError(where, "joint_limits", f"is not valid YAML{line}: {exc}") from exc
    if not isinstance(data, Mapping):
        raise ParameterError(where, "joint_limits", "the file must be a mapping with a 'joint_limits:' section "
                                                    "(ROS 1) or '<node>: ros__parameters: joint_limits:' (ROS 2)")
    if any(str(k) == "joint_limits" or str(k).startswith("joint_limits.") for k in data):
        params: Mapping[str, Any] = data
    else:
        sections = _node_sections(data, where)
        if node is not None:
            wanted = node.lstrip("/")
            match = [name for name in sections if name.lstrip("/") == wanted]
            if not match:
                raise ParameterError(where, "joint_limits", f"no node '{node}' with a joint_limits section "
                                                            f"(nodes with one: {', '.join(sections) or 'none'})")
            params = sections[match[0]]
        elif not sections:
            raise ParameterError(where, "joint_limits", "no 'joint_limits:' section, neither at the top (ROS 1) nor "
                                                        "in a node's ros__parameters (ROS 2)")
        else:
            found = {name: joint_limits_parameters(p, f"{where}: {name}") for name, p in sections.items()}
            if len({repr(sorted(v.items())) for v in found.values()}) > 1:
                raise ParameterError(where, "joint_limits", "several nodes have different joint_limits sections ("
                                                            f"{', '.join(found)}); pass node=... to choose one")
            params = next(iter(sections.values()))
    return {"joint_limits": joint_limits_parameters(params, where)}
