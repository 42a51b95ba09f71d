"""Seeing the robot and its controllers: 3D viewer, recorder, plots and diagrams.

Everything here sits on top of the library (the core never imports it) and is imported on first use,
so ``import rrbot_workshop.viz`` does not pull in meshcat or matplotlib until they are needed.

* :class:`Viewer` - meshcat 3D view on 127.0.0.1, live from ``/joint_states``, recorded animations,
  self-contained HTML export.
* :class:`Recorder` - samples state, command and reference interfaces every control cycle.
* :func:`plot_tracking`, :func:`plot_interfaces` - matplotlib figures from a recorder.
* :func:`controller_chains`, :func:`architecture`, :func:`lifecycle_states` - SVG diagrams of a
  running system.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = [
    "Viewer",
    "MeshcatServer",
    "Recorder",
    "plot_tracking",
    "plot_interfaces",
    "controller_chains",
    "architecture",
    "lifecycle_states",
    "SvgDiagram",
    "ControllerManagerPanel",
    "TrajectoryPanel",
    "PlotPanel",
]

_EXPORTS = {
    "Viewer": "viewer",
    "MeshcatServer": "meshcat_server",
    "Recorder": "recorder",
    "plot_tracking": "plots",
    "plot_interfaces": "plots",
    "controller_chains": "diagrams",
    "architecture": "diagrams",
    "lifecycle_states": "diagrams",
    "SvgDiagram": "svg",
    "ControllerManagerPanel": "panels",
    "TrajectoryPanel": "panels",
    "PlotPanel": "live_plot",
}


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'rrbot_workshop.viz' has no attribute '{name}' (valid: {', '.join(__all__)})")
    return getattr(importlib.import_module(f".{module}", __name__), name)


def __dir__() -> list[str]:
    return sorted(__all__)
