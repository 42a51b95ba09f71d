"""Bring-up: the launch file of this library. Description + controllers YAML -> a running :class:`System`.

A ros2_control launch file runs xacro, starts ``ros2_control_node`` with the URDF and the controllers
YAML, and calls spawners. :func:`bringup` does the same in one call:

1. the description (a ``.xacro``/``.urdf`` path, URDF text, or a package name under ``descriptions/``)
   becomes URDF text, and its ``<ros2_control>`` tags become :class:`~rrbot_workshop.description.HardwareInfo`;
2. the resource manager loads the hardware and brings each component to its initial state
   (``hardware_components_initial_state`` of the controller manager, or ``hardware_initial_state``);
3. the controller manager is created with the YAML's parameters;
4. spawner semantics: controllers in ``spawn`` are loaded, configured and activated together in one
   strict switch; those in ``inactive`` are loaded and configured only.

The :class:`System` then runs on its clock: ``spin(seconds)`` advances simulated time cycle by cycle.
"""

from __future__ import annotations

import itertools
import logging
import sys
import types
from collections.abc import Iterable, Mapping
from pathlib import Path
from types import TracebackType
from typing import Any

from rrbot_workshop.bringup_inputs import controllers_config, description_to_urdf, hardware_initial_states
from rrbot_workshop.controller_manager.manager import ControllerManager
from rrbot_workshop.controller_manager.node_loop import run_cycles
from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.exceptions import ControllerNotFound, HardwareError, ParameterError
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.clock import Clock, WallClock, make_clock
from rrbot_workshop.middleware.controllers_yaml import ControllersConfig
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.topics import TopicBus

__all__ = ["bringup", "System", "current_system", "get_system", "systems"]

_log = logging.getLogger(__name__)

_SYSTEMS: dict[str, System] = {}
_CURRENT: list[str] = []
_COUNTER = itertools.count(1)


def systems() -> dict[str, System]:
    """Running systems by name (shut-down ones are removed)."""
    return dict(_SYSTEMS)


def current_system() -> System | None:
    """The system brought up last that is still running, or None."""
    return _SYSTEMS[_CURRENT[-1]] if _CURRENT else None


def get_system(name: str) -> System:
    """The running system called ``name``.

    Raises:
        KeyError: If there is none; the message lists the running ones.
    """
    try:
        return _SYSTEMS[name]
    except KeyError:
        raise KeyError(f"no running system '{name}' (running: {sorted(_SYSTEMS) or 'none'})") from None


class System:
    """A running robot: hardware, controllers, topic bus and clock.

    Made by :func:`bringup`; usable as a context manager (``shutdown`` on exit).

    Attributes:
        name: System name (for ``%control --system``).
        urdf: The processed URDF text.
        hardware_infos: The parsed ``<ros2_control>`` tags.
        bus: Topic bus.
        resource_manager: The resource manager.
        controller_manager: The controller manager.
        clock: The loop's clock.
    """

    def __init__(
        self,
        name: str,
        urdf: str,
        hardware_infos: list[HardwareInfo],
        controller_manager: ControllerManager,
        clock: Clock,
    ) -> None:
        self.name = name
        self.urdf = urdf
        self.hardware_infos = hardware_infos
        self.controller_manager = controller_manager
        self.resource_manager = controller_manager.resource_manager
        self.bus: TopicBus = controller_manager.bus
        self.clock = clock
        self._running = True
        self._background: Any = None
        self._spin_listeners: list[Any] = []

    # ----------------------------------------------------------------- time
    @property
    def time(self) -> float:
        """Current (simulated) time in [s]."""
        return self.clock.now()

    @property
    def period(self) -> float:
        """Control period in [s]."""
        return self.clock.period

    @property
    def running(self) -> bool:
        """False after :meth:`shutdown`."""
        return self._running

    def _check_running(self) -> None:
        if not self._running:
            raise HardwareError(f"system '{self.name}' is shut down; bring up a new one")

    def spin_cycles(self, n: int) -> float:
        """Run ``n`` control cycles; returns the time after the last one in [s].

        The cycles run as :func:`~rrbot_workshop.controller_manager.node_loop.run_cycles` runs them: with Python's
        garbage collector paused until the batch ends.

        Raises:
            HardwareError: If the system is shut down.
        """
        self._check_running()
        if isinstance(self.clock, WallClock):
            self.clock.reset_pacing()
        run_cycles(self.controller_manager.update, self.clock.tick, self.clock.period, int(n))
        for listener in list(self._spin_listeners):
            try:
                listener(self)
            except Exception:  # noqa: BLE001 - a panel's redraw must not stop the robot
                _log.error("spin listener %r raised", listener, exc_info=True)
        return self.clock.now()

    def add_spin_listener(self, fn: Any) -> Any:
        """Call ``fn(system)`` after every :meth:`spin_cycles` (each ``spin``, each batch of a background loop):
        panels redraw there, not in every cycle. Returns a remover."""
        self._spin_listeners.append(fn)

        def remove() -> None:
            if fn in self._spin_listeners:
                self._spin_listeners.remove(fn)

        return remove

    def spin_in_background(self, real_time_factor: float = 1.0, tick: float = 0.02) -> Any:
        """Keep the control loop running between cells, ``real_time_factor`` simulated seconds per wall second
        (see :mod:`rrbot_workshop.background`); a running background loop is replaced.

        Returns:
            The :class:`~rrbot_workshop.background.BackgroundSpinner` (``.stop()``, ``.running``, ``.error``).

        Raises:
            HardwareError: If the system is shut down, runs on a wall clock, or no event loop runs.
        """
        from rrbot_workshop.background import BackgroundSpinner

        self._check_running()
        self.stop_background()
        self._background = BackgroundSpinner(self, real_time_factor, tick)
        return self._background

    @property
    def background(self) -> Any:
        """The background loop started by :meth:`spin_in_background` while it spins, else None."""
        return self._background if self._background is not None and self._background.running else None

    def stop_background(self) -> None:
        """Stop the background loop, if one spins."""
        if self._background is not None:
            self._background.stop()
            self._background = None

    def spin(self, seconds: float) -> float:
        """Run for ``seconds`` [s] of (simulated) time, rounded to whole cycles; returns the time in [s]."""
        return self.spin_cycles(self.clock.cycles_for(seconds))

    def spin_until(self, predicate: Any, timeout: float) -> bool:
        """Run cycle by cycle until ``predicate()`` is true or ``timeout`` [s] of simulated time passes.

        Returns:
            Whether the predicate became true.
        """
        for _ in range(self.clock.cycles_for(timeout)):
            if predicate():
                return True
            self.spin_cycles(1)
        return bool(predicate())

    # ----------------------------------------------------------------- topics and services
    def publish(self, topic: str, msg: Any) -> None:
        """Publish ``msg`` on ``topic`` (delivered at the start of the next cycle)."""
        self.bus.publish(topic, msg)

    def latest(self, topic: str) -> Any:
        """Last message on ``topic``, or None."""
        return self.bus.latest(topic)

    def history(self, topic: str) -> list[Any]:
        """Messages published on ``topic``, oldest first."""
        return self.bus.history(topic)

    def call_service(self, name: str, request: Any = None) -> Any:
        """Call a service (e.g. ``"/controller_manager/list_controllers"``) and return its response."""
        return self.bus.call_service(name, request if request is not None else {})

    # ----------------------------------------------------------------- spawner
    def spawn(
        self,
        controllers: Iterable[str],
        *,
        inactive: bool = False,
        activate_as_group: bool = False,
        load_only: bool = False,
    ) -> None:
        """Start controllers on the running system, as ``ros2 run controller_manager spawner`` does.

        For each controller in order: load it (a controller already loaded is not loaded again; a warning
        says so), configure it, and activate it with a strict switch of its own. ``activate_as_group``
        activates them all in one strict switch after every one is configured (use it for a chain, whose
        members must become active together); ``inactive`` stops after configure, ``load_only`` after load.

        Args:
            controllers: Controller names, declared in the controllers YAML.
            inactive: Configure but do not activate (``--inactive``).
            activate_as_group: One switch for all (``--activate-as-group``).
            load_only: Load only (``--load-only``).

        Raises:
            ControllerNotFound: If a name is not declared in the controllers YAML.
            ControllerError: If loading or configuring fails (the spawner's exit code 1).
            SwitchError: If an activation is rejected; controllers spawned before it stay as they are,
                as with separate spawner calls.
        """
        self._check_running()
        names = list(controllers)
        if inactive and activate_as_group:
            raise ParameterError("spawn", "inactive/activate_as_group", "choose one: they contradict each other")
        cm = self.controller_manager
        for name in names:
            if name in cm.controllers:
                _log.warning("spawner: controller '%s' is already loaded, skipping load_controller", name)
            else:
                cm.load_controller(name)
            if load_only:
                continue
            if cm.controllers[name].state is not State.ACTIVE:
                cm.configure_controller(name)
            if not inactive and not activate_as_group:
                cm.switch_controllers(activate=[name], strictness="strict")
        if activate_as_group and not load_only:
            cm.switch_controllers(activate=names, strictness="strict")

    def unspawn(self, controllers: Iterable[str]) -> None:
        """Stop and unload controllers, as ``ros2 run controller_manager unspawner`` does.

        Each active controller is deactivated (one strict switch for all, so a chain can stop together),
        then each is unloaded.

        Raises:
            ControllerNotFound: If a name is not loaded.
            SwitchError: If the deactivation is rejected (nothing is unloaded then).
        """
        self._check_running()
        names = list(controllers)
        cm = self.controller_manager
        for name in names:
            cm.get_controller(name)  # raises ControllerNotFound with the loaded names
        active = [n for n in names if cm.controllers[n].state is State.ACTIVE]
        if active:
            cm.switch_controllers(deactivate=active, strictness="strict")
        for name in names:
            cm.unload_controller(name)

    # ----------------------------------------------------------------- end
    def shutdown(self) -> None:
        """Deactivate and unload controllers, shut the hardware down. Safe to call more than once."""
        if not self._running:
            return
        self._running = False
        self.stop_background()
        try:
            self.controller_manager.shutdown()
        finally:
            self.resource_manager.shutdown_components()
            _SYSTEMS.pop(self.name, None)
            if self.name in _CURRENT:
                _CURRENT.remove(self.name)

    def __enter__(self) -> System:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.shutdown()

    def __repr__(self) -> str:
        state = "running" if self._running else "shut down"
        return (
            f"System({self.name!r}, {state}, t={self.time:.3f} s, hardware={self.resource_manager.component_names()}, "
            f"controllers={list(self.controller_manager.controllers)})"
        )


# ===================================================================== bringup
def bringup(
    description: str | Path,
    controllers: str | Path | Mapping[str, Any] | ControllersConfig | None = None,
    xacro_args: Mapping[str, Any] | None = None,
    spawn: Iterable[str] = (),
    inactive: Iterable[str] = (),
    clock: str | Clock = "sim",
    hardware_initial_state: Mapping[str, str | State] | None = None,
    name: str | None = None,
) -> System:
    """Build and start a system from a description and a controllers YAML.

    Args:
        description: ``.xacro``/``.urdf`` path, URDF text, or a package name under ``descriptions/``
            (then ``urdf/<name>.urdf.xacro`` is used).
        controllers: Controllers YAML: a path, a file name under ``descriptions/<package>/config/``,
            YAML text, a mapping, or a :class:`ControllersConfig`. None: no controllers declared.
        xacro_args: Xacro arguments (``{"use_mock_hardware": True}``).
        spawn: Controllers to load, configure and activate (one strict switch for all).
        inactive: Controllers to load and configure only.
        clock: ``"sim"`` (deterministic, default), ``"wall"`` (paced to real time) or a clock object.
        hardware_initial_state: Component name -> ``"unconfigured"``/``"inactive"``/``"active"``;
            overrides ``hardware_components_initial_state`` from the YAML. Unlisted components become active.
        name: System name for ``%control --system``; the robot name (plus a number if taken) by default.

    Returns:
        The running :class:`System` (it becomes the "current" one for the magics).

    Raises:
        DescriptionError: If the description cannot be found or parsed.
        ParameterError: If the controllers YAML cannot be found or is malformed.
        HardwareError: If hardware cannot be loaded, or an initial state names an unknown component.
        ControllerNotFound: If a controller in ``spawn``/``inactive`` is not declared in the YAML.
        ControllerError: If a controller fails to load, configure or activate.
        SwitchError: If activating ``spawn`` is rejected.
    """
    from rrbot_workshop.description import parse_ros2_control

    urdf, package, source = description_to_urdf(description, xacro_args or {})
    cfg = controllers_config(controllers, package)
    infos = parse_ros2_control(urdf, source=source)
    spawn, inactive = list(spawn), list(inactive)
    both = sorted(set(spawn) & set(inactive))
    if both:
        raise ParameterError("bringup", "spawn/inactive", f"{both} appear in both lists; choose one")
    for ctrl in [*spawn, *inactive]:
        if ctrl not in cfg.controller_types and "type" not in cfg.parameters_for(ctrl):  # '/**' may give the type
            raise ControllerNotFound(ctrl, cfg.controller_types, what=f"declared in the controllers config ({cfg.source})")

    the_clock = make_clock(clock, cfg.update_rate)
    rm = ResourceManager(update_rate=cfg.update_rate, initial_states=hardware_initial_states(cfg, hardware_initial_state))
    rm.load_hardware_infos(infos)
    cm = ControllerManager(rm, TopicBus(), cfg.update_rate, urdf, cfg, the_clock)
    if name is None:
        import re

        match = re.search(r"<robot[^>]*\bname\s*=\s*[\"']([^\"']+)", urdf)
        base = match.group(1) if match else "system"
        name = base if base not in _SYSTEMS else f"{base}_{next(_COUNTER)}"
        while name in _SYSTEMS:
            name = f"{base}_{next(_COUNTER)}"
    elif name in _SYSTEMS:
        raise HardwareError(f"a system named '{name}' is already running; shut it down or pick another name")
    system = System(name, urdf, infos, cm, the_clock)
    try:
        for ctrl in [*spawn, *inactive]:
            cm.load_controller(ctrl)
            cm.configure_controller(ctrl)
        if spawn:
            cm.switch_controllers(activate=spawn, strictness="strict")
    except Exception:
        system._running = True
        system.shutdown()
        raise
    _SYSTEMS[name] = system
    _CURRENT.append(name)
    _log.info("brought up '%s': hardware %s, active %s", name, rm.component_names(), spawn)
    return system


class _CallableModule(types.ModuleType):
    """``import rrbot_workshop.bringup`` binds the package attribute ``bringup`` to this module, which would
    hide the function of the same name (``rw.bringup(...)``). Calling the module therefore calls the function."""

    def __call__(self, *args: Any, **kwargs: Any) -> System:
        return bringup(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
sys.modules[__name__].__wrapped__ = bringup  # type: ignore[attr-defined]  # inspect.signature shows bringup's
