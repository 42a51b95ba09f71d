"""The running robot: :class:`System` (hardware, controllers, topic bus and clock) and the registry of running ones.

A :class:`System` is what :func:`~rrbot_workshop.bringup.bringup` returns: the stand-in for a running
``ros2_control_node`` with its spawners done. It runs on its clock (``spin(seconds)`` advances simulated time cycle
by cycle), takes topics and service calls, spawns and unspawns controllers, and can keep spinning between notebook
cells (:mod:`rrbot_workshop.bringup.spinner`). Running systems are kept by name for the magics (``%control
--system``).
"""

from __future__ import annotations

import itertools
import logging
import re
import shlex
from collections.abc import Iterable, Mapping
from fractions import Fraction
from pathlib import Path
from types import TracebackType
from typing import Any

from rrbot_workshop.controller_manager.manager import ControllerManager
from rrbot_workshop.controller_manager.node_loop import run_cycles
from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.exceptions import HardwareError, ParameterError
from rrbot_workshop.middleware.arguments import callable_argument, name_list, number, whole_number
from rrbot_workshop.middleware.clock import Clock, WallClock
from rrbot_workshop.middleware.controllers_yaml import (
    MANAGER_NODE,
    ControllersConfig,
    node_key_matches,
    normalize_namespace,
)
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.topics import TopicBus

__all__ = ["MAX_SPIN_CYCLES", "System", "current_system", "get_system", "systems", "register", "unique_name", "namespaced", "shared_graph"]

_log = logging.getLogger(__name__)

#: The most control cycles one ``spin``, ``spin_cycles`` or ``spin_until`` call may run: the work of one call stays
#: bounded (10,000 s of simulated time at 100 Hz); spin in a loop for longer runs.
MAX_SPIN_CYCLES = 1_000_000

_SYSTEMS: dict[str, System] = {}
_CURRENT: list[str] = []
_COUNTER = itertools.count(1)
_GRAPH: list[TopicBus] = []  # the topic graph the systems with a namespace share (one, while any of them runs)


def shared_graph(manager_name: str) -> TopicBus:
    """The topic bus shared by the running systems with a namespace: one ROS graph, where each controller manager
    and its controllers live under their own namespace. A new one when none of them runs.

    Args:
        manager_name: Fully qualified name of the controller manager about to join (``/rrbot_1/controller_manager``).

    Raises:
        HardwareError: If a running system already has a controller manager of that name.
    """
    running = [s for s in _SYSTEMS.values() if s.namespace != "/"]
    for other in running:
        if other.controller_manager.name == manager_name:
            raise HardwareError(f"a controller manager {manager_name} already runs (system '{other.name}'); shut it "
                                "down or bring this one up in another namespace")
    if not running or not _GRAPH:
        _GRAPH[:] = [TopicBus()]
    return _GRAPH[0]


def namespaced(cfg: ControllersConfig, namespace: str | None) -> ControllersConfig:
    """The controllers config as the nodes of ``namespace`` read it (``cfg``'s own namespace if None).

    Raises:
        ParameterError: If the namespace is not valid, or the file configures controller managers only in other
            namespaces (the message names them and the ``namespace=`` to pass).
    """
    ns = normalize_namespace(namespace) if namespace is not None else cfg.namespace
    if ns != cfg.namespace:
        cfg = cfg.for_namespace(ns)
    mine = any(key.rsplit("/", 1)[-1] == MANAGER_NODE and node_key_matches(key, cfg.manager_name)
               for key, _ in cfg.sections)
    others = [n for n in cfg.manager_namespaces() if n != ns]
    if cfg.sections and not mine and others:
        raise ParameterError("controllers file", cfg.source, f"configures the controller manager {others[0]}/"
                             f"{MANAGER_NODE} but not {cfg.manager_name}, as ROS 2 matches node names: bring it up "
                             f"in that namespace, bringup(..., namespace='{others[0]}')")
    return cfg


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
        namespace: The namespace of the controller manager and its controllers (``"/"`` unless given to bringup).
        clock: The loop's clock.
        mocked_hardware: Component name -> the plugin that ``bringup(..., mock_hardware=...)`` replaced by a mock.
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
        self.namespace: str = controller_manager.namespace
        self.clock = clock
        self.mocked_hardware: dict[str, str] = {}
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

    def spin_cycles(self, n: int, since: Fraction | None = None) -> float:
        """Run ``n`` control cycles; returns the time after the last one in [s] (plus ``since``, the time run after
        it, as :meth:`~rrbot_workshop.middleware.clock.Clock.plan` gives it; None keeps the time already run since the
        last cycle when ``n`` is 0, and none is left after a cycle).

        The cycles run as :func:`~rrbot_workshop.controller_manager.node_loop.run_cycles` runs them: with Python's
        garbage collector paused until the batch ends.

        Raises:
            HardwareError: If the system is shut down.
            ArgumentError: If ``n`` is not a whole number from 0 to :data:`MAX_SPIN_CYCLES`.
        """
        self._check_running()
        n = whole_number("System.spin_cycles", "n", n, high=MAX_SPIN_CYCLES)
        if isinstance(self.clock, WallClock):
            self.clock.reset_pacing()
        run_cycles(self.controller_manager.update, self.clock.tick, self.clock.period, n)
        if since is not None:
            self.clock.advance(since)
        for listener in list(self._spin_listeners):
            try:
                listener(self)
            except Exception:  # noqa: BLE001 - a panel's redraw must not stop the robot
                _log.error("spin listener %r raised", listener, exc_info=True)
        return self.clock.now()

    def add_spin_listener(self, fn: Any) -> Any:
        """Call ``fn(system)`` after every :meth:`spin_cycles` (each ``spin``, each batch of a background loop):
        panels redraw there, not in every cycle. Returns a remover.

        Raises:
            ArgumentError: If ``fn`` cannot be called.
        """
        callable_argument("System.add_spin_listener", "listener", fn, "a function taking the system")
        self._spin_listeners.append(fn)

        def remove() -> None:
            if fn in self._spin_listeners:
                self._spin_listeners.remove(fn)

        return remove

    def spin_in_background(self, real_time_factor: float = 1.0, tick: float = 0.02) -> Any:
        """Keep the control loop running between cells, ``real_time_factor`` simulated seconds per wall second
        (see :mod:`rrbot_workshop.bringup.spinner`); a running background loop is replaced.

        Returns:
            The :class:`~rrbot_workshop.bringup.spinner.BackgroundSpinner` (``.stop()``, ``.running``, ``.error``).

        Raises:
            HardwareError: If the system is shut down, runs on a wall clock, or no event loop runs.
        """
        from rrbot_workshop.bringup.spinner import BackgroundSpinner

        self._check_running()
        BackgroundSpinner.check_arguments(self, real_time_factor, tick)  # a refused request leaves the running loop
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

    def _cycles(self, function: str, argument: str, seconds: Any) -> int:
        """Whole cycles in ``seconds`` [s], refused unless a finite number >= 0 of at most :data:`MAX_SPIN_CYCLES`."""
        seconds = number(function, argument, seconds, low=0.0, high=MAX_SPIN_CYCLES * self.clock.period)
        return self.clock.cycles_for(seconds)

    def spin(self, seconds: float) -> float:
        """Run for ``seconds`` [s] of (simulated) time; returns the time in [s].

        Time advances by exactly ``seconds`` (read as a fraction: ``1/30`` is one thirtieth), and every cycle whose
        time falls within them runs, at the manager's rate (each controller at its own). Time between cycles carries
        over to the next call: ``spin(1/30)`` six times on a 10 Hz loop runs the same two cycles as ``spin(0.2)``.

        Raises:
            HardwareError: If the system is shut down.
            ArgumentError: If ``seconds`` is not a finite number >= 0, or needs more than :data:`MAX_SPIN_CYCLES`
                cycles (spin in a loop for longer runs).
        """
        self._check_running()
        seconds = number("System.spin", "seconds", seconds, low=0.0, high=(MAX_SPIN_CYCLES - 1) * self.clock.period)
        cycles, since = self.clock.plan(seconds)
        return self.spin_cycles(cycles, since=since)

    def spin_until(self, predicate: Any, timeout: float) -> bool:
        """Run cycle by cycle until ``predicate()`` is true or ``timeout`` [s] of simulated time passes.

        Returns:
            Whether the predicate became true.

        Raises:
            ArgumentError: If ``predicate`` cannot be called, or ``timeout`` is not a finite number >= 0 of at most
                :data:`MAX_SPIN_CYCLES` cycles.
        """
        callable_argument("System.spin_until", "predicate", predicate, "a function taking no argument")
        for _ in range(self._cycles("System.spin_until", "timeout", timeout)):
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
        param_file: str | Path | Iterable[str | Path] | None = None,
        controller_ros_args: str | None = None,
        remap: Mapping[str, str] | None = None,
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
            param_file: ``--param-file``: one file or several, given to each controller as Jazzy's spawner does
                (its ``type`` and its parameters for the controller, over the controllers YAML; see
                :meth:`~rrbot_workshop.controller_manager.manager.ControllerManager.load_controller`). ``$(var ...)``
                in it take the system's ``launch_args``.
            controller_ros_args: ``--controller-ros-args`` text, e.g. ``"-r ~/cmd_vel:=/cmd_vel"`` (remaps) or
                ``"-p name:=value"``, for each controller's node.
            remap: Remap rules as a mapping, ``{"~/cmd_vel": "/cmd_vel"}`` (added after ``controller_ros_args``).

        Raises:
            ControllerNotFound: If a name is not declared in the controllers YAML.
            ControllerError: If loading or configuring fails (the spawner's exit code 1).
            SwitchError: If an activation is rejected; controllers spawned before it stay as they are,
                as with separate spawner calls.
            ArgumentError: If ``controllers`` is not a name or a list of names.
        """
        self._check_running()
        names = name_list("System.spawn", "controllers", controllers)
        if inactive and activate_as_group:
            raise ParameterError("spawn", "inactive/activate_as_group", "choose one: they contradict each other")
        cm = self.controller_manager
        files = [] if param_file is None else [param_file] if isinstance(param_file, str | Path) else list(param_file)
        ros_args = shlex.split(controller_ros_args) if controller_ros_args else []
        for match, replacement in (remap or {}).items():
            ros_args += ["-r", f"{match}:={replacement}"]
        for name in names:
            if name in cm.controllers:
                _log.warning("spawner: controller '%s' is already loaded, skipping load_controller", name)
            else:
                for extra in files[:-1]:
                    if not cm.params.use_param_file(name, extra, cm.launch_args):
                        _log.warning("parameter file %s has no section for '%s'; it is not used", extra, name)
                cm.load_controller(name, param_file=files[-1] if files else None,
                                   ros_args=ros_args if ros_args else None)
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
            ArgumentError: If ``controllers`` is not a name or a list of names.
        """
        self._check_running()
        names = name_list("System.unspawn", "controllers", controllers)
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


def unique_name(urdf: str, name: str | None) -> str:
    """The name a new system gets: ``name`` if free, else the robot's name (plus a number if taken).

    Raises:
        HardwareError: If ``name`` is given and a running system has it.
    """
    if name is not None:
        if name in _SYSTEMS:
            raise HardwareError(f"a system named '{name}' is already running; shut it down or pick another name")
        return name
    match = re.search(r"<robot[^>]*\bname\s*=\s*[\"']([^\"']+)", urdf)
    base = match.group(1) if match else "system"
    name = base if base not in _SYSTEMS else f"{base}_{next(_COUNTER)}"
    while name in _SYSTEMS:
        name = f"{base}_{next(_COUNTER)}"
    return name


def register(system: System) -> None:
    """Keep ``system`` as a running one and make it the current system."""
    _SYSTEMS[system.name] = system
    _CURRENT.append(system.name)
