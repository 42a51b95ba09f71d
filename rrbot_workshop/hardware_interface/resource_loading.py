"""Loading hardware components for the resource manager: plugins, ``on_init``, exported handles.

Before anything is loaded, :func:`check_infos` rejects a batch of descriptions with repeated
names, unknown names in ``hardware_components_initial_state``, or missing or unknown plugins, so
a bad batch loads nothing. :func:`load_component` wraps one implementation in a
:class:`~rrbot_workshop.hardware_interface.hardware_component.HardwareComponent`, initialises it, checks that it
exports every interface its ``<ros2_control>`` tag declares and none that another component
exports, and stores its handles. The resource manager keeps one :class:`ComponentEntry` per
component and calls them in :func:`cycle_order`.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.exceptions import HardwareError, PluginNotFound
from rrbot_workshop.hardware_interface.hardware_component import HardwareComponent
from rrbot_workshop.hardware_interface.resource_storage import InterfaceStorage
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import State

__all__ = ["ComponentEntry", "check_infos", "load_component", "cycle_order", "mock_hardware_infos", "MOCK_MODES", "MOCK_PLUGINS"]

#: Component type -> the plugin that mocks it (``hardware/mock_substitutes.py`` holds the two that are not Jazzy's).
MOCK_PLUGINS: dict[str, str] = {
    "system": "mock_components/GenericSystem",
    "actuator": "rrbot_workshop/MockActuator",
    "sensor": "rrbot_workshop/MockSensor",
}

#: What ``bringup(..., mock_hardware=...)`` accepts: None (load the plugins as written), ``"unknown"``, ``"all"``.
MOCK_MODES = (None, "unknown", "all")

#: read/write order of component types, as in ros2_control: actuators, sensors, then systems.
_TYPE_ORDER = {"actuator": 0, "sensor": 1, "system": 2}


@dataclass
class ComponentEntry:
    """The resource manager's record of one loaded component.

    Attributes:
        component: Its lifecycle wrapper.
        info: Its description.
        state_names: Full names of the state interfaces it exports.
        command_names: Full names of the command interfaces it exports.
        rw_rate: Effective read/write rate in [Hz] (at most the manager's rate).
        last_read: Time of its last ``read`` in [s] (None before the first).
        last_write: Time of its last ``write`` in [s] (None before the first).
    """

    component: HardwareComponent
    info: HardwareInfo
    state_names: list[str]
    command_names: list[str]
    rw_rate: int
    last_read: float | None = None
    last_write: float | None = None


def check_infos(
    infos: Sequence[HardwareInfo], loaded: Iterable[str], initial_states: Mapping[str, State]
) -> list[tuple[HardwareInfo, Any]]:
    """Check a batch of descriptions before loading any, and resolve their plugins.

    Args:
        infos: The descriptions to load.
        loaded: Names of the components already loaded.
        initial_states: ``hardware_components_initial_state`` (component name -> state).

    Returns:
        ``(info, plugin class)`` for each description, in order.

    Raises:
        HardwareError: If names repeat, ``initial_states`` names an unknown component, or a plugin
            is missing or unknown.
    """
    taken = set(loaded)
    names = [i.name for i in infos]
    dup = sorted({n for n in names if names.count(n) > 1} | (set(names) & taken))
    if dup:
        raise HardwareError(f"hardware component name(s) {dup} are used more than once; names must be unique")
    unknown = sorted(set(initial_states) - set(names) - taken)
    if unknown:
        raise HardwareError(
            f"hardware_components_initial_state names unknown component(s) {unknown} (valid: {sorted(names)})"
        )
    resolved = []
    for info in infos:
        if not info.hardware_plugin_name:
            raise HardwareError(f"hardware component '{info.name}' has no <hardware><plugin>; cannot load it")
        try:
            cls = plugins.resolve("hardware", info.hardware_plugin_name)
        except PluginNotFound as exc:
            raise HardwareError(f"hardware component '{info.name}': {exc}") from exc
        _check_plugin_type(info, cls)
        resolved.append((info, cls))
    return resolved


def _check_plugin_type(info: HardwareInfo, cls: Any) -> None:
    """Refuse a plugin on a component of another type, as Jazzy's loaders do.

    Jazzy loads each ``<ros2_control>`` tag with the pluginlib loader of its ``type`` (``SystemInterface``,
    ``ActuatorInterface`` or ``SensorInterface``); a plugin exported for another base class is not found.
    ``mock_components/GenericSystem`` is exported only as a ``SystemInterface``.
    """
    wanted = info.type.lower()
    kind = getattr(cls, "component_type", "")
    if wanted not in _TYPE_ORDER or not kind or kind == wanted:
        return
    plugin = info.hardware_plugin_name
    if plugin == "mock_components/GenericSystem":
        fix = (f"write type=\"system\" on this <ros2_control> tag (GenericSystem mocks any joints, sensors and GPIOs "
               f"as a system), or use the {wanted}'s own plugin (bringup(..., mock_hardware='unknown') mocks an "
               f"unknown {wanted} plugin; mock_hardware='all' mocks every component by its type)")
        why = "Jazzy exports GenericSystem only as a SystemInterface, so its plugin loader refuses it for"
    else:
        fix = f"write type=\"{kind}\" on the tag, or give a plugin written as a {wanted.capitalize()}Interface"
        why = f"the plugin is a {kind.capitalize()}Interface; Jazzy's plugin loader refuses it for"
    raise HardwareError(
        f"hardware component '{info.name}' is <ros2_control type=\"{info.type}\"> with plugin '{plugin}': {why} a "
        f"{wanted} component. Fix: {fix}"
    )


def mock_hardware_infos(infos: Sequence[HardwareInfo], mode: str | None) -> tuple[list[HardwareInfo], dict[str, str]]:
    """Put the mock of each component's type in place of its plugin, as ``bringup(..., mock_hardware=mode)`` asks.

    The mock of a system is ``mock_components/GenericSystem``; an actuator or a sensor gets the library's
    ``rrbot_workshop/MockActuator`` or ``rrbot_workshop/MockSensor`` (Jazzy has no mock of those types; see
    :mod:`rrbot_workshop.hardware.mock_substitutes`). The ``<hardware><param>`` values stay; the mocks read theirs.
    A replaced component whose joint commands are all position/velocity/acceleration also gets
    ``calculate_dynamics=true`` unless it sets it (as the demos' own mock switches do): a velocity command then moves
    the joint's position, as the driver's hardware would. Effort commands are mirrored only (GenericSystem with
    dynamics refuses a joint without a position, velocity or acceleration command). A mocked joint given several
    control modes at once (example 7's controller claims position and velocity) follows the first of position,
    velocity and acceleration instead of refusing the switch, as the replaced driver may accept them.

    Args:
        infos: The parsed ``<ros2_control>`` tags.
        mode: None (nothing changes), ``"unknown"`` (only plugins the library does not have) or ``"all"`` (every
            component that is not already the mock of its type).

    Returns:
        ``(infos, mocked)``: the descriptions to load (copies where the plugin changed) and component name -> the
        plugin it replaced.

    Raises:
        HardwareError: If ``mode`` is not one of :data:`MOCK_MODES`, or a component's type is not
            system/actuator/sensor.
    """
    import dataclasses

    if mode not in MOCK_MODES:
        raise HardwareError(f"mock_hardware={mode!r} is not valid (valid: None, 'unknown', 'all')")
    if mode is None:
        return list(infos), {}
    out: list[HardwareInfo] = []
    mocked: dict[str, str] = {}
    for info in infos:
        plugin = info.hardware_plugin_name
        mock = MOCK_PLUGINS.get(info.type.lower())
        if mock is None:
            raise HardwareError(f"hardware component '{info.name}' has type '{info.type}'; it cannot be mocked "
                                "(valid types: system, actuator, sensor)")
        replace = plugin != mock if mode == "all" else bool(plugin) and not _known(plugin)
        if replace:
            mocked[info.name] = plugin
            params = dict(info.hardware_parameters)
            commands = {i.name for j in info.joints for i in j.command_interfaces}
            if "calculate_dynamics" not in params and commands and commands <= {"position", "velocity", "acceleration"}:
                params["calculate_dynamics"] = "true"  # a driver's joints move: velocity commands integrate
            info = dataclasses.replace(info, hardware_plugin_name=mock, hardware_parameters=params, mocked_plugin=plugin)
        out.append(info)
    return out, mocked


def _known(plugin: str) -> bool:
    """True if :func:`plugins.resolve` knows ``plugin`` (a resolver that fails still counts as known)."""
    try:
        plugins.resolve("hardware", plugin)
    except PluginNotFound:
        return False
    except Exception:  # noqa: BLE001 - e.g. a learner's unfinished class: known, and its error shows at load
        return True
    return True


class _ErrorLines(logging.Handler):
    """Keeps the error lines a component logs while it initialises: the reason its on_init failed.

    Args:
        shown_elsewhere: Whether another handler shows the component's records. When none does, Python would print
            its warnings and errors on stderr (``logging.lastResort``); this handler, being one, does it instead.
    """

    def __init__(self, shown_elsewhere: bool) -> None:
        super().__init__(logging.NOTSET)
        self.lines: list[str] = []
        self._shown_elsewhere = shown_elsewhere

    def emit(self, record: logging.LogRecord) -> None:
        if record.levelno >= logging.ERROR:
            self.lines.append(record.getMessage()[:300])
        last = logging.lastResort
        if not self._shown_elsewhere and last is not None and record.levelno >= last.level:
            last.handle(record)


def load_component(impl: Any, info: HardwareInfo, storage: InterfaceStorage, update_rate: int) -> ComponentEntry:
    """Wrap and initialise one implementation and store its handles (unavailable until configured).

    Args:
        impl: An instance of a ``SystemInterface``/``ActuatorInterface``/``SensorInterface`` subclass.
        info: Its description.
        storage: The interface storage that receives its handles.
        update_rate: Controller manager rate in [Hz] (the default and largest ``rw_rate``).

    Raises:
        HardwareError: If ``on_init`` fails, or the exported interfaces do not match the description
            or clash with another component's.
    """
    component = HardwareComponent(impl)
    hardware_log = logging.getLogger("rrbot_workshop.hardware")
    said = _ErrorLines(shown_elsewhere=hardware_log.hasHandlers())
    hardware_log.addHandler(said)
    try:
        state = component.initialize(info)
    finally:
        hardware_log.removeHandler(said)
    if state is not State.UNCONFIGURED:
        why = f"; it logged: {said.lines[0]}" if said.lines else ""
        raise HardwareError(
            f"hardware component '{info.name}' ({info.hardware_plugin_name or type(impl).__name__}) failed to "
            f"initialise: on_init did not succeed (state '{state.label}'){why}"
        ) from component.last_error  # what on_init raised, if it raised: the learner's own line
    states = list(component.export_state_interfaces())
    commands = list(component.export_command_interfaces())
    _check_exports(info, storage, states, commands)
    storage.add_hardware(info.name, states, commands)
    rate = info.rw_rate if 0 < info.rw_rate < update_rate else update_rate
    return ComponentEntry(component, info, [h.name for h in states], [h.name for h in commands], rate)


def _check_exports(info: HardwareInfo, storage: InterfaceStorage, states: Sequence[Any], commands: Sequence[Any]) -> None:
    exported_s = {h.name for h in states}
    exported_c = {h.name for h in commands}
    clash = sorted((exported_s & {n for n, o in storage.hardware_owner.items() if n in storage.states})
                   | (exported_c & {n for n in storage.commands}))
    if clash:
        owners = sorted({storage.hardware_owner.get(n, "?") for n in clash})
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


def cycle_order(entries: Iterable[ComponentEntry]) -> list[ComponentEntry]:
    """``entries`` in read/write order: actuators, sensors, systems, then any other type (stable)."""
    return sorted(entries, key=lambda e: _TYPE_ORDER.get(e.info.type.lower(), 3))
