"""Controller base classes: ``ControllerInterface`` and ``ChainableControllerInterface``.

A controller is a lifecycle node. The controller manager loads it (``init`` -> ``on_init``),
configures it (``on_configure``: read parameters, create topics), activates it (claims the interfaces
named by ``command_interface_configuration`` / ``state_interface_configuration``, then ``on_activate``)
and calls ``update(time, period)`` every cycle. A chainable controller also *exports* reference
interfaces that a preceding controller can claim instead of listening to its topic.

This module gathers the names a controller is written with: the plain controller and what it is handed
are in :mod:`rrbot_workshop.controller_interface.controller`, the chainable one in
:mod:`rrbot_workshop.controller_interface.chainable`, and the callbacks' return types
(``CallbackReturn``, ``ReturnType``) in :mod:`rrbot_workshop.middleware.lifecycle`.
"""

from rrbot_workshop.controller_interface.chainable import ChainableControllerInterface
from rrbot_workshop.controller_interface.controller import (
    ControllerInterface,
    ControllerNode,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType

__all__ = [
    "InterfaceConfigurationType",
    "InterfaceConfiguration",
    "ControllerNode",
    "ControllerInterface",
    "ChainableControllerInterface",
    "CallbackReturn",
    "ReturnType",
]
