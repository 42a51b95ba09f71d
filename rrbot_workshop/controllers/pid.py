"""``pid_controller/PidController``: one control_toolbox PID per degree of freedom, chainable.

For each DOF ``i`` the controller reads a reference (from ``~/reference`` or, when chained, from its
exported reference interfaces ``<controller>/<dof>/<interface>``) and a measured state (state interfaces
``<dof>/<interface>``, or ``~/measured_state``), and writes ``<dof>/<command_interface>``::

    ff    = feedforward_gain * (reference_dot if two interfaces else reference)   (0 unless feed-forward is on)
    error = reference - state                      (shortest angle if angle_wraparound)
    cmd   = ff + pid(error, reference_dot - state_dot, dt)   or  ff + pid(error, dt)

A DOF whose reference or state is not finite is not written. ``reference_and_state_interfaces`` holds
one interface (e.g. ``[position]``) or two (``[position, velocity]``; the second is the derivative of
the first). Interfaces are ordered interface-major, as in ros2_controllers: all DOFs of the first
interface, then all DOFs of the second.

Feed-forward is off by default, as in Jazzy: ``feedforward_gain`` counts only once it is switched on, by the
parameter ``enable_feedforward: true`` or by the service ``~/set_feedforward_control`` (``std_srvs/SetBool``; Jazzy
marks both for deprecation in favour of a non-zero gain alone). A YAML that sets a gain and leaves the mode off gets a
command without feed-forward (lint warns about it).

As Jazzy's ``update_parameters``, the controller re-reads its parameters at the next update after any of them is set
(``get_node().set_parameters``): ``enable_feedforward`` then sets the mode again (overriding the service), and the
gains take effect at once. Parameters that shape the interfaces (``dof_names``, ``command_interface``,
``reference_and_state_*``, ``use_external_measured_states``) wait for the next configure.

Differences from Jazzy, on purpose: ``~/reference`` messages are matched to DOFs by name (Jazzy's callback means
to reorder them but does not).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from rrbot_workshop.control_toolbox.pid import Gains, Pid
from rrbot_workshop.controller_interface.base import (
    ChainableControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
)
from rrbot_workshop.controllers.pid_parameters import PID_CONTROLLER_PARAMETERS
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.hardware_interface.handles import CommandInterface, StateInterface
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State
from rrbot_workshop.middleware.params import Params
from rrbot_workshop.middleware.topics import Publisher, Subscription
from rrbot_workshop.msgs import (
    Header,
    MultiDOFCommand,
    MultiDOFStateStamped,
    SetBoolRequest,
    SetBoolResponse,
    SingleDOFState,
)

__all__ = ["PidController", "shortest_angular_distance"]


def shortest_angular_distance(from_angle: float, to_angle: float) -> float:
    """``to - from`` wrapped into [-pi, pi) [rad] (ROS ``angles::shortest_angular_distance``)."""
    a = math.fmod(to_angle - from_angle + math.pi, 2.0 * math.pi)
    if a < 0.0:
        a += 2.0 * math.pi
    return a - math.pi


class PidController(ChainableControllerInterface):
    """PID per DOF with exported reference and state interfaces (ros2_controllers ``pid_controller``).

    Attributes:
        pids: One :class:`~rrbot_workshop.control_toolbox.pid.Pid` per DOF (created at configure).
        feedforward_mode_enabled: Whether ``feedforward_gain`` is applied: ``enable_feedforward`` whenever the
            parameters are read anew, and ``~/set_feedforward_control`` in between.
        reference_and_state_dof_names: DOF names used for references and states.
    """

    PARAMETERS: ClassVar[str | None] = PID_CONTROLLER_PARAMETERS

    def __init__(self) -> None:
        super().__init__()
        self.pids: list[Pid] = []
        self.reference_and_state_dof_names: list[str] = []
        self._params: Params | None = None
        self._dof_names: list[str] = []
        self._interfaces: list[str] = []
        self._dof = 0
        self._ref_msg: MultiDOFCommand | None = None
        self._measured_msg: MultiDOFCommand | None = None
        self._measured: list[float] = []
        self._state_values: list[float] = []
        self._ref_sub: Subscription | None = None
        self._measured_sub: Subscription | None = None
        self._state_pub: Publisher | None = None
        self._ff_srv: Any = None
        self.feedforward_mode_enabled = False
        self._revision: int | None = None  # the node's parameters_revision the parameters were last read at
        self._external_states = False  # use_external_measured_states, as configured
        self._command_interface = ""  # as configured
        self._gains: dict[str, Any] = {}  # each configured DOF's gains.<dof> parameters, live

    # ----------------------------------------------------------------- configuration
    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Read parameters, build one Pid per DOF, create topics."""
        assert self.param_listener is not None
        params = self.param_listener.get_params()
        self._params = params
        self._dof_names = list(params.dof_names)
        self._interfaces = list(params.reference_and_state_interfaces)
        self.reference_and_state_dof_names = list(params.reference_and_state_dof_names) or list(self._dof_names)
        if len(self.reference_and_state_dof_names) != len(self._dof_names):
            self.logger.error(
                "'%s': parameter 'reference_and_state_dof_names' has %d entries but 'dof_names' has %d; "
                "they must have the same size", self.get_name(), len(self.reference_and_state_dof_names),
                len(self._dof_names),
            )
            return CallbackReturn.FAILURE
        self._dof = len(self._dof_names)
        self.pids = []
        for dof in self._dof_names:
            g = params.gains.dof_names_map[dof]
            try:
                self.pids.append(Pid(
                    g.p, g.i, g.d, g.u_clamp_max, g.u_clamp_min, g.i_clamp_max, g.i_clamp_min,
                    g.antiwindup_strategy, g.tracking_time_constant, g.error_deadband, g.antiwindup,
                ))
            except ParameterError as exc:
                self.logger.error("'%s': gains of '%s' (parameters gains.%s.*) are invalid: %s",
                                  self.get_name(), dof, dof, exc)
                return CallbackReturn.FAILURE

        node = self.get_node()
        if node.parameters_revision != self._revision:
            # Jazzy's update_parameters sets the mode only from parameters it has not read yet: a mode set by the
            # service survives a cleanup and configure with unchanged parameters
            self.feedforward_mode_enabled = bool(params.enable_feedforward)
        self._revision = node.parameters_revision
        self._external_states = bool(params.use_external_measured_states)
        self._command_interface = params.command_interface
        self._gains = {dof: params.gains.dof_names_map[dof] for dof in self._dof_names}
        self._ref_msg = self._empty_msg()
        self._measured_msg = self._empty_msg()
        self._measured = [math.nan] * (self._dof * len(self._interfaces))
        self._state_values = list(self._measured)
        if self._ref_sub is None:
            self._ref_sub = node.create_subscription(MultiDOFCommand, "~/reference", self._on_reference)
        if params.use_external_measured_states and self._measured_sub is None:
            self._measured_sub = node.create_subscription(
                MultiDOFCommand, "~/measured_state", self._on_measured_state)
        if self._state_pub is None:
            self._state_pub = node.create_publisher(MultiDOFStateStamped, "~/controller_state")
        if self._ff_srv is None:
            self._ff_srv = node.create_service(SetBoolRequest, "~/set_feedforward_control", self._on_set_feedforward)
        return CallbackReturn.SUCCESS

    def _update_parameters(self) -> None:
        """Re-read the parameters after one was set (Jazzy's ``update_parameters``, called at each update).

        The feed-forward mode follows ``enable_feedforward`` again and each DOF's Pid takes its new gains. Invalid
        values are logged and the running ones stay.
        """
        assert self.param_listener is not None and self._params is not None
        self._revision = self.get_node().parameters_revision
        try:
            params = self.param_listener.refresh()
        except ParameterError as exc:
            self.logger.error("'%s': new parameters not taken: %s; the running ones stay", self.get_name(), exc)
            return
        for name in ("dof_names", "reference_and_state_dof_names", "command_interface",
                     "reference_and_state_interfaces", "use_external_measured_states"):
            if params[name] != self._params[name]:
                self.logger.warning("'%s': parameter '%s' changed to %r; it takes effect at the next configure",
                                    self.get_name(), name, params[name])
        for dof, pid in zip(self._dof_names, self.pids, strict=True):
            g = params.gains.dof_names_map.get(dof)  # None: dof_names changed, this DOF's gains stay until configure
            if g is not None:  # as control_toolbox's PidROS: invalid gains are logged and the old ones stay
                if pid.set_gains(Gains(g.p, g.i, g.d, g.u_clamp_max, g.u_clamp_min, g.i_clamp_max, g.i_clamp_min,
                                       g.antiwindup_strategy, g.tracking_time_constant, g.error_deadband,
                                       g.antiwindup)):
                    self._gains[dof] = g
        self._params = params
        self.feedforward_mode_enabled = bool(params.enable_feedforward)

    def _on_set_feedforward(self, request: SetBoolRequest) -> SetBoolResponse:
        if not isinstance(request, SetBoolRequest) or not isinstance(request.data, bool):
            return SetBoolResponse(success=False, message=f"expected std_srvs/SetBool with a bool 'data', got {request!r}")
        self.feedforward_mode_enabled = request.data
        self.logger.warning("'%s': feed-forward %s; Jazzy plans to drop this service in favour of a non-zero "
                            "'feedforward_gain' alone", self.get_name(), "on" if request.data else "off")
        return SetBoolResponse(success=True, message=f"feed-forward {'on' if request.data else 'off'}")

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Drop the PIDs and subscriptions."""
        for sub in (self._ref_sub, self._measured_sub):
            if sub is not None:
                sub.destroy()
        self._ref_sub = self._measured_sub = None
        self.pids = []
        return CallbackReturn.SUCCESS

    def _empty_msg(self) -> MultiDOFCommand:
        n = len(self.reference_and_state_dof_names)
        return MultiDOFCommand(list(self.reference_and_state_dof_names), [math.nan] * n, [math.nan] * n)

    def command_interface_configuration(self) -> InterfaceConfiguration:
        """``<dof>/<command_interface>`` for each DOF."""
        itf = self._command_interface
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, [f"{d}/{itf}" for d in self._dof_names])

    def state_interface_configuration(self) -> InterfaceConfiguration:
        """``<ref_dof>/<interface>``, interface-major; none with external measured states."""
        if self._params is not None and self._external_states:
            return InterfaceConfiguration(InterfaceConfigurationType.NONE)
        names = [f"{d}/{i}" for i in self._interfaces for d in self.reference_and_state_dof_names]
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, names)

    def on_export_reference_interfaces(self) -> list[CommandInterface]:
        """``<controller>/<dof>/<interface>``, interface-major, NaN until written."""
        name = self.get_name()
        return [CommandInterface(name, f"{d}/{i}", initial_value=math.nan)
                for i in self._interfaces for d in self.reference_and_state_dof_names]

    def on_export_state_interfaces(self) -> list[StateInterface]:
        """The measured state, re-exported as ``<controller>/<dof>/<interface>``."""
        name = self.get_name()
        return [StateInterface(name, f"{d}/{i}", initial_value=math.nan)
                for i in self._interfaces for d in self.reference_and_state_dof_names]

    # ----------------------------------------------------------------- topics (non-real-time side)
    def _reorder(self, msg: MultiDOFCommand, topic: str) -> MultiDOFCommand | None:
        expected = self.reference_and_state_dof_names
        n = len(expected)
        if len(msg.values) != n:
            self.logger.error("'%s': rejected a message on %s: field 'values' has %d entries, expected %d (%s)",
                              self.get_name(), topic, len(msg.values), n, expected)
            return None
        if msg.values_dot and len(msg.values_dot) != n:
            self.logger.error(
                "'%s': rejected a message on %s: field 'values_dot' has %d entries, expected %d or none",
                self.get_name(), topic, len(msg.values_dot), n)
            return None
        dots = list(msg.values_dot) if msg.values_dot else [math.nan] * n
        if not msg.dof_names:
            self.logger.warning("'%s': message on %s has no 'dof_names'; assuming the order %s",
                                self.get_name(), topic, expected)
            return MultiDOFCommand(list(expected), [float(v) for v in msg.values], [float(v) for v in dots])
        if len(msg.dof_names) != n:
            self.logger.error("'%s': rejected a message on %s: field 'dof_names' has %d entries, expected %d (%s)",
                              self.get_name(), topic, len(msg.dof_names), n, expected)
            return None
        unknown = [d for d in msg.dof_names if d not in expected]
        if unknown or len(set(msg.dof_names)) != n:
            self.logger.error("'%s': rejected a message on %s: field 'dof_names' = %s must name each of %s once",
                              self.get_name(), topic, msg.dof_names, expected)
            return None
        index = {d: k for k, d in enumerate(msg.dof_names)}
        return MultiDOFCommand(list(expected), [float(msg.values[index[d]]) for d in expected],
                               [float(dots[index[d]]) for d in expected])

    def _on_reference(self, msg: MultiDOFCommand) -> None:
        ordered = self._reorder(msg, "~/reference")
        if ordered is not None:
            self._ref_msg = ordered

    def _on_measured_state(self, msg: MultiDOFCommand) -> None:
        if msg.values_dot and len(self._interfaces) != 2:
            self.logger.error("'%s': rejected a message on ~/measured_state: field 'values_dot' needs two "
                              "'reference_and_state_interfaces', got %s", self.get_name(), self._interfaces)
            return
        ordered = self._reorder(msg, "~/measured_state")
        if ordered is not None:
            self._measured_msg = ordered

    # ----------------------------------------------------------------- lifecycle
    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Reset PIDs (keeping the integral when ``save_i_term``), clear references, take the first setpoint."""
        assert self._params is not None
        self._ref_msg = self._empty_msg()
        self._measured_msg = self._empty_msg()
        for h in self.reference_interfaces:
            h.set_value(math.nan)
        self._measured = [math.nan] * len(self._measured)
        for dof, pid in zip(self._dof_names, self.pids, strict=True):
            pid.reset(save_i_term=self._gains[dof].save_i_term)
        if self._params.set_current_state_as_first_setpoint and not self._external_states:
            for h, loan in zip(self.reference_interfaces, self.state_interfaces):  # noqa: B905 - strict= is slow
                h.set_value(float(loan.get_value()))
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Nothing to stop: the last command stays until another controller writes."""
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- cycle
    def update_reference_from_subscribers(self, time: float, period: float) -> ReturnType:
        """Copy fresh topic values into the reference interfaces (each message value is used once)."""
        msg = self._ref_msg
        if msg is None:
            return ReturnType.OK
        two = len(self.reference_interfaces) == 2 * self._dof
        for i in range(self._dof):
            if not math.isnan(msg.values[i]):
                self.reference_interfaces[i].set_value(msg.values[i])
                if two and not math.isnan(msg.values_dot[i]):
                    self.reference_interfaces[self._dof + i].set_value(msg.values_dot[i])
                msg.values[i] = math.nan
        return ReturnType.OK

    def update_and_write_commands(self, time: float, period: float) -> ReturnType:
        """Run each DOF's PID and write its command; publish ``~/controller_state``."""
        if self._node is not None and self._node.parameters_revision != self._revision:
            self._update_parameters()
        assert self._params is not None
        n = self._dof
        if self._external_states:
            m = self._measured_msg
            if m is not None:
                for i in range(n):
                    self._measured[i] = m.values[i]
                    if len(self._measured) == 2 * n:
                        self._measured[n + i] = m.values_dot[i]
        else:
            for k, loan in enumerate(self.state_interfaces):
                self._measured[k] = float(loan.get_value())
        for h, v in zip(self.exported_state_interfaces, self._measured):  # noqa: B905 - strict= is slow
            h.set_value(v)

        refs = [h.get_value() for h in self.reference_interfaces]
        two = len(refs) == 2 * n and len(self._measured) == 2 * n
        gains = self._gains
        feedforward = self.feedforward_mode_enabled
        for i in range(n):
            ref, state = refs[i], self._measured[i]
            if not (math.isfinite(ref) and math.isfinite(state)):
                continue
            g = gains[self._dof_names[i]]
            if not feedforward:
                ff = 0.0
            elif len(refs) == 2 * n:
                ff = refs[n + i] * g.feedforward_gain if math.isfinite(refs[n + i]) else 0.0
            else:
                ff = ref * g.feedforward_gain
            error = shortest_angular_distance(state, ref) if g.angle_wraparound else ref - state
            if two and math.isfinite(refs[n + i]) and math.isfinite(self._measured[n + i]):
                out = self.pids[i].compute_command(error, refs[n + i] - self._measured[n + i], period)
            else:
                out = self.pids[i].compute_command(error, period)
            self.command_interfaces[i].set_value(ff + out)

        if self._state_pub is not None:  # built when someone reads it, from this cycle's numbers
            outputs = [float(self.command_interfaces[i].get_value()) for i in range(len(self.reference_and_state_dof_names))]
            self._state_pub.publish_lazy(_state_message, time, period, self.reference_and_state_dof_names,
                                         self._dof_names, gains, refs, list(self._measured), outputs, n, two)
        return ReturnType.OK


def _state_message(time: float, period: float, names: list[str], dof_names: list[str], gains: Any, refs: list[float],
                   measured: list[float], outputs: list[float], n: int, two: bool) -> MultiDOFStateStamped:
    """The ``~/controller_state`` message of one cycle of the PID controller."""
    msg = MultiDOFStateStamped(header=Header(stamp=time))
    for i, name in enumerate(names):
        ref, state = refs[i], measured[i]
        s = SingleDOFState(name=name, reference=ref, feedback=state, time_step=period, output=outputs[i])
        s.error = shortest_angular_distance(state, ref) if gains[dof_names[i]].angle_wraparound else ref - state
        if two:
            s.feedback_dot = measured[n + i]
            s.error_dot = refs[n + i] - measured[n + i]
        msg.dof_states.append(s)
    return msg

