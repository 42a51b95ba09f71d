"""The controller manager's own parameters (``controller_manager: ros__parameters:`` of the controllers YAML).

Jazzy's ``controller_manager_parameters.yaml`` names them with dots (``defaults.switch_controller.strictness``); a
YAML file may nest them (``defaults: {switch_controller: {strictness: strict}}``) or write the dotted key, as ROS 2
parameter files allow. Values of the wrong type are refused with the parameter's name.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.params import ControllersConfig

__all__ = ["manager_parameter", "manager_flag", "default_strictness", "ManagerParameters"]

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


@dataclass(frozen=True)
class ManagerParameters:
    """The manager's parameters, read once when it is built (:meth:`read`)."""

    #: ros2_control's ``handle_exceptions`` (default true): catch what a controller's ``update`` raises.
    handle_exceptions: bool
    #: Jazzy's ``enforce_command_limits`` (default false): limit commands from the description before write.
    enforce_command_limits: bool
    #: ``defaults.switch_controller.strictness`` (Jazzy: best_effort): a switch asked with strictness 0 or None.
    default_strictness: str
    #: ``defaults.deactivate_controllers_on_hardware_self_deactivate`` (default true): a component that deactivates
    #: itself from ``write`` stops the controllers commanding it.
    deactivate_controllers_on_hardware_self_deactivate: bool
    #: ``defaults.allow_controller_activation_with_inactive_hardware`` (default false), applied by the resource
    #: manager when a switch claims command interfaces of an INACTIVE component.
    allow_controller_activation_with_inactive_hardware: bool

    @classmethod
    def read(cls, params: ControllersConfig, handle_exceptions: bool, allow_inactive_hardware: bool) -> ManagerParameters:
        """The values of ``params``; the two arguments are the defaults the manager was given.

        Raises:
            ParameterError: If a value has the wrong type.
        """
        return cls(
            handle_exceptions=bool(params.manager_parameters.get("handle_exceptions", handle_exceptions)),
            enforce_command_limits=manager_flag(params, "enforce_command_limits", False),
            default_strictness=default_strictness(params),
            deactivate_controllers_on_hardware_self_deactivate=manager_flag(
                params, "defaults.deactivate_controllers_on_hardware_self_deactivate", True),
            allow_controller_activation_with_inactive_hardware=manager_flag(
                params, "defaults.allow_controller_activation_with_inactive_hardware", allow_inactive_hardware),
        )
