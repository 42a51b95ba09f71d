"""Routing a command mode switch to the hardware components it concerns.

When controllers switch, the command interfaces they start and stop claiming go to the components
that export them, each component getting only its own keys, in cycle order: first
``prepare_command_mode_switch`` (may they?), then ``perform_command_mode_switch`` (do it). A
component's hook that raises counts as ERROR. Each function returns why it failed, or ``""``; the
resource manager keeps that reason in ``last_switch_error``.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Sequence
from typing import Any

from rrbot_workshop.hardware_interface.resource_loading import ComponentEntry
from rrbot_workshop.hardware_interface.resource_storage import InterfaceStorage
from rrbot_workshop.middleware.lifecycle import ReturnType, State

__all__ = ["prepare", "perform"]

# The resource manager's messages keep the logger name they had before it was split into modules.
_log = logging.getLogger("rrbot_workshop.hardware_interface.resource_manager")


def prepare(
    entries: Sequence[ComponentEntry],
    storage: InterfaceStorage,
    start_interfaces: Sequence[str],
    stop_interfaces: Sequence[str],
    allow_inactive: bool,
    ask_components: bool = True,
) -> str:
    """Ask each component concerned whether the new set of claimed command interfaces is possible.

    Args:
        entries: The components, in cycle order.
        storage: The interface storage.
        start_interfaces: Command interfaces about to be claimed.
        stop_interfaces: Command interfaces about to be released.
        allow_inactive: Whether an INACTIVE component may have interfaces started
            (``allow_controller_activation_with_inactive_hardware``).
        ask_components: Call each component's ``prepare_command_mode_switch``; False checks only the resource
            manager's own rules (a dry run: a driver may keep what it prepared for the ``perform`` that follows).

    Returns:
        ``""`` if every component agrees, else the first reason (logged): a key does not exist or
        is unavailable, a component would start interfaces while INACTIVE (unless allowed), a
        component is neither INACTIVE nor ACTIVE, or a component's hook returns not-OK.
    """
    reject = _reject if ask_components else str
    if not start_interfaces and not stop_interfaces:
        return ""
    for key in [*start_interfaces, *stop_interfaces]:
        if key not in storage.commands:
            return reject(f"command interface '{key}' does not exist")
        if key not in storage.available_commands:
            return reject(f"command interface '{key}' is not available")
    start, stop = _split(storage, start_interfaces), _split(storage, stop_interfaces)
    for entry in entries:
        name = entry.info.name
        if name not in start and name not in stop:
            continue
        state = entry.component.get_lifecycle_state()
        if state not in (State.INACTIVE, State.ACTIVE):
            return reject(f"hardware component '{name}' is '{state.label}', not inactive or active")
        if state is State.INACTIVE and start.get(name) and not allow_inactive:
            return reject(
                f"hardware component '{name}' is inactive; its command interfaces {start[name]} cannot be claimed"
            )
        if not ask_components:
            continue
        impl = entry.component.impl
        if hasattr(impl, "mode_switch_rejection"):
            impl.mode_switch_rejection = ""
        result = _call_hook(entry, "prepare_command_mode_switch", start.get(name, []), stop.get(name, []))
        if result is not ReturnType.OK:
            why = getattr(impl, "mode_switch_rejection", "")
            return _reject(
                f"hardware component '{name}' rejected the command mode switch "
                f"(start {start.get(name, [])}, stop {stop.get(name, [])})" + (f": {why}" if why else "")
            )
    return ""


def perform(
    entries: Sequence[ComponentEntry],
    storage: InterfaceStorage,
    start_interfaces: Sequence[str],
    stop_interfaces: Sequence[str],
) -> str:
    """Tell each component concerned (INACTIVE or ACTIVE) to switch mode, after a successful :func:`prepare`.

    Returns:
        ``""`` if every component did, else the reason for the last one that failed (each is logged).
    """
    start, stop = _split(storage, start_interfaces), _split(storage, stop_interfaces)
    error = ""
    for entry in entries:
        name = entry.info.name
        if name not in start and name not in stop:
            continue
        if entry.component.get_lifecycle_state() not in (State.INACTIVE, State.ACTIVE):
            continue
        if _call_hook(entry, "perform_command_mode_switch", start.get(name, []), stop.get(name, [])) is not ReturnType.OK:
            error = _reject(f"hardware component '{name}' failed to perform the command mode switch")
    return error


def _split(storage: InterfaceStorage, keys: Iterable[str]) -> dict[str, list[str]]:
    """Hardware keys by owning component (controller references are left out)."""
    out: dict[str, list[str]] = {}
    for k in keys:
        owner = storage.hardware_owner.get(k)
        if owner is not None:
            out.setdefault(owner, []).append(k)
    return out


def _reject(reason: str) -> str:
    _log.warning("%s", reason)
    return reason


def _call_hook(entry: ComponentEntry, hook: str, start: list[str], stop: list[str]) -> Any:
    try:
        return getattr(entry.component, hook)(start, stop)
    except Exception:  # noqa: BLE001 - learner code must not take the manager down
        _log.error("%s of hardware '%s' raised", hook, entry.info.name, exc_info=True)
        return ReturnType.ERROR
