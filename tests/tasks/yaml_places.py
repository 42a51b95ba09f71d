"""A learner's controllers YAML as Jazzy reads it, for the graders: the controllers it declares in either layout, and
where in the file the learner wrote something (``"multi_rrbot_controllers.yaml, line 12"``), so a reason starts there.

Jazzy takes a controller's ``type`` under the controller manager's ``ros__parameters`` or in the controller's own
section (the spawner reads it there), block or flow style, the manager's section under ``controller_manager``,
``/controller_manager`` or ``/**/controller_manager``. :func:`load` reads the file as the controller manager does;
:func:`type_of` and :func:`declared` look in both places; :func:`at` finds the line of a key.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any, NoReturn

import yaml

import rrbot_workshop as rw
from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.middleware.controllers_yaml import ControllersConfig

__all__ = ["MANAGER_KEYS", "load", "type_of", "declared", "section_keys", "at", "type_at", "parameters"]

#: The keys under which the controller manager's section may be written.
MANAGER_KEYS = ("controller_manager", "/controller_manager", "/**/controller_manager")


def _fail(message: str) -> NoReturn:
    raise AssertionError(message) from None


@functools.cache
def _read(path: Path) -> ControllersConfig | str:
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        return f"{path.name} is not valid YAML: {' '.join(str(exc).split())}"
    if not isinstance(data, dict):
        return f"{path.name} must be a mapping of node names (controller_manager, ...), not {type(data).__name__}"
    if not any(isinstance(data.get(k), dict) and "ros__parameters" in data[k] for k in MANAGER_KEYS):
        return f"{path.name} needs 'controller_manager:' with 'ros__parameters:' under it"
    try:
        return rw.params.load_controllers_yaml(data)
    except RRBotWorkshopError as exc:
        return f"{path.name}: {' '.join(str(exc).split())}"


def load(path: Path) -> ControllersConfig:
    """The file as the controller manager reads it (once per grading); a file it cannot read fails the check."""
    found = _read(path)
    if isinstance(found, str):
        _fail(found)
    return found


def type_of(cfg: ControllersConfig, name: str) -> str | None:
    """The controller's ``type``, under the controller manager or in its own section; ``None`` if it has none."""
    found = cfg.controller_types.get(name) or cfg.parameters_for(name).get("type")
    return found if isinstance(found, str) else None


def declared(cfg: ControllersConfig) -> list[str]:
    """Every controller the file gives a type, in either place, sorted."""
    return sorted(set(cfg.controller_types) | {n for n in cfg.section_names() if type_of(cfg, n)})


def section_keys(cfg: ControllersConfig, name: str) -> tuple[str, ...]:
    """The keys under which the controller ``name``'s own section may be written."""
    return (cfg.section_names().get(name, name), name, f"/{name}", f"/**/{name}")


def parameters(cfg: ControllersConfig, name: str) -> dict[str, Any]:
    """The controller's parameters (its ``type`` left out)."""
    return {k: v for k, v in cfg.parameters_for(name).items() if k != "type"}


@functools.cache
def _composed(path: Path) -> Any:
    try:
        return yaml.compose(path.read_text())
    except yaml.YAMLError:
        return None


def at(path: Path, sections: tuple[str, ...], *keys: str) -> str:
    """``"<file>, line N"``: where the learner wrote ``<section>: ros__parameters: <keys...>`` (the deepest of them
    that is there), or the file's name alone when the section is not there."""
    node, line = _composed(path), None
    if isinstance(node, yaml.MappingNode):
        for key_node, value in node.value:
            if key_node.value in sections:
                line, node = key_node.start_mark.line + 1, value
                for key in ("ros__parameters", *keys):
                    found = next(((k, v) for k, v in node.value if k.value == key), None) \
                        if isinstance(node, yaml.MappingNode) else None
                    if found is None:
                        break
                    line, node = found[0].start_mark.line + 1, found[1]
                break
    return f"{path.name}, line {line}" if line else path.name


def type_at(path: Path, cfg: ControllersConfig, name: str) -> str:
    """Where the controller's ``type`` is written: under the controller manager, else in its own section."""
    if cfg.controller_types.get(name) is not None:
        return at(path, MANAGER_KEYS, name, "type")
    return at(path, section_keys(cfg, name), "type")
