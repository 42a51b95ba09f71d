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
"""

from __future__ import annotations

import logging
import traceback
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from . import plugins
from .clock import rate_due
from .description.info import HardwareInfo
from .exceptions import HardwareError, PluginNotFound
from .handles import LoanedCommandInterface, LoanedStateInterface
from .hardware.component import HardwareComponent, HardwareComponentInfo
from .lifecycle import ReturnType, State
from .resource_storage import InterfaceStorage

__all__ = ["ResourceManager", "HardwareReadWriteStatus", "HardwareComponentInfo"]

_log = logging.getLogger(__name__)

_TYPE_ORDER = {"actuator": 0, "sensor": 1, "system": 2}


@dataclass
class HardwareReadWriteStatus:
    """Result of :meth:`ResourceManager.read` / :meth:`ResourceManager.write`.

    Attributes:
        ok: False if any component failed or deactivated itself.
        failed_hardware_names: Components taken out (error) or deactivated (DEACTIVATE) in this call.
    """

    ok: bool = True
    failed_hardware_names: list[str] = field(default_factory=list)


@dataclass
class _Entry:
    component: HardwareComponent
    info: HardwareInfo
    state_names: list[str]
    command_names: list[str]
    rw_rate: int
    last_read: float | None = None
    last_write: float | None = None


class ResourceManager:
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
        self._initial_states = dict(initial_states or {})
        #: Why the last prepare/perform command mode switch returned False ("" if it did not).
        self.last_switch_error = ""
        self._storage = InterfaceStorage()
        self._entries: dict[str, _Entry] = {}
        self._cycle_order: list[_Entry] = []
        if urdf is not None:
            self.load_urdf(urdf)

    # ================================================================= loading
    def load_urdf(self, urdf: str) -> None:
        """Parse ``urdf`` and load every ``<ros2_control>`` component in it.

        Raises:
            DescriptionError: If the ``<ros2_control>`` tags are invalid.
            HardwareError: See :meth:`load_hardware_infos`.
        """
        from .description import parse_ros2_control

        self.load_hardware_infos(parse_ros2_control(urdf))

    def load_hardware_infos(self, infos: Sequence[HardwareInfo]) -> None:
        """Load, initialise and store one component per info, then bring each to its initial state.

        Raises:
            HardwareError: If names repeat, a plugin is missing or unknown, ``on_init`` fails, or the
                exported interfaces do not match the description. Nothing is loaded then.
        """
        names = [i.name for i in infos]
        dup = sorted({n for n in names if names.count(n) > 1} | (set(names) & set(self._entries)))
        if dup:
            raise HardwareError(f"hardware component name(s) {dup} are used more than once; names must be unique")
        unknown = sorted(set(self._initial_states) - set(names) - set(self._entries))
        if unknown:
            raise HardwareError(
                f"hardware_components_initial_state names unknown component(s) {unknown} (valid: {sorted(names)})"
            )
        loaded = []
        for info in infos:
            if not info.hardware_plugin_name:
                raise HardwareError(f"hardware component '{info.name}' has no <hardware><plugin>; cannot load it")
            try:
                cls = plugins.resolve("hardware", info.hardware_plugin_name)
            except PluginNotFound as exc:
                raise HardwareError(f"hardware component '{info.name}': {exc}") from exc
            loaded.append((info, cls))
        for info, cls in loaded:
            self.import_component(cls(), info, _transition=False)
        for info in infos:
            default = State.ACTIVE if self.activate_all else State.UNCONFIGURED
            target = self._initial_states.get(info.name, default)
            if target is not State.UNCONFIGURED and not self.set_component_state(info.name, target):
                _log.error("hardware component '%s' did not reach its initial state '%s'", info.name, target.label)

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
        component = HardwareComponent(impl)
        state = component.initialize(info)
        if state is not State.UNCONFIGURED:
            raise HardwareError(
                f"hardware component '{info.name}' ({info.hardware_plugin_name or type(impl).__name__}) failed to "
                f"initialise: on_init did not succeed (state '{state.label}')"
            )
        states = list(component.export_state_interfaces())
        commands = list(component.export_command_interfaces())
        self._validate(info, states, commands)
        self._storage.add_hardware(info.name, states, commands)
        rate = info.rw_rate if 0 < info.rw_rate < self.update_rate else self.update_rate
        self._entries[info.name] = _Entry(component, info, [h.name for h in states], [h.name for h in commands], rate)
        self._cycle_order = sorted(self._entries.values(), key=lambda e: _TYPE_ORDER.get(e.info.type.lower(), 3))
        if _transition and self.activate_all:
            self.set_component_state(info.name, self._initial_states.get(info.name, State.ACTIVE))

    def _validate(self, info: HardwareInfo, states: Sequence[Any], commands: Sequence[Any]) -> None:
        exported_s = {h.name for h in states}
        exported_c = {h.name for h in commands}
        clash = sorted((exported_s & {n for n, o in self._storage.hardware_owner.items() if n in self._storage.states})
                       | (exported_c & {n for n in self._storage.commands}))
        if clash:
            owners = sorted({self._storage.hardware_owner.get(n, "?") for n in clash})
            raise HardwareError(
                f"hardware component '{info.name}' exports interface(s) {clash} already exported by {owners}"
            )
        comps = [*info.joints, *info.sensors, *info.gpios]
        want_s = {f"{c.name}/{i.name}" for c in comps for i in c.state_interfaces}
        want_c = {f"{c.name}/{i.name}" for c in [*info.joints, *info.gpios] for i in c.command_interfaces}
        if info.type.lower() == "sensor":
            want_c = set()
        missing = sorted(want_s - exported_s) + sorted(want_c - exported_c)
        if missing:
            raise HardwareError(
                f"hardware component '{info.name}' does not export interface(s) {missing} that its "
                "<ros2_control> description declares"
            )

    # ================================================================= lifecycle
    def _entry(self, name: str) -> _Entry:
        try:
            return self._entries[name]
        except KeyError:
            raise HardwareError(
                f"no hardware component named '{name}' (valid: {', '.join(sorted(self._entries)) or 'none'})"
            ) from None

    def _refresh(self, entry: _Entry) -> None:
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

    def hardware_of_interface(self, name: str) -> str | None:
        """Name of the component that exports interface ``name``, or None (controller export or unknown)."""
        return self._storage.hardware_owner.get(name)

    # ================================================================= interfaces
    def state_interface_keys(self) -> list[str]:
        """Every state interface name, sorted."""
        return sorted(self._storage.states)

    def command_interface_keys(self) -> list[str]:
        """Every command interface name (hardware and controller references), sorted."""
        return sorted(self._storage.commands)

    def available_state_interfaces(self) -> list[str]:
        """Available state interface names, sorted."""
        return sorted(self._storage.available_states)

    def available_command_interfaces(self) -> list[str]:
        """Available command interface names, sorted."""
        return sorted(self._storage.available_commands)

    def state_interface_exists(self, name: str) -> bool:
        """Whether a state interface of that name is stored."""
        return name in self._storage.states

    def command_interface_exists(self, name: str) -> bool:
        """Whether a command interface of that name is stored."""
        return name in self._storage.commands

    def state_interface_is_available(self, name: str) -> bool:
        """Whether state interface ``name`` can be read now."""
        return name in self._storage.available_states

    def command_interface_is_available(self, name: str) -> bool:
        """Whether command interface ``name`` can be claimed now (claims aside)."""
        return name in self._storage.available_commands

    def command_interface_is_claimed(self, name: str) -> bool:
        """Whether someone holds command interface ``name``."""
        return name in self._storage.claims

    def command_interface_holder(self, name: str) -> str | None:
        """Name of the holder of command interface ``name``, or None."""
        return self._storage.holder(name)

    def interface_data_type(self, name: str) -> str:
        """Data type of an interface (``"double"`` if unknown)."""
        handle = self._storage.states.get(name) or self._storage.commands.get(name)
        return handle.data_type if handle is not None else "double"

    def claim_state_interface(self, name: str) -> LoanedStateInterface:
        """Loan state interface ``name``.

        Raises:
            InterfaceNotFound: If it does not exist or is not available.
        """
        return self._storage.claim_state(name)

    def claim_command_interface(self, name: str, holder: str = "") -> LoanedCommandInterface:
        """Loan command interface ``name`` exclusively; ``release()`` on the loan frees it.

        Raises:
            InterfaceNotFound: If it does not exist or is not available.
            InterfaceAlreadyClaimed: If it is claimed; the error names the holder.
        """
        return self._storage.claim_command(name, holder)

    def get_interface_value(self, name: str, kind: str | None = None) -> Any:
        """Value of a state, command or reference interface (state first if both exist).

        Raises:
            InterfaceNotFound: If nothing has that name.
        """
        return self._storage.value(name, kind)

    # ----------------------------------------------------------------- controller exports
    def import_controller_reference_interfaces(self, controller_name: str, handles: Sequence[Any]) -> None:
        """Store a chainable controller's reference interfaces (unavailable until it activates).

        Raises:
            ControllerError: If a name already exists.
        """
        self._storage.import_controller_interfaces(controller_name, handles, "reference")

    def import_controller_exported_state_interfaces(self, controller_name: str, handles: Sequence[Any]) -> None:
        """Store a chainable controller's exported state interfaces (unavailable until it activates).

        Raises:
            ControllerError: If a name already exists.
        """
        self._storage.import_controller_interfaces(controller_name, handles, "state")

    def get_controller_reference_interface_names(self, controller_name: str) -> list[str]:
        """Full names of the reference interfaces ``controller_name`` exported."""
        return list(self._storage.controller_references.get(controller_name, []))

    def get_controller_exported_state_interface_names(self, controller_name: str) -> list[str]:
        """Full names of the state interfaces ``controller_name`` exported."""
        return list(self._storage.controller_states.get(controller_name, []))

    def make_controller_reference_interfaces_available(self, controller_name: str, available: bool = True) -> None:
        """Make a controller's reference interfaces (un)available."""
        self._storage.set_available((), self.get_controller_reference_interface_names(controller_name), available)

    def make_controller_exported_state_interfaces_available(self, controller_name: str, available: bool = True) -> None:
        """Make a controller's exported state interfaces (un)available."""
        self._storage.set_available(self.get_controller_exported_state_interface_names(controller_name), (), available)

    def remove_controller_reference_interfaces(self, controller_name: str) -> None:
        """Forget a controller's reference interfaces (cleanup / unload)."""
        self._storage.remove_controller_interfaces(controller_name, "reference")

    def remove_controller_exported_state_interfaces(self, controller_name: str) -> None:
        """Forget a controller's exported state interfaces (cleanup / unload)."""
        self._storage.remove_controller_interfaces(controller_name, "state")

    def controller_of_interface(self, name: str) -> str | None:
        """The controller that exports interface ``name``, or None."""
        return self._storage.controller_of(name)

    # ================================================================= command mode switch
    def _split(self, keys: Iterable[str]) -> dict[str, list[str]]:
        out: dict[str, list[str]] = {}
        for k in keys:
            owner = self._storage.hardware_owner.get(k)
            if owner is not None:
                out.setdefault(owner, []).append(k)
        return out

    def prepare_command_mode_switch(self, start_interfaces: Sequence[str], stop_interfaces: Sequence[str]) -> bool:
        """Ask each component concerned whether the new set of claimed command interfaces is possible.

        Returns False (with a logged reason) if a key does not exist or is unavailable, a component
        would start interfaces while INACTIVE (unless allowed), a component is neither INACTIVE nor
        ACTIVE, or a component's hook returns not-OK. Each component gets only its own keys.
        """
        self.last_switch_error = ""
        if not start_interfaces and not stop_interfaces:
            return True
        for key in [*start_interfaces, *stop_interfaces]:
            if key not in self._storage.commands:
                return self._reject(f"command interface '{key}' does not exist")
            if key not in self._storage.available_commands:
                return self._reject(f"command interface '{key}' is not available")
        start, stop = self._split(start_interfaces), self._split(stop_interfaces)
        for entry in self._cycle_order:
            name = entry.info.name
            if name not in start and name not in stop:
                continue
            state = entry.component.get_lifecycle_state()
            if state not in (State.INACTIVE, State.ACTIVE):
                return self._reject(f"hardware component '{name}' is '{state.label}', not inactive or active")
            if state is State.INACTIVE and start.get(name) and not self.allow_controller_activation_with_inactive_hardware:
                return self._reject(
                    f"hardware component '{name}' is inactive; its command interfaces {start[name]} cannot be claimed"
                )
            impl = entry.component.impl
            if hasattr(impl, "mode_switch_rejection"):
                impl.mode_switch_rejection = ""
            result = self._call_hook(entry, "prepare_command_mode_switch", start.get(name, []), stop.get(name, []))
            if result is not ReturnType.OK:
                why = getattr(impl, "mode_switch_rejection", "")
                return self._reject(
                    f"hardware component '{name}' rejected the command mode switch "
                    f"(start {start.get(name, [])}, stop {stop.get(name, [])})" + (f": {why}" if why else "")
                )
        return True

    def perform_command_mode_switch(self, start_interfaces: Sequence[str], stop_interfaces: Sequence[str]) -> bool:
        """Tell each component concerned to switch mode (after a successful prepare)."""
        self.last_switch_error = ""
        start, stop = self._split(start_interfaces), self._split(stop_interfaces)
        ok = True
        for entry in self._cycle_order:
            name = entry.info.name
            if name not in start and name not in stop:
                continue
            if entry.component.get_lifecycle_state() not in (State.INACTIVE, State.ACTIVE):
                continue
            if self._call_hook(entry, "perform_command_mode_switch", start.get(name, []), stop.get(name, [])) is not ReturnType.OK:
                ok = self._reject(f"hardware component '{name}' failed to perform the command mode switch")
        return ok

    def _reject(self, reason: str) -> bool:
        self.last_switch_error = reason
        _log.warning("%s", reason)
        return False

    @staticmethod
    def _call_hook(entry: _Entry, hook: str, start: list[str], stop: list[str]) -> Any:
        try:
            return getattr(entry.component, hook)(start, stop)
        except Exception:  # noqa: BLE001 - learner code must not take the manager down
            _log.error("%s of hardware '%s' raised:\n%s", hook, entry.info.name, traceback.format_exc())
            return ReturnType.ERROR

    # ================================================================= cycle
    def read(self, time: float, period: float) -> HardwareReadWriteStatus:
        """Read every component (actuators, sensors, systems) that is due this cycle.

        Args:
            time: Current time in [s].
            period: Controller manager period in [s].
        """
        return self._cycle("read", time, period)

    def write(self, time: float, period: float) -> HardwareReadWriteStatus:
        """Write every component that is due this cycle (components write only while ACTIVE)."""
        return self._cycle("write", time, period)

    def _cycle(self, which: str, time: float, period: float) -> HardwareReadWriteStatus:
        status = HardwareReadWriteStatus()
        for entry in self._cycle_order:
            last = entry.last_read if which == "read" else entry.last_write
            if not rate_due(last, time, entry.rw_rate, self.update_rate):
                continue
            own_period = period if last is None or entry.rw_rate >= self.update_rate else time - last
            if which == "read":
                entry.last_read = time
            else:
                entry.last_write = time
            try:
                result = getattr(entry.component, which)(time, own_period)
            except Exception:  # noqa: BLE001 - handle_exceptions
                _log.error("%s of hardware '%s' raised:\n%s", which, entry.info.name, traceback.format_exc())
                result = ReturnType.ERROR
            if result is ReturnType.OK:
                continue
            status.ok = False
            if result is ReturnType.DEACTIVATE and which == "write":
                _log.warning("hardware '%s' asked to be deactivated from write", entry.info.name)
                self.set_component_state(entry.info.name, State.INACTIVE)
                status.failed_hardware_names.append(entry.info.name)
                continue
            for failed in self._group_of(entry):
                self._fail(failed, which, result)
                if failed.info.name not in status.failed_hardware_names:
                    status.failed_hardware_names.append(failed.info.name)
        return status

    def _group_of(self, entry: _Entry) -> list[_Entry]:
        group = entry.info.group
        if not group:
            return [entry]
        return [entry] + [e for e in self._cycle_order if e is not entry and e.info.group == group]

    def _fail(self, entry: _Entry, which: str, result: Any) -> None:
        comp = entry.component
        if comp.get_lifecycle_state() in (State.INACTIVE, State.ACTIVE):
            comp.error()
        self._storage.set_available(entry.state_names, entry.command_names, False)
        _log.error(
            "hardware '%s' failed in %s (%s); it is now '%s' and its interfaces are unavailable",
            entry.info.name, which, getattr(result, "value", result), comp.get_lifecycle_state().label,
        )
