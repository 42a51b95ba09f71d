"""Parameter injection: launch-time substitutions in a controllers YAML, several parameter files, single overrides.

What a ROS 2 Jazzy launch file can do to a controllers YAML before the controller manager reads it:

* ``ParameterFile(path, allow_substs=True)`` replaces ``$(var name)`` with the launch argument ``name`` (``$(var name
  default)`` falls back to ``default``) and
  ``$(env NAME)`` / ``$(env NAME default)`` with an environment variable (:func:`substitute`). A file given to the
  spawner with ``--param-file`` is read as it is: no substitutions there.
* Several parameter files for the same node are applied in order, a later file overriding the keys it sets and
  keeping the others (:func:`merge`).
* A single value set from the launch file (``{"update_rate": 50}``, or ``-p update_rate:=50`` on the command line)
  overrides the files (:func:`override`).

The result is a mapping that :func:`rrbot_workshop.bringup` takes as its ``controllers`` argument.
"""

from __future__ import annotations

import copy
import difflib
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.text_files import load_yaml, read_text

__all__ = ["substitute", "load_with_substitutions", "merge", "override"]

_SUBST = re.compile(r"\$\((?P<kind>[a-z-]+)(?P<args>(?:\s+[^()\s]+)*)\s*\)")
_OWNER = "parameter file"


def substitute(text: str, variables: Mapping[str, Any], source: str = "<text>") -> str:
    """Replace ``$(var name)``, ``$(var name default)``, ``$(env NAME)`` and ``$(env NAME default)`` in ``text``.

    Args:
        text: YAML (or any) text.
        variables: Launch arguments by name; values are written with ``str()`` (``True`` becomes ``true``).
        source: File name used in error messages.

    Raises:
        ParameterError: For an unknown variable (with the closest known names), an unset environment variable
            without default, or a substitution kind other than ``var`` and ``env``, naming the file and line.
    """

    def line_of(pos: int) -> int:
        return text.count("\n", 0, pos) + 1

    def replace(match: re.Match[str]) -> str:
        kind, args = match.group("kind"), match.group("args").split()
        where = f"{source}:{line_of(match.start())}"
        if kind == "var" and len(args) in (1, 2):
            name = args[0]
            if name not in variables and len(args) == 2:
                return args[1]  # $(var name default): launch's LaunchConfiguration with a default
            if name not in variables:
                close = difflib.get_close_matches(name, list(variables), n=3)
                fix = (f"did you mean {close}?" if close else
                       f"pass it as the launch file would: bringup(..., launch_args={{'{name}': ...}}) "
                       f"(lint: --arg {name}:=...)")
                raise ParameterError(_OWNER, name, f"{where}: $(var {name}) is not a launch argument "
                                     f"(given: {sorted(variables) or 'none'}); {fix}")
            value = variables[name]
            return str(value).lower() if isinstance(value, bool) else str(value)
        if kind == "env" and len(args) in (1, 2):
            value = os.environ.get(args[0], args[1] if len(args) == 2 else None)
            if value is None:
                raise ParameterError(_OWNER, args[0], f"{where}: environment variable {args[0]} is not set "
                                     "and $(env ...) gives no default")
            return value
        raise ParameterError(_OWNER, match.group(0), f"{where}: unsupported substitution {match.group(0)!r} "
                             "(here: $(var name), $(var name default), $(env NAME), $(env NAME default))")

    return _SUBST.sub(replace, text)


def load_with_substitutions(path: str | Path, variables: Mapping[str, Any]) -> dict[str, Any]:
    """Read a controllers YAML as ``ParameterFile(path, allow_substs=True)`` does, substitutions applied.

    Raises:
        ParameterError: If the file cannot be read, a substitution fails, or the result is not a YAML mapping.
    """
    file = Path(path)
    text, problem = read_text(file)
    if problem:
        raise ParameterError(_OWNER, str(file), problem)
    data, problem = load_yaml(substitute(text, variables, source=str(file)))
    if problem:
        raise ParameterError(_OWNER, str(file), f"after substitution {problem}")
    if not isinstance(data, dict):
        raise ParameterError(_OWNER, str(file), "must be a mapping of node names to their ros__parameters")
    return data


def merge(*files: Mapping[str, Any]) -> dict[str, Any]:
    """Apply parameter files in order: mappings merge key by key, anything else (lists too) is replaced."""

    def into(base: dict[str, Any], extra: Mapping[str, Any]) -> None:
        for key, value in extra.items():
            if isinstance(value, Mapping) and isinstance(base.get(key), dict):
                into(base[key], value)
            else:
                base[key] = copy.deepcopy(value)

    out: dict[str, Any] = {}
    for data in files:
        into(out, data)
    return out


def override(config: Mapping[str, Any], node: str, values: Mapping[str, Any]) -> dict[str, Any]:
    """A copy of ``config`` with ``node``'s parameters set from ``values`` (dotted names, e.g. ``"gains.joint1.p"``).

    The node's section may be written as ``node``, ``/node`` or ``/**/node``, as a ROS 2 parameters file addresses it;
    the first of these that holds ``ros__parameters`` is changed.

    Raises:
        ParameterError: If ``node`` has no ``ros__parameters`` in ``config`` (the valid node names are listed).
    """
    out = merge(config)
    bare = node.split("/")[-1]
    keys = [node, *(k for k in (bare, f"/{bare}", f"/**/{bare}") if k != node)]
    section = next((out[k] for k in keys if isinstance(out.get(k), dict)
                    and isinstance(out[k].get("ros__parameters"), dict)), None)
    if not isinstance(section, dict) or not isinstance(section.get("ros__parameters"), dict):
        nodes = sorted(k for k, v in out.items() if isinstance(v, dict) and "ros__parameters" in v)
        raise ParameterError(_OWNER, node, f"has no ros__parameters section (nodes: {nodes})")
    for dotted, value in values.items():
        target = section["ros__parameters"]
        *path, last = dotted.split(".")
        for part in path:
            target = target.setdefault(part, {})
        target[last] = copy.deepcopy(value)
    return out
