"""ROS node names: the rule a controller's name must follow, since every controller is a node.

ROS 2 (``rmw_validate_node_name``, used by ``rcl`` when a node is created) accepts a node name when it

* is not empty,
* holds only ASCII letters, digits and underscores (``[A-Za-z0-9_]``),
* does not start with a digit,
* is at most 255 characters long.

Jazzy's controller manager creates a node per controller at load, so a name such as ``a-b``, ``2nd`` or one with a
space or a newline makes the load fail. :func:`node_name_problem` says why a name breaks the rule (or ``""``), and
:func:`check_node_name` raises with that reason and the rule. :func:`parse_ros_args` reads the remap rules and
parameters of a node's ``--ros-args`` (the spawner's ``--controller-ros-args``).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from rrbot_workshop.exceptions import ControllerError

__all__ = ["NODE_NAME_MAX_LENGTH", "NODE_NAME_RULE", "node_name_problem", "is_valid_node_name", "check_node_name",
           "topic_name_problem", "parse_ros_args"]

#: The longest node name ROS accepts.
NODE_NAME_MAX_LENGTH = 255

#: The rule in one sentence, for error messages.
NODE_NAME_RULE = ("a ROS node name is 1-255 ASCII letters, digits and underscores and does not start with a digit "
                  "(e.g. 'arm_controller')")

_ALLOWED = re.compile(r"[A-Za-z0-9_]+\Z")
_BAD_CHAR = re.compile(r"[^A-Za-z0-9_]")


def node_name_problem(name: object) -> str:
    """Why ``name`` is not a valid ROS node name, or ``""`` if it is.

    Args:
        name: The candidate (anything; a non-string is a problem too).
    """
    if not isinstance(name, str):
        return f"it is a {type(name).__name__}, not a string"
    if not name:
        return "it is empty"
    if len(name) > NODE_NAME_MAX_LENGTH:
        return f"it has {len(name)} characters, more than {NODE_NAME_MAX_LENGTH}"
    if not _ALLOWED.match(name):
        bad = _BAD_CHAR.search(name)
        assert bad is not None
        return f"it contains {bad.group()!r} at index {bad.start()}"
    if name[0].isdigit():
        return "it starts with a digit"
    return ""


def is_valid_node_name(name: object) -> bool:
    """True if ``name`` follows the ROS node name rule."""
    return not node_name_problem(name)


def check_node_name(name: object, what: str = "controller") -> str:
    """Return ``name`` if it is a valid ROS node name.

    Args:
        name: The candidate.
        what: What the name is for, for the message (``"controller"``).

    Raises:
        ControllerError: If it is not, saying why and giving the rule.
    """
    problem = node_name_problem(name)
    if problem:
        shown = repr(name) if not isinstance(name, str) or len(name) <= 80 else repr(name[:77] + "...")
        raise ControllerError(f"{what} name {shown} is not a valid ROS node name: {problem}; {NODE_NAME_RULE}")
    return name  # type: ignore[return-value]


_TOPIC_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def topic_name_problem(name: object) -> str:
    """Why ``name`` is not a valid ROS topic name, or ``""`` (the rules of ``rcl_validate_topic_name``: tokens of
    letters, digits and underscores not starting with a digit, separated by single ``/``; an optional leading ``/``
    or ``~/``; no trailing ``/``).

    Args:
        name: The candidate.
    """
    if not isinstance(name, str):
        return f"it is a {type(name).__name__}, not a string"
    if not name:
        return "it is empty"
    body = name[2:] if name.startswith("~/") else name[1:] if name.startswith("/") else name
    if name == "~":
        return ""
    if not body:
        return "it names no topic after its leading '/'" if name.startswith("/") else "it is empty"
    if body.endswith("/"):
        return "it ends with '/'"
    for token in body.split("/"):
        if not token:
            return "it contains '//'"
        if not _TOPIC_TOKEN.match(token):
            bad = _BAD_CHAR.search(token)
            if bad is not None:
                return f"it contains {bad.group()!r}"
            return f"its part {token!r} starts with a digit"
    return ""


def parse_ros_args(args: str | Sequence[str]) -> tuple[list[tuple[str, str]], dict[str, Any]]:
    """The remap rules and parameters of a node's ``--ros-args`` (the spawner's ``--controller-ros-args``).

    ``-r from:=to`` (or ``--remap``) remaps a topic or service name; ``-p name:=value`` (or ``--param``) sets a
    parameter (the value read as YAML, as rcl reads it). A leading ``--ros-args`` and a closing ``--`` are accepted.

    Args:
        args: The text (``"-r ~/cmd_vel:=/cmd_vel"``) or its words.

    Returns:
        (rules as (from, to) in order, parameters by dotted name).

    Raises:
        ParameterError: For another flag, a rule without ``:=``, a node-name prefix (``node:from:=to``), or a
            ``__ns``/``__node`` rule (a controller's namespace and name are its controller manager's and its own).
    """
    import shlex

    import yaml

    from rrbot_workshop.exceptions import ParameterError

    words = shlex.split(args) if isinstance(args, str) else list(args)
    rules: list[tuple[str, str]] = []
    params: dict[str, Any] = {}
    i = 0
    while i < len(words):
        flag = words[i]
        if flag in ("--ros-args", "--"):
            i += 1
            continue
        if flag not in ("-r", "--remap", "-p", "--param") or i + 1 >= len(words):
            raise ParameterError("controller ros args", flag, f"is not supported here (give '-r from:=to' or "
                                 f"'-p name:=value'; got {' '.join(words)!r})")
        rule = words[i + 1]
        if ":=" not in rule:
            raise ParameterError("controller ros args", rule, f"needs 'from:=to' after {flag}")
        left, right = rule.split(":=", 1)
        if flag in ("-r", "--remap"):
            if left.startswith("__"):
                raise ParameterError("controller ros args", rule, "renames the node or its namespace; a controller's "
                                     "name and namespace are set by its controller manager")
            if ":" in left:
                raise ParameterError("controller ros args", rule, "node-specific rules ('node:from:=to') are not "
                                     "supported; the rule already applies to this controller only")
            for name in (left, right):
                problem = topic_name_problem(name)
                if problem:
                    raise ParameterError("controller ros args", rule, f"'{name}' is not a valid name: {problem}")
            rules.append((left, right))
        else:
            params[left] = yaml.safe_load(right) if right else ""
        i += 2
    return rules, params
