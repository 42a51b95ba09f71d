"""Bring-up: from a robot's files to a running :class:`System`, as a ROS 2 launch file does.

* :mod:`~rrbot_workshop.bringup.launch`: :func:`bringup`, the launch file and spawners in one call;
* :mod:`~rrbot_workshop.bringup.inputs`: what bringup is given (description, controllers YAML, initial states),
  resolved into what it builds from;
* :mod:`~rrbot_workshop.bringup.system`: :class:`System`, the running robot, and the registry of running ones;
* :mod:`~rrbot_workshop.bringup.spinner`: the control loop spinning between notebook cells.

``rw.bringup(...)`` calls :func:`bringup`: ``import rrbot_workshop.bringup`` binds the package attribute ``bringup``
to this package, which would hide the function of the same name, so calling the package calls the function.
"""

from __future__ import annotations

import sys
import types
from typing import Any

from rrbot_workshop.bringup.launch import bringup
from rrbot_workshop.bringup.system import System, current_system, get_system, systems

__all__ = ["bringup", "System", "current_system", "get_system", "systems"]


class _CallableModule(types.ModuleType):
    """A module whose call is :func:`bringup` (see the module docstring)."""

    def __call__(self, *args: Any, **kwargs: Any) -> System:
        return bringup(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
sys.modules[__name__].__wrapped__ = bringup  # type: ignore[attr-defined]  # inspect.signature shows bringup's
