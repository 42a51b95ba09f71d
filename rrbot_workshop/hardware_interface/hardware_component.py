"""The lifecycle wrapper the resource manager holds around each hardware implementation.

ros2_control keeps the user's ``SystemInterface`` (or actuator, or sensor) inside a small object,
``hardware_interface::HardwareComponent``, that owns the state machine. The user's class only answers
callbacks (``on_configure`` ...); the wrapper decides whether a call is allowed in the current state,
which state follows each result, and when ``error()`` runs. :class:`HardwareComponent` is that object.

The transition table (ros2_control ``hardware_component.cpp``):

============  ===========================  ============  ============  =========
call          allowed from                 SUCCESS       FAILURE       ERROR
============  ===========================  ============  ============  =========
initialize    unknown                      unconfigured  finalized     finalized
configure     unconfigured                 inactive      unconfigured  error()
cleanup       inactive                     unconfigured  error()       error()
activate      inactive                     active        inactive      error()
deactivate    active                       inactive      active        error()
shutdown      not unknown, not finalized   finalized     error()       error()
error()       not unknown, not unconfigured  unconfigured  finalized   finalized
============  ===========================  ============  ============  =========

A call from any other state changes nothing and returns the current state. Note that ``error()`` does
nothing in ``unconfigured``: a configure that returns ERROR leaves the component unconfigured without
calling ``on_error``.

Unlike C++, Python code can raise anywhere. As ros2_control's ``handle_exceptions`` does, an exception
raised by a callback, ``read`` or ``write`` is caught, logged with its traceback, kept in
:attr:`HardwareComponent.last_error`, and treated as ERROR; the notebook kernel keeps running.
"""

from __future__ import annotations

import builtins
import logging
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.exceptions import HardwareError
from rrbot_workshop.hardware_interface.component_interface import HardwareComponentInterface
from rrbot_workshop.hardware_interface.handles import CommandInterface, StateInterface
from rrbot_workshop.middleware.lifecycle import TRANSITIONS, CallbackReturn, ReturnType, State

__all__ = ["HardwareComponent", "HardwareComponentInfo"]

_log = logging.getLogger(__name__)

#: Marks "the implementation raised" (distinct from any value it could return).
_RAISED = object()
_READABLE = (State.INACTIVE, State.ACTIVE)


def _reraise(exc: BaseException | None) -> Any:
    """Raise ``exc`` again inside :meth:`HardwareComponent._call`, so it is logged with its traceback there."""
    assert exc is not None
    raise exc


@dataclass
class HardwareComponentInfo:
    """Status of one hardware component, as ``controller_manager_msgs/HardwareComponentState`` reports it.

    Attributes:
        name: Component name (``name`` of its ``<ros2_control>`` tag).
        type: ``"system"``, ``"actuator"`` or ``"sensor"``.
        plugin_name: ``<hardware><plugin>`` text, e.g. ``"mock_components/GenericSystem"``.
        group: ``<hardware><group>`` name, or ``""``.
        state: Current lifecycle state.
        is_async: Whether the component asked for its own thread (``is_async`` attribute).
        rw_rate: Read/write rate in [Hz] (the resource manager replaces 0 by the controller manager's rate).
        command_interfaces: Full names of the exported command interfaces, in export order.
        state_interfaces: Full names of the exported state interfaces, in export order.
    """

    name: str
    type: str
    plugin_name: str
    group: str
    state: State
    is_async: bool = False
    rw_rate: int = 0
    command_interfaces: list[str] = field(default_factory=list)
    state_interfaces: list[str] = field(default_factory=list)


class HardwareComponent:
    """Runs the hardware lifecycle for one implementation (``hardware_interface::HardwareComponent``).

    Args:
        impl: A fresh, uninitialised hardware implementation (a :class:`SystemInterface`,
            :class:`ActuatorInterface` or :class:`SensorInterface` subclass instance).

    Example:
        >>> component = HardwareComponent(GenericSystem())
        >>> component.initialize(info)            # State.UNCONFIGURED
        >>> states = component.export_state_interfaces()
        >>> component.configure(); component.activate()
        >>> component.read(0.0, 0.01)             # ReturnType.OK
    """

    #: ros2_control's ``handle_exceptions`` (the resource manager sets it): False lets an exception from the
    #: implementation's ``read``/``write`` propagate to the caller instead of becoming ERROR.
    handle_exceptions: bool = True

    def __init__(self, impl: HardwareComponentInterface) -> None:
        self._impl = impl
        self._exported: tuple[list[StateInterface], list[CommandInterface]] | None = None
        self._last_error: BaseException | None = None

    # ----------------------------------------------------------------- identity
    @property
    def impl(self) -> HardwareComponentInterface:
        """The wrapped implementation."""
        return self._impl

    @property
    def info(self) -> HardwareInfo:
        """The implementation's ``HardwareInfo`` (empty until :meth:`initialize`)."""
        return self._impl.info

    @property
    def name(self) -> str:
        """Component name, the ``name`` of its ``<ros2_control>`` tag."""
        return self._impl.info.name

    @property
    def type(self) -> str:
        """``"system"``, ``"actuator"`` or ``"sensor"`` (from the description, else from the class)."""
        return self._impl.info.type or self._impl.component_type

    @property
    def group(self) -> str:
        """``<hardware><group>`` name, or ``""``."""
        return self._impl.info.group

    @property
    def plugin_name(self) -> str:
        """``<hardware><plugin>`` text, or ``""``."""
        return self._impl.info.hardware_plugin_name

    @property
    def last_error(self) -> BaseException | None:
        """The last exception raised by the implementation and caught here, or None."""
        return self._last_error

    def get_name(self) -> str:
        """Component name (ros2_control spelling of :attr:`name`)."""
        return self.name

    def get_group_name(self) -> str:
        """Group name (ros2_control spelling of :attr:`group`)."""
        return self.group

    def get_lifecycle_state(self) -> State:
        """Current lifecycle state."""
        return self._impl._lifecycle_state

    def _set_state(self, state: State) -> None:
        self._impl._lifecycle_state = state
        TRANSITIONS.bump()  # the compiled cycles rebuild their plans

    # ----------------------------------------------------------------- callback plumbing
    def _call(self, what: str, fn: Callable[..., Any], *args: Any) -> Any:
        """Call ``fn``; on an exception log it with its traceback and return :data:`_RAISED`."""
        try:
            return fn(*args)
        except Exception as exc:  # noqa: BLE001 - learner code may raise anything (handle_exceptions)
            self._last_error = exc
            _log.error(
                "hardware '%s': %s raised %s: %s; treated as ERROR",
                self.name or type(self._impl).__name__,
                what,
                type(exc).__name__,
                exc,
                exc_info=True,
            )
            return _RAISED

    def _checked(self, what: str, expected: builtins.type[Any], fn: Callable[..., Any], *args: Any) -> Any:
        """Call ``fn``; return its result if it is an ``expected`` member, else None (logged)."""
        result = self._call(what, fn, *args)
        if isinstance(result, expected):
            return result
        if result is not _RAISED:
            _log.error(
                "hardware '%s': %s returned %r, expected a %s; treated as ERROR",
                self.name or type(self._impl).__name__,
                what,
                result,
                expected.__name__,
            )
        return None

    def _callback(self, what: str, fn: Callable[[State], Any]) -> CallbackReturn:
        """Run a lifecycle callback with the current state; exceptions and bad results become ERROR."""
        result = self._checked(what, CallbackReturn, fn, self.get_lifecycle_state())
        return CallbackReturn.ERROR if result is None else result

    def _return_type(self, what: str, fn: Callable[..., Any], *args: Any) -> ReturnType:
        """Run ``read``/``write``/mode-switch hooks; exceptions and results that are not ReturnType become ERROR."""
        result = self._checked(what, ReturnType, fn, *args)
        return ReturnType.ERROR if result is None else result

    # ----------------------------------------------------------------- transitions
    def initialize(self, info: HardwareInfo) -> State:
        """Call ``on_init(info)`` (allowed from ``unknown`` only).

        Args:
            info: Parsed ``<ros2_control>`` tag of this component.

        Returns:
            ``unconfigured`` on SUCCESS, ``finalized`` on FAILURE, ERROR or an exception.
        """
        if self.get_lifecycle_state() is State.UNKNOWN:
            result = self._checked("on_init", CallbackReturn, self._impl.on_init, info)
            self._set_state(State.UNCONFIGURED if result is CallbackReturn.SUCCESS else State.FINALIZED)
        return self.get_lifecycle_state()

    def configure(self) -> State:
        """Call ``on_configure`` (allowed from ``unconfigured``): inactive / unconfigured / ``error()``.

        The interfaces are exported first if nobody asked for them yet, so ``on_configure`` can use
        ``get_state``/``set_state``.

        Raises:
            HardwareError: If that export fails (the state stays ``unconfigured``).
        """
        if self.get_lifecycle_state() is State.UNCONFIGURED:
            self._ensure_exported()
            result = self._callback("on_configure", self._impl.on_configure)
            self._finish(result, success=State.INACTIVE, failure=State.UNCONFIGURED, what="on_configure")
        return self.get_lifecycle_state()

    def cleanup(self) -> State:
        """Call ``on_cleanup`` (allowed from ``inactive``): unconfigured / ``error()`` / ``error()``."""
        if self.get_lifecycle_state() is State.INACTIVE:
            result = self._callback("on_cleanup", self._impl.on_cleanup)
            self._finish(result, success=State.UNCONFIGURED, failure=None, what="on_cleanup")
        return self.get_lifecycle_state()

    def activate(self) -> State:
        """Call ``on_activate`` (allowed from ``inactive``): active / inactive / ``error()``."""
        if self.get_lifecycle_state() is State.INACTIVE:
            result = self._callback("on_activate", self._impl.on_activate)
            self._finish(result, success=State.ACTIVE, failure=State.INACTIVE, what="on_activate")
        return self.get_lifecycle_state()

    def deactivate(self) -> State:
        """Call ``on_deactivate`` (allowed from ``active``): inactive / active / ``error()``."""
        if self.get_lifecycle_state() is State.ACTIVE:
            result = self._callback("on_deactivate", self._impl.on_deactivate)
            self._finish(result, success=State.INACTIVE, failure=State.ACTIVE, what="on_deactivate")
        return self.get_lifecycle_state()

    def shutdown(self) -> State:
        """Call ``on_shutdown`` (allowed unless ``unknown`` or ``finalized``): finalized / ``error()`` / ``error()``."""
        if self.get_lifecycle_state() not in (State.UNKNOWN, State.FINALIZED):
            result = self._callback("on_shutdown", self._impl.on_shutdown)
            self._finish(result, success=State.FINALIZED, failure=None, what="on_shutdown")
        return self.get_lifecycle_state()

    def error(self) -> State:
        """Call ``on_error`` (allowed unless ``unknown`` or ``unconfigured``): unconfigured / finalized / finalized."""
        if self.get_lifecycle_state() not in (State.UNKNOWN, State.UNCONFIGURED):
            result = self._callback("on_error", self._impl.on_error)
            self._set_state(State.UNCONFIGURED if result is CallbackReturn.SUCCESS else State.FINALIZED)
        return self.get_lifecycle_state()

    def _finish(self, result: CallbackReturn, success: State, failure: State | None, what: str = "") -> None:
        """Apply one row of the table; ``failure=None`` means FAILURE also goes through ``error()``. A result other
        than SUCCESS is logged with the state it leads to, as Jazzy's resource manager does."""
        if result is CallbackReturn.SUCCESS:
            self._set_state(success)
            return
        before = self.get_lifecycle_state()
        if result is CallbackReturn.FAILURE and failure is not None:
            self._set_state(failure)
        else:
            self.error()
        _log.error("hardware '%s': %s returned %s in '%s'; it is now '%s'", self.name or type(self._impl).__name__,
                   what or "a transition", result.value.upper(), before.label, self.get_lifecycle_state().label)

    # ----------------------------------------------------------------- interfaces
    def _ensure_exported(self) -> tuple[list[StateInterface], list[CommandInterface]]:
        if self._exported is None:
            try:
                states = list(self._impl.export_state_interfaces())
                commands = list(self._impl.export_command_interfaces())
            except Exception as exc:
                self._last_error = exc
                raise HardwareError(
                    f"hardware '{self.name}' ({type(self._impl).__name__}) failed to export its interfaces: "
                    f"{type(exc).__name__}: {exc}"
                ) from exc
            self._impl._register_handles(states, commands)
            self._exported = (states, commands)
        return self._exported

    def export_state_interfaces(self) -> list[StateInterface]:
        """The component's state interfaces (exported once; later calls return the same handles).

        The first call to either export method asks the implementation for both its state and command
        interfaces and registers them on it, so ``get_state``/``set_command`` by name work.

        Raises:
            HardwareError: If the implementation raised while exporting (e.g. an unsupported data type).
        """
        return list(self._ensure_exported()[0])

    def export_command_interfaces(self) -> list[CommandInterface]:
        """The component's command interfaces (exported once; later calls return the same handles).

        Raises:
            HardwareError: If the implementation raised while exporting.
        """
        return list(self._ensure_exported()[1])

    def component_info(self, rw_rate: int | None = None) -> HardwareComponentInfo:
        """A status snapshot for ``list_hardware_components``.

        Args:
            rw_rate: Effective read/write rate in [Hz]; defaults to the description's ``rw_rate``.
        """
        states, commands = self._exported if self._exported is not None else ([], [])
        return HardwareComponentInfo(
            name=self.name,
            type=self.type,
            plugin_name=self.plugin_name,
            group=self.group,
            state=self.get_lifecycle_state(),
            is_async=self.info.is_async,
            rw_rate=self.info.rw_rate if rw_rate is None else rw_rate,
            command_interfaces=[h.name for h in commands],
            state_interfaces=[h.name for h in states],
        )

    # ----------------------------------------------------------------- mode switching
    def prepare_command_mode_switch(self, start_interfaces: Sequence[str], stop_interfaces: Sequence[str]) -> ReturnType:
        """Ask the implementation whether the new command mode is possible; an exception gives ERROR.

        Args:
            start_interfaces: This component's command interfaces about to be claimed.
            stop_interfaces: This component's command interfaces about to be released.
        """
        return self._return_type(
            "prepare_command_mode_switch",
            self._impl.prepare_command_mode_switch,
            list(start_interfaces),
            list(stop_interfaces),
        )

    def perform_command_mode_switch(self, start_interfaces: Sequence[str], stop_interfaces: Sequence[str]) -> ReturnType:
        """Tell the implementation to switch mode (real-time side); an exception gives ERROR."""
        return self._return_type(
            "perform_command_mode_switch",
            self._impl.perform_command_mode_switch,
            list(start_interfaces),
            list(stop_interfaces),
        )

    # ----------------------------------------------------------------- cyclic
    def read(self, time: float, period: float) -> ReturnType:
        """Call the implementation's ``read`` in ``inactive`` or ``active``; elsewhere return OK.

        ERROR (or an exception) calls :meth:`error`. DEACTIVATE is returned unchanged for the resource
        manager to act on.

        Args:
            time: Current time in [s].
            period: Time since the last read in [s].
        """
        if self._impl._lifecycle_state not in _READABLE:
            return ReturnType.OK
        if self._exported is None:
            self._ensure_exported()
        try:  # the common case inline; exceptions and wrong results take the logged path of settle
            result = self._impl.read(time, period)
        except Exception:  # noqa: BLE001 - learner code may raise anything (handle_exceptions)
            return self.settle("read", None, sys.exc_info()[1])
        return result if result is ReturnType.OK else self.settle("read", result)

    def write(self, time: float, period: float) -> ReturnType:
        """Call the implementation's ``write`` in ``active`` only; sensors never write.

        In every other state (and always for sensors) this returns OK without calling the implementation.
        ERROR (or an exception) calls :meth:`error`; DEACTIVATE is returned unchanged.

        Args:
            time: Current time in [s].
            period: Time since the last write in [s].
        """
        if self._impl._lifecycle_state is not State.ACTIVE or self.type == "sensor":
            return ReturnType.OK
        if self._exported is None:
            self._ensure_exported()
        try:
            result = self._impl.write(time, period)
        except Exception:  # noqa: BLE001 - learner code may raise anything (handle_exceptions)
            return self.settle("write", None, sys.exc_info()[1])
        return result if result is ReturnType.OK else self.settle("write", result)

    def settle(self, what: str, result: Any, exc: BaseException | None = None) -> ReturnType:
        """What a ``read``/``write`` of the implementation amounts to when it did not return OK.

        An exception (``exc``) is logged with its traceback and becomes ERROR, a result that is not a ReturnType is
        logged and becomes ERROR, and ERROR puts the component through :meth:`error`. DEACTIVATE is returned unchanged.
        The resource manager's compiled cycle calls the implementation itself and hands this its outcome, so both
        paths behave the same.

        Args:
            what: ``"read"`` or ``"write"``.
            result: What the implementation returned (ignored when ``exc`` is given).
            exc: What the implementation raised, if anything.
        """
        if exc is not None:
            if not self.handle_exceptions:  # ros2_control's handle_exceptions false: the caller gets it
                raise exc
            result = self._return_type(what, _reraise, exc)
        elif result.__class__ is not ReturnType:
            result = self._return_type(what, lambda: result)
        if result is ReturnType.ERROR:
            self.error()
        return result

    def __repr__(self) -> str:
        return f"HardwareComponent({self.name!r}, type={self.type!r}, state={self.get_lifecycle_state().label!r})"
