"""Bring-up's inputs: what :func:`~rrbot_workshop.bringup.bringup` is given, resolved into what it builds from.

* :func:`description_to_urdf`: a ``.xacro``/``.urdf`` path, URDF text, or a package name under ``descriptions/``
  -> URDF text (with the package, when known, and a label of the source);
* :func:`controllers_config`: a path, a file name under ``descriptions/<package>/config/``, YAML text, a mapping
  or a :class:`~rrbot_workshop.middleware.controllers_yaml.ControllersConfig` -> a ``ControllersConfig``;
* :func:`hardware_initial_states`: the hardware components' initial states, from the controllers YAML and the caller.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import DescriptionError, HardwareError, ParameterError
from rrbot_workshop.middleware.controllers_yaml import ControllersConfig, load_controllers_yaml
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.text_files import read_text

__all__ = ["description_to_urdf", "controllers_config", "hardware_initial_states"]


def description_to_urdf(description: str | Path, xacro_args: Mapping[str, Any]) -> tuple[str, str | None, str]:
    """(URDF text, package name if known, source label)."""
    from rrbot_workshop.description import descriptions_root, process_xacro

    text = str(description)
    if isinstance(description, str) and text.lstrip().startswith("<"):
        return text, None, "<urdf string>"
    path = Path(text)
    package = None
    if not path.suffix and "/" not in text and "\\" not in text:
        root = descriptions_root()
        package = text
        path = root / text / "urdf" / f"{text}.urdf.xacro"
        if not path.exists():
            valid = sorted(p.name for p in root.iterdir() if p.is_dir()) if root.is_dir() else []
            raise DescriptionError(
                f"description '{text}' is neither a file nor a package with urdf/{text}.urdf.xacro (packages: {valid})"
            )
    if not path.exists():
        raise DescriptionError(f"description file '{path}' does not exist")
    if package is None:
        try:
            rel = path.resolve().relative_to(descriptions_root().resolve())
            package = rel.parts[0]
        except (ValueError, IndexError):
            package = None
    if path.suffix == ".xacro":
        return process_xacro(path, **dict(xacro_args)), package, str(path)
    if xacro_args:
        return process_xacro(path, **dict(xacro_args)), package, str(path)
    text, problem = read_text(path)
    if problem:
        raise DescriptionError(f"description file '{path}' {problem}", source=str(path))
    return text, package, str(path)


def controllers_config(controllers: Any, package: str | None,
                       launch_args: Mapping[str, Any] | None = None) -> ControllersConfig:
    """The controllers config from what :func:`~rrbot_workshop.bringup.bringup` was given as ``controllers``;
    ``launch_args`` fill a file's or a text's ``$(var name)`` (see :func:`load_controllers_yaml`)."""
    if controllers is None:
        return ControllersConfig()
    if isinstance(controllers, ControllersConfig):
        return controllers
    if isinstance(controllers, Mapping):
        return load_controllers_yaml(controllers)
    text = str(controllers)
    if "\n" in text:
        return load_controllers_yaml(text, launch_args=launch_args)
    path = Path(text)
    if not path.exists() and package is not None and "/" not in text:
        from rrbot_workshop.description import descriptions_root

        candidate = descriptions_root() / package / "config" / text
        if candidate.exists():
            path = candidate
        else:
            config_dir = candidate.parent
            valid = sorted(p.name for p in config_dir.glob("*.yaml")) if config_dir.is_dir() else []
            raise ParameterError("controllers file", text, f"not found in {config_dir} (files there: {valid})")
    if not path.exists():
        raise ParameterError("controllers file", text, "does not exist (give a path, a file name under "
                             "descriptions/<package>/config/, a mapping or YAML text)")
    return load_controllers_yaml(path, launch_args=launch_args)


def hardware_initial_states(cfg: ControllersConfig, override: Mapping[str, Any] | None) -> dict[str, State]:
    """Component name -> initial state: the YAML's ``hardware_components_initial_state``, then ``override``."""
    states: dict[str, State] = {}
    section = cfg.manager_parameters.get("hardware_components_initial_state") or {}
    if not isinstance(section, Mapping):
        raise ParameterError("controller_manager", "hardware_components_initial_state", "must be a mapping")
    for label in ("unconfigured", "inactive"):
        names = section.get(label) or []
        if not isinstance(names, list):
            raise ParameterError(
                "controller_manager", f"hardware_components_initial_state.{label}", "must be a list of component names"
            )
        for n in names:
            states[str(n)] = State.from_label(label)
    extra = set(section) - {"unconfigured", "inactive"}
    if extra:
        raise ParameterError(
            "controller_manager", "hardware_components_initial_state",
            f"has unknown key(s) {sorted(extra)} (valid: 'unconfigured', 'inactive')",
        )
    for n, label in (override or {}).items():
        try:
            states[n] = label if isinstance(label, State) else State.from_label(str(label))
        except ValueError as exc:
            raise HardwareError(f"hardware_initial_state of '{n}': {exc}") from None
    return states
