"""The controllers YAML: a ros2_control controllers file read into a :class:`ControllersConfig`.

:func:`load_controllers_yaml` reads a controllers file in the ros2_control layout::

    controller_manager:
      ros__parameters:
        update_rate: 100
        joint_state_broadcaster:
          type: joint_state_broadcaster/JointStateBroadcaster
    joint_state_broadcaster:
      ros__parameters: {}

The declared parameters of each controller type, and their validation, are in
:mod:`rrbot_workshop.middleware.params`, which also offers both names of this module.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.text_files import load_yaml, read_text

__all__ = ["ControllersConfig", "load_controllers_yaml"]


@dataclass
class ControllersConfig:
    """Content of a controllers YAML file.

    Attributes:
        update_rate: Controller manager rate in [Hz] (default 100, as in ros2_control).
        manager_parameters: Every ``controller_manager`` parameter that is not a controller entry.
        controller_types: Controller name -> type string, from ``controller_manager.ros__parameters``.
        controller_parameters: Controller name -> its ``ros__parameters`` (nested dict).
        source: File path or ``"<string>"``.
    """

    update_rate: int = 100
    manager_parameters: dict[str, Any] = field(default_factory=dict)
    controller_types: dict[str, str] = field(default_factory=dict)
    controller_parameters: dict[str, dict[str, Any]] = field(default_factory=dict)
    source: str = "<string>"

    def parameters_for(self, name: str) -> dict[str, Any]:
        """Parameters of controller ``name`` (a deep copy; empty if none were given)."""
        merged = copy.deepcopy(self.controller_parameters.get("/**", {}))
        merged.update(copy.deepcopy(self.controller_parameters.get(name, {})))
        return merged


def _strip_ns(key: str) -> str:
    return key.strip("/").split("/")[-1] if key != "/**" else key


def load_controllers_yaml(source: str | Path | Mapping[str, Any]) -> ControllersConfig:
    """Read a controllers file (path, YAML text, or an already-parsed mapping).

    Raises:
        ParameterError: If the YAML is malformed or does not follow the ros2_control layout.
    """
    where = "<string>"
    if isinstance(source, Mapping):
        data: Any = source
    elif not isinstance(source, str | Path):
        raise ParameterError("controllers file", repr(source)[:80], f"must be a path, YAML text or a mapping, not "
                                                                  f"{type(source).__name__}")
    else:
        text = str(source)
        if isinstance(source, Path) or (("\n" not in text) and text.endswith((".yaml", ".yml"))):
            path = Path(source)
            where = str(path)
            text, problem = read_text(path)
            if problem:
                raise ParameterError("controllers file", where, problem)
        data, problem = load_yaml(text)
        if problem:
            raise ParameterError("controllers file", where, problem)
        if data is None:
            raise ParameterError("controllers file", where, "is empty; it needs a 'controller_manager:' entry with "
                                 "'ros__parameters:' (update_rate and the controllers' types)")
    if not isinstance(data, Mapping):
        raise ParameterError("controllers file", where, "must be a mapping of node names to 'ros__parameters'")

    cfg = ControllersConfig(source=where)
    for raw_key, body in data.items():
        key = _strip_ns(str(raw_key))
        if not isinstance(body, Mapping) or "ros__parameters" not in body:
            raise ParameterError(
                "controllers file", f"{where}: {raw_key}", "each top-level entry needs a 'ros__parameters:' mapping"
            )
        params = body["ros__parameters"] or {}
        if not isinstance(params, Mapping):
            raise ParameterError("controllers file", f"{where}: {raw_key}.ros__parameters", "must be a mapping")
        if key.endswith("controller_manager"):
            for pname, pval in params.items():
                if isinstance(pval, Mapping) and "type" in pval:
                    ctype = pval["type"]
                    if not isinstance(ctype, str) or "/" not in ctype:
                        raise ParameterError(
                            "controller_manager",
                            f"{pname}.type",
                            f"'{ctype}' is not a plugin type string such as 'package/ClassName' ({where})",
                        )
                    cfg.controller_types[str(pname)] = ctype
                    extra = {k: v for k, v in pval.items() if k != "type"}
                    if extra:
                        cfg.controller_parameters.setdefault(str(pname), {}).update(extra)
                else:
                    cfg.manager_parameters[str(pname)] = pval
            rate = cfg.manager_parameters.get("update_rate", 100)
            if not isinstance(rate, int) or isinstance(rate, bool) or rate <= 0:
                raise ParameterError("controller_manager", "update_rate", f"must be a positive integer [Hz], got {rate!r}")
            cfg.update_rate = rate
        elif key == "/**":
            # '/**' reaches every node, the controller manager too: '<name>: {type: ...}' there declares a
            # controller (unless the controller_manager section declares it itself); the rest goes to every controller
            shared = {}
            for pname, pval in params.items():
                ctype = pval.get("type") if isinstance(pval, Mapping) else None
                if isinstance(ctype, str) and "/" in ctype:
                    cfg.controller_types.setdefault(str(pname), ctype)
                else:
                    shared[pname] = pval
            cfg.controller_parameters.setdefault(key, {}).update(copy.deepcopy(shared))
        else:
            cfg.controller_parameters.setdefault(key, {}).update(copy.deepcopy(dict(params)))
    return cfg
