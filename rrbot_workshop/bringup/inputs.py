"""Bring-up's inputs: what :func:`~rrbot_workshop.bringup.bringup` is given, resolved into what it builds from.

* :func:`description_to_urdf`: a ``.xacro``/``.urdf`` path, ``package://pkg/...`` or ``$(find pkg)/...``, URDF
  text, or a package name -> URDF text (with the package, when known, and a label of the source);
* :func:`controllers_config`: a path, ``package://pkg/...`` or ``$(find pkg)/...``, a file name under the
  package's ``config/``, YAML text, a mapping or a
  :class:`~rrbot_workshop.middleware.controllers_yaml.ControllersConfig` -> a ``ControllersConfig``;

Packages are looked up on the package path (:mod:`rrbot_workshop.description.packages`); ``package_path`` puts folders
in front of it for the call.
* :func:`hardware_initial_states`: the hardware components' initial states, from the controllers YAML and the caller.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import DescriptionError, HardwareError, ParameterError
from rrbot_workshop.middleware.controllers_yaml import ControllersConfig, load_controllers_yaml
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.text_files import read_text

__all__ = ["description_to_urdf", "controllers_config", "hardware_initial_states"]


def description_to_urdf(description: str | Path, xacro_args: Mapping[str, Any],
                        package_path: Sequence[str | Path] | None = None) -> tuple[str, str | None, str]:
    """(URDF text, package name if known, source label).

    Args:
        description: See :func:`~rrbot_workshop.bringup.bringup`.
        xacro_args: Xacro arguments.
        package_path: Folders searched first for packages (see :mod:`rrbot_workshop.description.packages`).

    Raises:
        DescriptionError: If the file or package is not found (the message says where it was looked for), or xacro
            fails.
    """
    from rrbot_workshop.description import packages

    with packages.use_package_path(package_path):
        return _description_to_urdf(description, xacro_args)


def _description_to_urdf(description: str | Path, xacro_args: Mapping[str, Any]) -> tuple[str, str | None, str]:
    from rrbot_workshop.description import packages, process_xacro

    text = str(description)
    if isinstance(description, str) and text.lstrip().startswith("<"):
        return text, None, "<urdf string>"
    package = None
    reference, relative = packages.split_package_reference(text)
    if reference is not None:
        package = reference
        path = packages.resolve_uri(text)
    elif not Path(text).suffix and "/" not in text and "\\" not in text:
        package = text
        index = packages.package_index()
        pkg = index.packages.get(text) or packages.package_index(refresh=True).packages.get(text)
        found = pkg.find(f"urdf/{text}.urdf.xacro") if pkg is not None else None
        if found is None:
            looked = (f"; looked for: {', '.join(str(c) for c in pkg.candidates(f'urdf/{text}.urdf.xacro'))}"
                      if pkg is not None else "")
            raise DescriptionError(
                f"description '{text}' is neither a file nor a package with urdf/{text}.urdf.xacro (packages: "
                f"{index.names()}; package path: {', '.join(str(e) for e in index.entries)}{looked})"
            )
        path = found
    else:
        path = Path(text).expanduser()
    if not path.exists():
        raise DescriptionError(f"description file '{path}' does not exist")
    if package is None:
        owner = packages.package_of(path)
        package = owner.name if owner is not None else None
    if path.suffix == ".xacro":
        return process_xacro(path, **dict(xacro_args)), package, str(path)
    if xacro_args:
        return process_xacro(path, **dict(xacro_args)), package, str(path)
    text, problem = read_text(path)
    if problem:
        raise DescriptionError(f"description file '{path}' {problem}", source=str(path))
    return text, package, str(path)


def controllers_config(controllers: Any, package: str | None,
                       package_path: Sequence[str | Path] | None = None,
                       launch_args: Mapping[str, Any] | None = None) -> ControllersConfig:
    """The controllers config from what :func:`~rrbot_workshop.bringup.bringup` was given as ``controllers``.

    Args:
        controllers: See :func:`~rrbot_workshop.bringup.bringup`.
        package: The description's package: a bare file name is looked for in its ``config/``.
        package_path: Folders searched first for packages.
        launch_args: Fill a file's or a text's ``$(var name)`` (see :func:`load_controllers_yaml`).

    Raises:
        ParameterError: If the file is not found (the message says where it was looked for) or is malformed.
    """
    if controllers is None:
        return ControllersConfig()
    if isinstance(controllers, ControllersConfig):
        return controllers
    if isinstance(controllers, Mapping):
        return load_controllers_yaml(controllers)
    text = str(controllers)
    if "\n" in text:
        return load_controllers_yaml(text, launch_args=launch_args)
    from rrbot_workshop.description import packages

    with packages.use_package_path(package_path):
        reference, _ = packages.split_package_reference(text)
        if reference is not None:
            try:
                return load_controllers_yaml(packages.resolve_uri(text), launch_args=launch_args)
            except DescriptionError as exc:
                raise ParameterError("controllers file", text, str(exc)) from None
        path = Path(text).expanduser()
        if not path.exists() and package is not None and "/" not in text:
            try:
                pkg = packages.find_package(package)
            except DescriptionError as exc:
                raise ParameterError("controllers file", text, str(exc)) from None
            found = pkg.find(f"config/{text}")
            if found is None:
                config_dirs = [c for c in pkg.candidates("config") if c.is_dir()]
                valid = sorted(p.name for d in config_dirs for p in d.glob("*.yaml"))
                looked = ", ".join(str(c) for c in pkg.candidates(f"config/{text}"))
                raise ParameterError("controllers file", text,
                                     f"not found in package '{package}' (looked for: {looked}; files there: {valid})")
            path = found
    if not path.exists():
        raise ParameterError("controllers file", text, "does not exist (give a path, package://<pkg>/<path>, "
                             "$(find <pkg>)/<path>, a file name under the package's config/, a mapping or YAML text)")
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
