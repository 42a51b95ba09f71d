"""Matplotlib figures from a :class:`~rrbot_workshop.viz.recorder.Recorder`.

The figures carry no timestamps or other run-dependent text, so a notebook that draws them from a
deterministic simulation produces the same picture every time. Axes are labelled with units in
brackets: [s], [rad], [rad/s], [N m].
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["plot_tracking", "plot_interfaces", "unit_of"]

#: Unit of each standard interface name (``hardware_interface/types/hardware_interface_type_values.hpp``).
_UNITS = {
    "position": "rad",
    "velocity": "rad/s",
    "acceleration": "rad/s²",
    "effort": "N m",
    "force": "N",
    "torque": "N m",
    "fx": "N", "fy": "N", "fz": "N",  # force-torque sensor interfaces as RRBot names them
    "tx": "N m", "ty": "N m", "tz": "N m",
}


def unit_of(interface: str, overrides: Mapping[str, str] | None = None) -> str:
    """Unit of an interface from its last name part: ``"joint1/velocity"`` -> ``"rad/s"``.

    Args:
        interface: Interface name (a ``"command:"`` or ``"state:"`` prefix is allowed).
        overrides: Interface name or last part -> unit (e.g. ``{"position": "m"}`` for a prismatic joint).

    Returns:
        The unit, or ``"-"`` if unknown.
    """
    last = interface.rsplit("/", 1)[-1]
    base = last.split(".", 1)[0]  # force.x -> force
    for key in (interface, last, base):
        if overrides and key in overrides:
            return overrides[key]
    return _UNITS.get(last, _UNITS.get(base, "-"))


def _figure(rows: int, cols: int, figsize: tuple[float, float] | None) -> tuple[Any, np.ndarray]:
    import matplotlib.pyplot as plt

    size = figsize or (4.5 * cols + 1.0, 2.6 * rows + 0.6)
    fig, axes = plt.subplots(rows, cols, figsize=size, sharex=True, squeeze=False, layout="constrained")
    return fig, axes


def plot_tracking(
    recorder: Any,
    joints: Sequence[str],
    *,
    interface: str = "position",
    commanded: str | Mapping[str, str] = "command:{joint}/{interface}",
    actual: str | Mapping[str, str] = "{joint}/{interface}",
    units: Mapping[str, str] | None = None,
    title: str | None = None,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """Commanded against actual value per joint, with the tracking error below.

    Args:
        recorder: A recorder that holds the commanded and actual columns.
        joints: Joint names, one column of subplots each.
        interface: Interface compared (``"position"``, ``"velocity"``, ...).
        commanded: Column of the commanded value: a format string with ``{joint}`` and ``{interface}``
            (default: the command interface) or a joint -> column mapping. A chain's reference interface,
            e.g. ``"pid_controller_{joint}/{joint}/position"``, works too.
        actual: Column of the measured value, same forms (default: the state interface).
        units: Unit overrides for :func:`unit_of` (e.g. ``{"position": "m"}``).
        title: Figure title.
        figsize: Figure size in [in].

    Returns:
        A ``matplotlib.figure.Figure`` with 2 rows (values, error) and one column per joint.

    Raises:
        KeyError: If a column is not recorded; the message lists what is.
        ValueError: If ``joints`` is empty.
    """
    if not joints:
        raise ValueError("plot_tracking needs at least one joint name")
    unit = unit_of(interface, units)
    fig, axes = _figure(2, len(joints), figsize)
    time = recorder["time"]
    def column(spec: str | Mapping[str, str], joint: str) -> str:
        if isinstance(spec, str):
            return spec.format(joint=joint, interface=interface)
        return spec[joint]

    for col, joint in enumerate(joints):
        cmd_name, act_name = column(commanded, joint), column(actual, joint)
        cmd, act = recorder[cmd_name], recorder[act_name]
        top, bottom = axes[0, col], axes[1, col]
        top.plot(time, cmd, "--", label=f"commanded ({cmd_name})", color="tab:orange")
        top.plot(time, act, "-", label=f"actual ({act_name})", color="tab:blue")
        top.set_title(joint)
        top.set_ylabel(f"{interface} [{unit}]")
        top.legend(loc="best", fontsize="small")
        top.grid(True, alpha=0.3)
        bottom.plot(time, cmd - act, color="tab:red")
        bottom.axhline(0.0, color="black", linewidth=0.6)
        bottom.set_ylabel(f"error [{unit}]")
        bottom.set_xlabel("time [s]")
        bottom.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    return fig


def plot_interfaces(
    recorder: Any,
    names: Sequence[str],
    *,
    units: Mapping[str, str] | None = None,
    title: str | None = None,
    figsize: tuple[float, float] | None = None,
) -> Any:
    """One subplot per recorded interface, against time.

    Args:
        recorder: A recorder holding the columns.
        names: Columns to draw (as recorded, e.g. ``"joint1/velocity"``, ``"command:joint1/effort"``).
        units: Unit overrides for :func:`unit_of`.
        title: Figure title.
        figsize: Figure size in [in].

    Returns:
        A ``matplotlib.figure.Figure`` with one row per name.

    Raises:
        KeyError: If a column is not recorded.
        ValueError: If ``names`` is empty.
    """
    if not names:
        raise ValueError("plot_interfaces needs at least one interface name")
    fig, axes = _figure(len(names), 1, figsize)
    time = recorder["time"]
    for row, name in enumerate(names):
        ax = axes[row, 0]
        ax.plot(time, recorder[name], color=f"C{row % 10}")
        ax.set_ylabel(f"[{unit_of(name, units)}]")
        ax.set_title(name, fontsize="medium", loc="left")
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    if title:
        fig.suptitle(title)
    return fig
