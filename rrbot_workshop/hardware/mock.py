"""``mock_components/GenericSystem``: hardware that reports back what it is told.

The mock system of ros2_control stands in for a real robot: every command it receives shows up on the
matching state interface at the next ``read``, so controllers can be tried without hardware or physics.
``<hardware><param>`` entries change how it mirrors:

* ``mock_sensor_commands`` (false): a command interface for every sensor state, mirrored to it;
* ``mock_gpio_commands`` (false): a command interface for every GPIO state that has none;
* ``disable_commands`` (false): ``read`` changes nothing (a disconnected driver);
* ``calculate_dynamics`` (false): integrate velocity and acceleration commands (below);
* ``position_state_following_offset`` (0): ``position`` state = command + offset, in [rad] or [m];
* ``custom_interface_with_following_offset`` (""): put command + offset on this joint interface
  instead of ``position`` (only read when the offset parameter is given).

Without dynamics, a finite ``position`` command becomes the ``position`` state (plus the offset); every
other joint command is copied to the state of the same name. With ``calculate_dynamics`` each joint is in
one of three modes chosen by ``perform_command_mode_switch`` (position by default), with ``dt = period``:

* position: ``p = cmd + offset``, ``v = (p - p_old) / dt``, ``a = (v - v_old) / dt``;
* velocity: ``a = (cmd - v_old) / dt``, ``v = cmd``, ``p += v dt``;
* acceleration: ``a = cmd``, ``v += a dt``, ``p += v dt`` (implicit Euler).

Only finite results are stored, and only on states the joint declares. A NaN command means "not set
yet" and is skipped; an infinite command makes ``read`` return ERROR. Mimic joints follow their source:
``p = offset + multiplier * p_src``, ``v = multiplier * v_src``, ``a = multiplier * a_src``.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from typing import Any

from rrbot_workshop.description.info import ComponentInfo, HardwareInfo, InterfaceInfo
from rrbot_workshop.hardware.mock_read_plan import build_read_steps, run_read_plan, runs_of_one_kind
from rrbot_workshop.hardware_interface.component_interface import SystemInterface
from rrbot_workshop.hardware_interface.handles import ADOPTIONS, CommandInterface, parse_value
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

__all__ = ["GenericSystem", "STANDARD_INTERFACES"]

_log = logging.getLogger(__name__)

POSITION, VELOCITY, ACCELERATION, EFFORT = "position", "velocity", "acceleration", "effort"
#: The joint interfaces ros2_control names (``hardware_interface_type_values.hpp``).
STANDARD_INTERFACES: tuple[str, ...] = (POSITION, VELOCITY, ACCELERATION, EFFORT)
_MODES = (POSITION, VELOCITY, ACCELERATION)
_FLOAT_TYPES = ("double", "float32")


def _parse_bool(text: str, name: str = "") -> bool:
    """ros2_control's ``parse_bool``: ``true``/``false`` in any letter case; ``name`` is the parameter's, for the
    message."""
    value = text.strip().lower()
    if value not in ("true", "false"):
        raise ValueError(f"{name + ' ' if name else ''}'{text}' is not a bool (valid: true, false)")
    return value == "true"


class GenericSystem(SystemInterface):
    """Mock hardware that mirrors commands to states (``mock_components/GenericSystem``).

    Attributes:
        calculate_dynamics: Whether velocity and acceleration commands are integrated.
        position_state_following_offset: Offset added to position feedback in [rad] or [m].
        custom_interface_with_following_offset: Joint interface that carries the offset, or ``""``.
        mock_sensor_commands: Whether sensors get mirrored command interfaces.
        mock_gpio_commands: Whether every GPIO state gets a mirrored command interface.
        disable_commands: Whether ``read`` ignores commands.
        jazzy_offset_quirk: Reproduce Jazzy's offset bug in velocity/acceleration modes (see :meth:`read`).
    """

    #: Set to True to reproduce Jazzy exactly; False (default) does what the code meant to do.
    jazzy_offset_quirk: bool = False

    def __init__(self) -> None:
        super().__init__()
        self.calculate_dynamics = False
        self.position_state_following_offset = 0.0
        self.custom_interface_with_following_offset = ""
        self.mock_sensor_commands = False
        self.mock_gpio_commands = False
        self.disable_commands = False
        self._joint_modes: list[str] = []
        self._warned_disabled = False
        #: What ``read`` does without ``calculate_dynamics``, prepared once: (kind, source, target, offset, gain).
        #: The prepared read (see mock_read_plan), as runs of steps of one kind; None until the first read.
        self._plan_runs: list[tuple[int, list[tuple[list[Any], int, list[Any], int, float, float]]]] | None = None
        self._plan_adoptions = -1

    # ----------------------------------------------------------------- lifecycle
    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        """Read the ``<hardware><param>`` values; a malformed value fails initialisation.

        Args:
            info: Parsed ``<ros2_control>`` tag.
        """
        super().on_init(info)
        params = info.hardware_parameters
        try:
            self.mock_sensor_commands = _parse_bool(params.get("mock_sensor_commands", "false"), "mock_sensor_commands")
            self.mock_gpio_commands = _parse_bool(params.get("mock_gpio_commands", "false"), "mock_gpio_commands")
            self.disable_commands = _parse_bool(params.get("disable_commands", "false"), "disable_commands")
            self.calculate_dynamics = _parse_bool(params.get("calculate_dynamics", "false"), "calculate_dynamics")
            #: True on a component ``bringup(..., mock_hardware=...)`` mocked (not in Jazzy): a joint
            #: given several control modes at once follows the first of position/velocity/acceleration instead of
            #: refusing, as the replaced driver may have accepted them (example 7's robot takes both).
            self.several_modes = bool(info.mocked_plugin)
            # As upstream, the custom interface is only read when an offset is given.
            if "position_state_following_offset" in params:
                offset = params["position_state_following_offset"]
                try:
                    self.position_state_following_offset = float(offset)
                except ValueError:
                    raise ValueError(f"position_state_following_offset '{offset}' is not a number") from None
                if not math.isfinite(self.position_state_following_offset):
                    raise ValueError(f"position_state_following_offset '{offset}' is not a finite number")
                self.custom_interface_with_following_offset = params.get("custom_interface_with_following_offset", "")
        except ValueError as exc:
            self.logger.error("hardware '%s': invalid <hardware><param>: %s", info.name, exc)
            return CallbackReturn.ERROR

        custom = self.custom_interface_with_following_offset
        if custom:
            others = {
                itf.name
                for joint in info.joints
                for itf in [*joint.command_interfaces, *joint.state_interfaces]
                if itf.name not in STANDARD_INTERFACES
            }
            if custom in others:
                self.logger.info("custom interface with following offset '%s' found", custom)
            else:
                self.logger.warning(
                    "custom interface with following offset '%s' is not a non-standard joint interface "
                    "(there are: %s); the offset will not be applied",
                    custom,
                    ", ".join(sorted(others)) or "none",
                )
        for mimic in info.mimic_joints:
            if not (0 <= mimic.joint_index < len(info.joints) and 0 <= mimic.mimicked_joint_index < len(info.joints)):
                self.logger.error("hardware '%s': mimic joint index out of range: %s", info.name, mimic)
                return CallbackReturn.ERROR
        self._joint_modes = [POSITION] * len(info.joints)
        return CallbackReturn.SUCCESS

    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Replace NaN joint states by 0, add the offset to ``position`` states, put every joint in position mode."""
        for joint in self.info.joints:
            for itf in joint.state_interfaces:
                name = f"{joint.name}/{itf.name}"
                if itf.data_type != "double" or name not in self._state_handles:
                    continue
                if math.isnan(self.get_state(name)):
                    self.set_state(name, 0.0)
                if itf.name == POSITION and not self.custom_interface_with_following_offset:
                    self.set_state(name, self.get_state(name) + self.position_state_following_offset)
        self._joint_modes = [POSITION] * len(self.info.joints)
        self._plan_runs = None
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- interfaces
    def export_command_interfaces(self) -> list[CommandInterface]:
        """Declared command interfaces, plus mock ones for sensor states and GPIO states when enabled."""
        commands = super().export_command_interfaces()
        names = {h.name for h in commands}

        def add_mock(components: Sequence[ComponentInfo]) -> None:
            for comp in components:
                for itf in comp.state_interfaces:
                    name = f"{comp.name}/{itf.name}"
                    if name not in names:
                        names.add(name)
                        value = parse_value(itf.initial_value, itf.data_type, where=name)
                        commands.append(CommandInterface(comp.name, itf.name, itf.data_type, value))

        if self.mock_sensor_commands:
            add_mock(self.info.sensors)
        if self.mock_gpio_commands:
            add_mock(self.info.gpios)
        return commands

    def _has_state(self, name: str) -> bool:
        return name in self._state_handles

    def _has_command(self, name: str) -> bool:
        return name in self._command_handles

    # ----------------------------------------------------------------- mode switching
    def _joint_of(self, key: str) -> int | None:
        # Upstream matches the first joint whose name is a *substring* of the key, so "joint1" also
        # claims "joint10/velocity". We match the key's prefix exactly instead.
        prefix = key.rpartition("/")[0]
        for index, joint in enumerate(self.info.joints):
            if joint.name == prefix:
                return index
        return None

    def prepare_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        """With ``calculate_dynamics``, reject a joint that starts none or more than one of position/velocity/acceleration.

        Without dynamics every request is accepted, as upstream. Non-joint keys (GPIO, sensors) are ignored.

        Args:
            start_interfaces: Command interfaces of this component about to be claimed.
            stop_interfaces: Command interfaces about to be released (not used).
        """
        if not self.calculate_dynamics:
            return ReturnType.OK
        counts: dict[int, int] = {}
        for key in start_interfaces:
            index = self._joint_of(key)
            if index is None:
                continue
            counts[index] = counts.get(index, 0) + (key.rpartition("/")[2] in _MODES)
        result = ReturnType.OK
        for index, count in counts.items():
            joint = self.info.joints[index].name
            if count == 0:
                self.mode_switch_rejection = (
                    f"joint '{joint}' needs one of the '{_MODES[0]}', '{_MODES[1]}' or '{_MODES[2]}' command interfaces"
                )
            elif count > 1 and not self.several_modes:
                self.mode_switch_rejection = f"joint '{joint}' got {count} control modes at once; only one is supported"
            else:
                continue
            self.logger.error("%s", self.mode_switch_rejection)
            result = ReturnType.ERROR
        return result

    def perform_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        """With ``calculate_dynamics``, put each joint in the mode of its started interface."""
        if not self.calculate_dynamics:
            return ReturnType.OK
        chosen: dict[int, str] = {}
        for key in start_interfaces:
            index = self._joint_of(key)
            mode = key.rpartition("/")[2]
            if index is not None and mode in _MODES:
                if index not in chosen or _MODES.index(mode) < _MODES.index(chosen[index]):
                    chosen[index] = mode  # several at once (a mocked driver's joint): the first of _MODES leads
        for index, mode in chosen.items():
            self._joint_modes[index] = mode
        return ReturnType.OK

    # ----------------------------------------------------------------- cyclic
    def _mirror(self, name: str) -> bool:
        """Copy command ``name`` to the state of the same name; False if the command is infinite."""
        value = self._command_handles[name].get_value()
        data_type = self._state_handles[name].data_type
        if not isinstance(value, int | float):  # None or a string written by a controller: refuse it clearly
            _log.error("hardware '%s': command '%s' holds %r, not a number; the read fails", self.info.name, name,
                       value)
            return False
        if data_type in _FLOAT_TYPES:
            if math.isinf(value):
                return False
            if not math.isnan(value):
                self._state_handles[name].set_value(value)
        elif data_type == "bool":
            self._state_handles[name].set_value(bool(value))
        # Integer interfaces are not mirrored, as upstream.
        return True

    def _position_offset(self) -> float:
        """Offset applied to the ``position`` state (zero when a custom interface carries it)."""
        return 0.0 if self.custom_interface_with_following_offset else self.position_state_following_offset

    def _integrate_joint(self, index: int, period: float) -> None:
        joint = self.info.joints[index].name
        keys = [f"{joint}/{itf}" for itf in _MODES]
        p, v, a = (self.get_state(k) if self._has_state(k) else math.nan for k in keys)
        cp, cv, ca = (self.get_command(k) if self._has_command(k) else math.nan for k in keys)

        def rate(new: float, old: float) -> float:
            return (new - old) / period if period > 0.0 else math.nan

        mode = self._joint_modes[index]
        if mode == POSITION:
            if math.isfinite(cp):
                old_p, old_v = p, (v if math.isfinite(v) else 0.0)
                p = cp + self._position_offset()
                v = rate(p, old_p)
                a = rate(v, old_v)
        else:
            if mode == ACCELERATION:
                if math.isnan(v):
                    v = 0.0
                if math.isfinite(ca):
                    a = ca
                v += 0.0 if math.isnan(a) else a * period
            elif math.isfinite(cv):  # velocity mode
                old_v = v if math.isfinite(v) else 0.0
                v = cv
                a = rate(v, old_v)
            if math.isfinite(v):
                p += v * period
            elif self.jazzy_offset_quirk:
                # Jazzy writes `p += isfinite(v) ? v*dt : 0.0 + offset`; by C++ precedence the offset
                # belongs to the else branch, so it is added on every cycle in which the velocity is
                # unknown. The offset is already in p since on_configure, so the intended update adds
                # nothing here; we only do this when asked to reproduce Jazzy.
                p += self._position_offset()
        for key, value in zip(keys, (p, v, a), strict=True):
            if math.isfinite(value) and self._has_state(key):
                self.set_state(key, value)

    def read(self, time: float, period: float) -> ReturnType:
        """Mirror commands to states (and integrate them with ``calculate_dynamics``).

        Velocity and acceleration modes never add the position offset on their own: the offset was added
        to the position once in ``on_configure`` and integration keeps it. (Jazzy adds it again on each
        cycle where the velocity is not finite, an operator-precedence bug; set
        :attr:`jazzy_offset_quirk` to reproduce it.)

        Args:
            time: Current time in [s].
            period: Time since the last read in [s].

        Returns:
            OK, or ERROR if a mirrored command is infinite.
        """
        if self.disable_commands:
            if not self._warned_disabled:
                self.logger.warning("hardware '%s': disable_commands is set, states will not change", self.info.name)
                self._warned_disabled = True
            return ReturnType.OK

        if not self.calculate_dynamics:
            return self._run_plan()  # positions follow their commands: prepared once, see mock_read_plan
        joints = self.info.joints
        for index in range(len(joints)):
            self._integrate_joint(index, period)

        skip = _MODES
        custom = self.custom_interface_with_following_offset
        for joint in joints:
            for itf in joint.state_interfaces:
                name = f"{joint.name}/{itf.name}"
                if itf.name in skip or not self._has_state(name):
                    continue
                if self._has_command(name) and not self._mirror(name):
                    return ReturnType.ERROR
                position_cmd = f"{joint.name}/{POSITION}"
                if custom and itf.name == custom and self._has_command(position_cmd):
                    value = self.get_command(position_cmd) + self.position_state_following_offset
                    if math.isfinite(value):
                        self.set_state(name, value)

        for mimic in self.info.mimic_joints:
            follower, source = joints[mimic.joint_index].name, joints[mimic.mimicked_joint_index].name
            for mode in _MODES:
                dst, src = f"{follower}/{mode}", f"{source}/{mode}"
                if self._has_state(dst) and self._has_state(src):
                    offset = mimic.offset if mode == POSITION else 0.0
                    self.set_state(dst, offset + mimic.multiplier * self.get_state(src))

        if self.mock_sensor_commands and not self._mirror_components(self.info.sensors, every_state=True):
            return ReturnType.ERROR
        if not self._mirror_components(self.info.gpios, every_state=self.mock_gpio_commands):
            return ReturnType.ERROR
        return ReturnType.OK

    # ----------------------------------------------------------------- prepared read (no dynamics)
    def _run_plan(self) -> ReturnType:
        runs = self._plan_runs
        if runs is None or self._plan_adoptions != ADOPTIONS.value:  # built before the handles moved: build again
            runs = self._plan_runs = runs_of_one_kind(build_read_steps(
                self.info, self._state_handles, self._command_handles, self._position_offset(),
                self.custom_interface_with_following_offset, self.position_state_following_offset,
                self.mock_sensor_commands, self.mock_gpio_commands))
            self._plan_adoptions = ADOPTIONS.value
        return run_read_plan(runs)

    def _mirror_components(self, components: Sequence[ComponentInfo], every_state: bool) -> bool:
        """Mirror sensor/GPIO commands to states; False if one is infinite."""
        for comp in components:
            itfs: list[InterfaceInfo] = comp.state_interfaces if every_state else comp.command_interfaces
            for itf in itfs:
                name = f"{comp.name}/{itf.name}"
                if self._has_command(name) and self._has_state(name) and not self._mirror(name):
                    return False
        return True

    def write(self, time: float, period: float) -> ReturnType:
        """Nothing to send: the mock's ``write`` always succeeds."""
        return ReturnType.OK
