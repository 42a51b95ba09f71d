"""The resource manager: owns the hardware components and every interface handle.

It loads one component per ``<ros2_control>`` tag (by plugin name), drives their lifecycles, keeps the
interface storage (which names exist, are available, are claimed and by whom), routes command-mode
switches to the components concerned, and calls ``read``/``write`` on all components each cycle.

Rules kept from ros2_control (``hardware_interface/src/resource_manager.cpp``):

* an interface is available while its component is INACTIVE or ACTIVE (configure makes state *and*
  command interfaces available; deactivate keeps them; cleanup, shutdown and error remove them);
* ``read``/``write`` go through actuators, then sensors, then systems; a component whose call returns
  ERROR or raises is put through ``error()``, its interfaces become unavailable and its name is
  reported, while the others keep running; a ``<group>`` fails together;
* DEACTIVATE from ``write`` makes the component INACTIVE (DEACTIVATE from ``read`` counts as an error);
* a component with ``rw_rate`` below the manager's rate is called only on the cycles that keep its rate.

This class holds the components and their lifecycles; the interface API it offers comes from
:class:`~rrbot_workshop.hardware_interface.resource_interfaces.ResourceInterfaces`, and the steps live next to it:
:mod:`~rrbot_workshop.hardware_interface.resource_loading` (plugins, ``on_init``, exported handles),
:mod:`~rrbot_workshop.hardware_interface.resource_cycle` (``read``/``write`` and failures) and
:mod:`~rrbot_workshop.hardware_interface.resource_mode_switch` (command mode switches).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.exceptions import HardwareError, JointLimitsError
from rrbot_workshop.hardware_interface import resource_mode_switch
from rrbot_workshop.hardware_interface.hardware_component import HardwareComponent, HardwareComponentInfo
from rrbot_workshop.hardware_interface.joint_limits import make_limiter
from rrbot_workshop.hardware_interface.resource_cycle import HardwareCycle, HardwareReadWriteStatus
from rrbot_workshop.hardware_interface.resource_interfaces import ResourceInterfaces
from rrbot_workshop.hardware_interface.resource_loading import ComponentEntry, check_infos, cycle_order, load_component
from rrbot_workshop.joint_limits import (
    JointControlInterfacesData,
    JointLimits,
    JointSaturationLimiter,
    SoftJointLimits,
    get_joint_limits,
    get_soft_joint_limits,
    joint_limits_parameters,
)
from rrbot_workshop.middleware.lifecycle import State

__all__ = ["ResourceManager", "HardwareReadWriteStatus", "HardwareComponentInfo"]

_log = logging.getLogger(__name__)

#: Interfaces a joint limiter limits (command) and reads (state).
_LIMITED_KINDS = ("position", "velocity", "effort", "acceleration")


@dataclass
class _JointLimiterEntry:
    """One joint's limiter and the full names of its interfaces by kind."""

    joint: str
    limiter: JointSaturationLimiter
    commands: dict[str, str]
    states: dict[str, str]
    reported: bool = False  # an out-of-bounds error was logged (once until the joint is back)


class ResourceManager(ResourceInterfaces):
    """Hardware components and their interfaces.

    Args:
        urdf: URDF text with ``<ros2_control>`` tags to load right away (or None: load later).
        update_rate: Controller manager rate in [Hz] (the default ``rw_rate``).
        activate_all: Bring every component to ACTIVE after loading (unless ``initial_states`` says
            otherwise); False leaves them UNCONFIGURED.
        initial_states: Component name -> state to reach after loading (``hardware_components_initial_state``).
        allow_controller_activation_with_inactive_hardware: Let controllers claim command interfaces of
            INACTIVE components (ros2_control's parameter of that name, default false).
    """

    def __init__(
        self,
        urdf: str | None = None,
        update_rate: int = 100,
        activate_all: bool = True,
        initial_states: Mapping[str, State] | None = None,
        allow_controller_activation_with_inactive_hardware: bool = False,
    ) -> None:
        self.update_rate = update_rate
        self.activate_all = activate_all
        self.allow_controller_activation_with_inactive_hardware = allow_controller_activation_with_inactive_hardware
        super().__init__()
        self._initial_states = dict(initial_states or {})
        self._handle_exceptions = True
        #: Why the last prepare/perform command mode switch returned False ("" if it did not).
        self.last_switch_error = ""
        self._entries: dict[str, ComponentEntry] = {}
        self._cycle_order: list[ComponentEntry] = []
        #: The compiled read/write plan (see resource_cycle.HardwareCycle).
        self._cycle = HardwareCycle(update_rate, self._storage, self.set_component_state)
        #: Joint limiters by component name, built on the first enforce_command_limits() after a load.
        self._limiters: dict[str, list[_JointLimiterEntry]] = {}
        #: ``{"joint_limits": {joint: {key: value}}}`` over the description's limits (set_joint_limits_parameters).
        self._joint_limits_params: dict[str, Any] = {"joint_limits": {}}
        self._joint_limits_source = "controller_manager"
        if urdf is not None:
            self.load_urdf(urdf)

    @property
    def handle_exceptions(self) -> bool:
        """ros2_control's ``handle_exceptions`` (default true): an exception from a component's ``read``/``write`` is
        logged and becomes ERROR; false lets it propagate out of :meth:`read`/:meth:`write` (and the manager's cycle)."""
        return self._handle_exceptions

    @handle_exceptions.setter
    def handle_exceptions(self, value: bool) -> None:
        self._handle_exceptions = bool(value)
        for entry in self._entries.values():
            entry.component.handle_exceptions = self._handle_exceptions

    # ================================================================= loading (steps in resource_loading)
    def load_urdf(self, urdf: str) -> None:
        """Parse ``urdf`` and load every ``<ros2_control>`` component in it.

        Raises:
            DescriptionError: If the ``<ros2_control>`` tags are invalid.
            HardwareError: See :meth:`load_hardware_infos`.
        """
        from rrbot_workshop.description import parse_ros2_control

        self.load_hardware_infos(parse_ros2_control(urdf))

    def load_hardware_infos(self, infos: Sequence[HardwareInfo]) -> None:
        """Load, initialise and store one component per info, then bring each to its initial state.

        Raises:
            HardwareError: If names repeat, a plugin is missing or unknown, ``on_init`` fails, or the
                exported interfaces do not match the description. Nothing is loaded then.
        """
        loaded: list[str] = []
        try:
            for info, cls in check_infos(infos, self._entries, self._initial_states):
                self.import_component(cls(), info, _transition=False)
                loaded.append(info.name)
        except Exception:
            # A rejected load changes nothing: forget the components this call already loaded.
            for name in loaded:
                entry = self._entries.pop(name)
                self._storage.remove_hardware(name, entry.state_names, entry.command_names)
            self._set_cycle_order()
            raise
        for info in infos:
            default = State.ACTIVE if self.activate_all else State.UNCONFIGURED
            target = self._initial_states.get(info.name, default)
            if target is not State.UNCONFIGURED and not self.set_component_state(info.name, target):
                _log.error("hardware component '%s' did not reach its initial state '%s'", info.name, target.label)

    def _set_cycle_order(self) -> None:
        self._cycle_order = cycle_order(self._entries.values())
        self._cycle.set_entries(self._cycle_order)

    def import_component(self, impl: Any, info: HardwareInfo, *, _transition: bool = True) -> None:
        """Add a ready-made component instance (tests and notebooks), initialise it and store its handles.

        Args:
            impl: An instance of a ``SystemInterface``/``ActuatorInterface``/``SensorInterface`` subclass.
            info: Its description.

        Raises:
            HardwareError: If the name is taken, ``on_init`` fails, or exported interfaces do not match.
        """
        if info.name in self._entries:
            raise HardwareError(f"hardware component '{info.name}' is already loaded")
        self._entries[info.name] = load_component(impl, info, self._storage, self.update_rate)
        self._entries[info.name].component.handle_exceptions = self._handle_exceptions
        self._set_cycle_order()
        if _transition:
            target = self._initial_states.get(info.name, State.ACTIVE if self.activate_all else State.UNCONFIGURED)
            if target is not State.UNCONFIGURED:
                self.set_component_state(info.name, target)

    # ================================================================= lifecycle
    def _entry(self, name: str) -> ComponentEntry:
        try:
            return self._entries[name]
        except KeyError:
            raise HardwareError(
                f"no hardware component named '{name}' (valid: {', '.join(sorted(self._entries)) or 'none'})"
            ) from None

    def _refresh(self, entry: ComponentEntry) -> None:
        available = entry.component.get_lifecycle_state() in (State.INACTIVE, State.ACTIVE)
        self._storage.set_available(entry.state_names, entry.command_names, available)

    def set_component_state(self, name: str, target: State) -> bool:
        """Drive component ``name`` to ``target``, chaining transitions (UNCONFIGURED -> ACTIVE is
        configure then activate). Interfaces' availability follows the resulting state.

        Returns:
            True if the component is in ``target`` afterwards.

        Raises:
            HardwareError: If there is no such component, or ``target`` is not a primary state.
        """
        entry = self._entry(name)
        comp = entry.component
        if target is State.UNKNOWN:
            raise HardwareError(f"hardware component '{name}': 'unknown' is not a state one can ask for")
        steps = {
            (State.UNCONFIGURED, State.INACTIVE): ("configure",),
            (State.UNCONFIGURED, State.ACTIVE): ("configure", "activate"),
            (State.INACTIVE, State.ACTIVE): ("activate",),
            (State.INACTIVE, State.UNCONFIGURED): ("cleanup",),
            (State.ACTIVE, State.INACTIVE): ("deactivate",),
            (State.ACTIVE, State.UNCONFIGURED): ("deactivate", "cleanup"),
        }
        current = comp.get_lifecycle_state()
        plan: tuple[str, ...] = ("shutdown",) if target is State.FINALIZED else steps.get((current, target), ())
        if current is State.FINALIZED:
            plan = ()
        for step in plan:
            before = comp.get_lifecycle_state()
            after = getattr(comp, step)()
            self._refresh(entry)
            if after is before or after is State.FINALIZED and target is not State.FINALIZED:
                break
        ok = comp.get_lifecycle_state() is target
        if not ok:
            _log.warning(
                "hardware component '%s' is '%s' after asking for '%s'", name, comp.get_lifecycle_state().label, target.label
            )
        return ok

    def shutdown_components(self) -> None:
        """Shut every component down (end of the system's life)."""
        for name in self._entries:
            if self._entries[name].component.get_lifecycle_state() not in (State.FINALIZED, State.UNKNOWN):
                self.set_component_state(name, State.FINALIZED)

    def get_components_status(self) -> dict[str, HardwareComponentInfo]:
        """Status of every component, in load order."""
        return {name: e.component.component_info(rw_rate=e.rw_rate) for name, e in self._entries.items()}

    def component_names(self) -> list[str]:
        """Component names in load order."""
        return list(self._entries)

    def get_component(self, name: str) -> HardwareComponent:
        """The lifecycle wrapper of component ``name``.

        Raises:
            HardwareError: If there is no such component.
        """
        return self._entry(name).component

    # ================================================================= command mode switch
    def prepare_command_mode_switch(self, start_interfaces: Sequence[str], stop_interfaces: Sequence[str]) -> bool:
        """Ask each component concerned whether the new set of claimed command interfaces is possible.

        Returns False (with a logged reason) if a key does not exist or is unavailable, a component
        would start interfaces while INACTIVE (unless allowed), a component is neither INACTIVE nor
        ACTIVE, or a component's hook returns not-OK. Each component gets only its own keys.
        """
        self.last_switch_error = resource_mode_switch.prepare(
            self._cycle_order, self._storage, start_interfaces, stop_interfaces,
            self.allow_controller_activation_with_inactive_hardware,
        )
        return not self.last_switch_error

    def check_command_mode_switch(self, start_interfaces: Sequence[str], stop_interfaces: Sequence[str]) -> str:
        """The resource manager's own rules of :meth:`prepare_command_mode_switch`, without asking the components and
        without logging or keeping the reason: why the switch would be refused, or ``""`` (for a dry run)."""
        return resource_mode_switch.prepare(
            self._cycle_order, self._storage, start_interfaces, stop_interfaces,
            self.allow_controller_activation_with_inactive_hardware, ask_components=False,
        )

    def perform_command_mode_switch(self, start_interfaces: Sequence[str], stop_interfaces: Sequence[str]) -> bool:
        """Tell each component concerned to switch mode (after a successful prepare)."""
        self.last_switch_error = resource_mode_switch.perform(
            self._cycle_order, self._storage, start_interfaces, stop_interfaces
        )
        return not self.last_switch_error

    # ================================================================= cycle (steps in resource_cycle)
    def read(self, time: float, period: float) -> HardwareReadWriteStatus:
        """Read every component (actuators, sensors, systems) that is due this cycle.

        Args:
            time: Current time in [s].
            period: Controller manager period in [s].
        """
        return self._cycle.read(time, period) or HardwareReadWriteStatus()

    @property
    def cycle(self) -> HardwareCycle:
        """The compiled read/write plan (:class:`~.resource_cycle.HardwareCycle`); the controller manager's cycle calls
        its ``read`` and ``write`` (what :meth:`read_cycle` and :meth:`write_cycle` call)."""
        return self._cycle

    def read_cycle(self, time: float, period: float) -> HardwareReadWriteStatus | None:
        """:meth:`read` for the controller manager's cycle: None when every component returned OK."""
        return self._cycle.read(time, period)

    # ================================================================= joint limits
    def set_joint_limits_parameters(
        self, params: Mapping[str, Any], source: str = "controller_manager", *, shared: Mapping[str, Any] | None = None
    ) -> None:
        """Take ``joint_limits.<joint>.*`` parameters over the description's limits for command limiting.

        The controller manager passes its own ``ros__parameters`` (and those of ``/**`` as ``shared``; its own win).
        See :mod:`rrbot_workshop.joint_limits` for the layout and the rules.

        Args:
            params: Parameters with a nested or dotted ``joint_limits`` section (others are ignored).
            source: Where they come from, for error messages.
            shared: Parameters that reach every node (``/**``), applied first.

        Raises:
            ParameterError: If a ``joint_limits`` parameter is unknown, of the wrong type or inconsistent; nothing
                changes then.
        """
        section = {joint: dict(values) for joint, values in joint_limits_parameters(shared or {}, "/**").items()}
        for joint, values in joint_limits_parameters(params, source).items():
            section.setdefault(joint, {}).update(values)
        self._joint_limits_params = {"joint_limits": section}
        self._joint_limits_source = source
        self._limiters.clear()
        known = {joint.name for entry in self._entries.values() for joint in entry.info.joints}
        unknown = sorted(set(section) - known) if self._entries else []
        if unknown:
            _log.warning("joint_limits parameters of %s name joints that no hardware component has: %s (joints: %s)",
                         source, ", ".join(unknown), ", ".join(sorted(known)))

    def get_hard_joint_limits(self) -> dict[str, JointLimits]:
        """Every joint's hard limits as command limiting applies them: the description's, then the parameters'."""
        return {joint.name: get_joint_limits(joint.name, self._joint_limits_params, entry.info.limits[joint.name],
                                             source=self._joint_limits_source)
                for entry in self._entries.values() for joint in entry.info.joints
                if joint.name in entry.info.limits}

    def get_soft_joint_limits(self) -> dict[str, SoftJointLimits]:
        """Every joint's soft limits as command limiting applies them (joints without any are left out)."""
        out = {}
        for entry in self._entries.values():
            for joint in entry.info.joints:
                soft = get_soft_joint_limits(joint.name, self._joint_limits_params, entry.info.soft_limits.get(joint.name),
                                             source=self._joint_limits_source)
                if soft is not None:
                    out[joint.name] = soft
        return out

    def enforce_command_limits(self, period: float) -> None:
        """Limit every active component's joint commands (see :mod:`~rrbot_workshop.hardware_interface.joint_limits`).

        The controller manager calls this before :meth:`write` when its parameter ``enforce_command_limits`` is true.
        A joint whose position is beyond a limit while a position is commanded is logged once as an error and its
        commands are left as they are (Jazzy's limiter throws there); once it is back inside, limiting starts again
        from its position.

        Args:
            period: Controller manager period in [s].
        """
        storage = self._storage
        for entry in self._cycle_order:
            if entry.component.get_lifecycle_state() is not State.ACTIVE:
                self._limiters.pop(entry.info.name, None)  # start afresh when it comes back
                continue
            limiters = self._limiters.get(entry.info.name)
            if limiters is None:
                limiters = self._limiters[entry.info.name] = self._build_limiters(entry)
            for item in limiters:
                desired = JointControlInterfacesData(item.joint)
                for kind, name in item.commands.items():
                    if storage.holder(name) is not None:  # as Jazzy: only claimed command interfaces are limited
                        setattr(desired, kind, float(storage.commands[name].get_value()))
                if not desired.has_data():
                    continue
                actual = JointControlInterfacesData(item.joint)
                for kind, name in item.states.items():
                    value = float(storage.states[name].get_value())
                    setattr(actual, kind, None if math.isnan(value) else value)
                commanded = desired.copy()
                try:
                    item.limiter.enforce(actual, desired, period)
                except JointLimitsError as exc:
                    item.limiter.reset_internals()  # once back inside, start from where the joint is
                    if not item.reported:
                        _log.error("%s; its commands are not limited while it is there", exc)
                        item.reported = True
                    continue
                item.reported = False
                for kind, name in item.commands.items():
                    value, before = getattr(desired, kind), getattr(commanded, kind)
                    if value is not None and value != before and not (math.isnan(value) and math.isnan(before)):
                        storage.commands[name].set_value(value)

    def _build_limiters(self, entry: ComponentEntry) -> list[_JointLimiterEntry]:
        out = []
        for joint in entry.info.joints:
            limits = entry.info.limits.get(joint.name)
            if limits is None or not joint.enable_limits:
                continue
            commands = {kind: f"{joint.name}/{kind}" for kind in _LIMITED_KINDS
                        if f"{joint.name}/{kind}" in entry.command_names}
            if not commands:
                continue
            states = {kind: f"{joint.name}/{kind}" for kind in _LIMITED_KINDS
                      if f"{joint.name}/{kind}" in self._storage.states}
            limits = get_joint_limits(joint.name, self._joint_limits_params, limits, source=self._joint_limits_source)
            soft = get_soft_joint_limits(joint.name, self._joint_limits_params, entry.info.soft_limits.get(joint.name),
                                         source=self._joint_limits_source)
            out.append(_JointLimiterEntry(joint.name, make_limiter(joint.name, limits, soft), commands, states))
        return out

    def write(self, time: float, period: float) -> HardwareReadWriteStatus:
        """Write every component that is due this cycle (components write only while ACTIVE)."""
        return self._cycle.write(time, period) or HardwareReadWriteStatus()

    def write_cycle(self, time: float, period: float) -> HardwareReadWriteStatus | None:
        """:meth:`write` for the controller manager's cycle: None when every component returned OK."""
        return self._cycle.write(time, period)
