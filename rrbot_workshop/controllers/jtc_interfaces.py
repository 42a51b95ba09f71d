"""The loaned interfaces of the joint trajectory controller, sorted by kind and joint.

A JTC reads ``<joint>/<state interface>`` for each of its joints and writes
``<command joint>/<command interface>`` for each command joint, where the command joints may be fewer
than the joints (or, in a chain, another controller's references). :class:`JointInterfaces` keeps the
loans of an active JTC in joint order per interface kind and turns them into
``JointTrajectoryPoint`` values and back: the measured state, the last commands (as a state, when a
controller restarts), and the commands of a sample.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from rrbot_workshop.hardware_interface.handles import (
    LoanedCommandInterface,
    LoanedStateInterface,
    value_reader,
    value_writer,
)
from rrbot_workshop.msgs import JointTrajectoryPoint

__all__ = ["JointInterfaces"]


#: The command kinds in the order of JointTrajectoryPoint's fields (positions, velocities, accelerations, effort).
_POINT_KINDS = ("position", "velocity", "acceleration", "effort")

#: Per field of a point (positions, velocities, accelerations, effort), the command values, or None for a kind the
#: controller does not command.
CommandValues = tuple[list[float] | None, list[float] | None, list[float] | None, list[float] | None]


class JointInterfaces:
    """The command and state interfaces of an active JTC, per kind in joint order.

    Args:
        joints: The controller's joints (``joints`` parameter).
        command_joints: Prefixes of the command interfaces (``command_joints``, else ``joints``).
        command_kinds: ``command_interfaces`` parameter, e.g. ``["position", "velocity"]``.
        state_kinds: ``state_interfaces`` parameter.
        command_interfaces: The loaned command interfaces, in any order.
        state_interfaces: The loaned state interfaces, in any order.
        cmd_to_joint: For each command joint, the index of its joint in ``joints``.

    Raises:
        KeyError: With the full name of an interface the controller needs but was not given.
    """

    def __init__(
        self,
        joints: Sequence[str],
        command_joints: Sequence[str],
        command_kinds: Sequence[str],
        state_kinds: Sequence[str],
        command_interfaces: Sequence[LoanedCommandInterface],
        state_interfaces: Sequence[LoanedStateInterface],
        cmd_to_joint: Sequence[int],
    ) -> None:
        by_name_c = {c.name: c for c in command_interfaces}
        by_name_s = {s.name: s for s in state_interfaces}
        self._commands = {k: [by_name_c[f"{j}/{k}"] for j in command_joints] for k in command_kinds}
        self._states = {k: [by_name_s[f"{j}/{k}"] for j in joints] for k in state_kinds}
        self._cmd_to_joint = list(cmd_to_joint)
        self._dof = len(joints)
        # prepared once: read or write every interface of a kind in one call
        self._identity = self._cmd_to_joint == list(range(self._dof))
        self._read_state = {k: value_reader(v) for k, v in self._states.items()}
        self._read_command = {k: value_reader(v) for k, v in self._commands.items()}
        self._write_command = {k: value_writer(v) for k, v in self._commands.items()}
        read_s = self._read_state
        #: The state readers of a cycle: positions; velocities (None without); accelerations (None without velocities
        #: or without their own interfaces).
        self._read_p = read_s["position"]
        self._read_v = read_s.get("velocity")
        self._read_a = read_s.get("acceleration") if self._read_v is not None else None
        self._read_e = "effort" in self._commands
        #: Per field of a point, the reader of its command interfaces (None: the controller does not command it).
        self._command_readers = [self._read_command.get(kind) for kind in _POINT_KINDS]

    def command_values(self, kind: str, fill: float) -> list[float]:
        """Per joint, the value of its ``kind`` command interface, ``fill`` for joints without one."""
        read = self._read_command[kind]()
        if self._identity:
            return read
        values = [fill] * self._dof
        for i, value in enumerate(read):
            values[self._cmd_to_joint[i]] = value
        return values

    def read_state(self) -> JointTrajectoryPoint:
        """The measured state: positions, velocities and accelerations as far as the state interfaces go.

        Accelerations are read only together with velocities; the effort is the effort command (NaN for
        joints without one), as the state interfaces carry no effort.
        """
        read_v, read_a = self._read_v, self._read_a
        return JointTrajectoryPoint(self._read_p(), [] if read_v is None else read_v(),
                                    [] if read_a is None else read_a(),
                                    self.command_values("effort", math.nan) if self._read_e else [], 0.0)

    def state_from_commands(self) -> JointTrajectoryPoint | None:
        """The commands as a state (a controller restart), or None if a needed one is NaN.

        Velocities and accelerations are taken where the state interfaces have them, the effort where the
        command interfaces do.
        """
        def finite(kind: str) -> list[float] | None:
            if kind not in self._commands:
                return None
            vals = self.command_values(kind, math.nan)
            return vals if all(math.isfinite(v) for v in vals) else None

        point = JointTrajectoryPoint()
        pos = finite("position")
        if pos is None:
            return None
        point.positions = pos
        for kind, attr in (("velocity", "velocities"), ("acceleration", "accelerations")):
            if kind in self._states:
                vals = finite(kind)
                if vals is None:
                    return None
                setattr(point, attr, vals)
        if "effort" in self._commands:
            vals = finite("effort")
            if vals is None:
                return None
            point.effort = vals
        return point

    def positions_to_hold(self) -> list[float]:
        """Per joint, the last finite position command, else the measured position (padding partial goals)."""
        commands = self.command_values("position", math.nan) if "position" in self._commands else [math.nan] * self._dof
        return [c if math.isfinite(c) else self._states["position"][i].get_value() for i, c in enumerate(commands)]

    def command_point(self) -> JointTrajectoryPoint:
        """The current commands as a point (fields of the missing command kinds stay empty)."""
        p, v, a, e = self.command_values_now()
        return JointTrajectoryPoint([] if p is None else p, [] if v is None else v, [] if a is None else a,
                                    [] if e is None else e)

    def command_values_now(self) -> CommandValues:
        """The current commands, per field of a point, None for a kind the controller does not command
        (:meth:`command_point` without the point: a cycle keeps the numbers and builds the point only when someone
        reads its message)."""
        if self._identity:  # every joint commanded: each field is one read (the common case, in every cycle)
            rp, rv, ra, re = self._command_readers
            return (rp() if rp is not None else None, rv() if rv is not None else None,
                    ra() if ra is not None else None, re() if re is not None else None)
        p, v, a, e = (self.command_values(kind, math.nan) if kind in self._commands else None for kind in _POINT_KINDS)
        return p, v, a, e

    def write(self, kind: str, values: Sequence[float]) -> None:
        """Write per-joint ``values`` to the ``kind`` command interfaces; nothing if fewer values than joints."""
        if len(values) < self._dof:
            return  # e.g. interpolation 'none' and a waypoint without that field
        self._write_command[kind](values if self._identity else [values[j] for j in self._cmd_to_joint])

    def writer(self, kind: str) -> Callable[[Sequence[float]], None]:
        """:meth:`write` for one ``kind``, prepared: a function of per-joint values, at least one per joint (the
        caller checks the count; a controller takes one per kind at activation, as it writes every cycle)."""
        write, cmd_to_joint = self._write_command[kind], self._cmd_to_joint
        if self._identity:
            return write
        return lambda values: write([values[j] for j in cmd_to_joint])

    def stop_motion(self) -> None:
        """Set every velocity, acceleration and effort command to 0 (positions keep their last value)."""
        for kind in ("velocity", "acceleration", "effort"):
            for loan in self._commands.get(kind, []):
                loan.set_value(0.0)
