"""Controllers: base classes and the controllers the course uses (imported on first use)."""

from __future__ import annotations

import importlib
from typing import Any

from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)

__all__ = [
    "ControllerInterface",
    "ChainableControllerInterface",
    "InterfaceConfiguration",
    "InterfaceConfigurationType",
]


def __getattr__(name: str) -> Any:
    try:
        return importlib.import_module(f".{name}", __name__)
    except ModuleNotFoundError as exc:
        if exc.name == f"{__name__}.{name}":
            raise AttributeError(f"module '{__name__}' has no attribute '{name}'") from None
        raise
