"""The controller manager's own parameters (``controller_manager: ros__parameters:`` of the controllers YAML).

Jazzy's ``controller_manager_parameters.yaml`` names them with dots (``defaults.switch_controller.strictness``); a
YAML file may nest them (``defaults: {switch_controller: {strictness: strict}}``) or write the dotted key, as ROS 2
parameter files allow. Values of the wrong type are refused with the parameter's name.
"""

from __future__ import annotations

from collections.abc import Mapping

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.params import ControllersConfig

__all__ = ["manager_parameter", "manager_flag", "default_strictness"]

_OWNER = "controller_manager"


def manager_parameter(params: ControllersConfig, dotted: str, default: object) -> object:
    """The value of ``dotted`` among the manager's parameters, nested or dotted, or ``default``."""
    values = params.manager_parameters
    if dotted in values:
        return values[dotted]
    node: object = values
    for key in dotted.split("."):
        if not isinstance(node, Mapping) or key not in node:
            return default
        node = node[key]
    return node


def manager_flag(params: ControllersConfig, dotted: str, default: bool) -> bool:
    """A boolean parameter.

    Raises:
        ParameterError: If the value is not true or false.
    """
    value = manager_parameter(params, dotted, default)
    if not isinstance(value, bool):
        raise ParameterError(_OWNER, dotted, f"must be true or false, got {value!r}")
    return value


def default_strictness(params: ControllersConfig) -> str:
    """``defaults.switch_controller.strictness``: ``"best_effort"`` (Jazzy's default) or ``"strict"``.

    Raises:
        ParameterError: If the value is neither.
    """
    value = manager_parameter(params, "defaults.switch_controller.strictness", "best_effort")
    if value not in ("strict", "best_effort"):
        raise ParameterError(_OWNER, "defaults.switch_controller.strictness",
                             f"must be 'strict' or 'best_effort', got {value!r}")
    return str(value)
