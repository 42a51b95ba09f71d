"""``rrbot_workshop/MujocoSystem``: a simulated robot in MuJoCo, driven like real hardware.

This component plays the role Gazebo's ``gazebo_ros2_control/GazeboSystem`` plays in the original workshop. It
builds its physics model from the same URDF the controller manager receives (see :mod:`.mujoco_model`), so
the ``<ros2_control>`` tag is the only thing that changes between mock hardware and simulation.

Rules this component keeps:

* **Commands go through actuators only.** Each declared command interface has its own MuJoCo actuator
  (position servo, velocity servo or motor). ``write`` copies commands into ``data.ctrl``; positions are never
  written into the state, except by :meth:`MujocoSystem.reset` and by ``initial_value`` at configure time.
* **One mode per joint.** ``prepare_command_mode_switch`` refuses to drive a joint through two of
  ``position``/``velocity``/``effort`` at once; ``perform_command_mode_switch`` enables the chosen actuator and
  seeds its command from the current state (position: where the joint is; velocity: 0; effort: the torque that
  currently balances gravity), so a newly activated controller starts from rest.
* **Unclaimed joints are passive.** A joint no controller commands has every actuator switched off: gravity,
  damping and friction move it as physics says. The same holds for every joint while the component is inactive
  (motors off).
* **Lockstep time.** Physics advances in ``read(time, period)``, by ``period`` worth of ``timestep`` steps, under
  the controls of the previous ``write``. Fractions of a step are carried over, so the simulated time equals the
  sum of the periods the controller manager passed, to within one time step. Because ``read`` also runs while the
  component is inactive, the world keeps moving (and falling) when the hardware is deactivated.

Hardware parameters (``<hardware><param name=...>``): ``timestep`` [s] (default 0.001), ``position_kp``
[N m/rad] (1000), ``position_kv`` [N m s/rad] (20), ``velocity_kv`` [N m s/rad] (100), ``gravity`` (``true``,
``false`` or three numbers in [m/s^2]), ``add_floor`` (``true``). Joint parameters (``<joint><param>``):
``damping`` [N m s/rad], ``friction`` [N m], ``armature`` [kg m^2], and the three gains above for that joint.

State interfaces: joints ``position``, ``velocity``, ``acceleration``, ``effort`` (the actuator torque); a
force-torque ``<sensor>`` with ``fx fy fz tx ty tz`` and ``<param name="frame_id">``, reporting the wrench the
part of the robot beyond the frame exerts on it, in that frame (a hanging 1 kg load reads ``fz = -9.81`` when the
frame's z axis points up); GPIO states that mirror the same-named GPIO commands (GPIOs have no physics; the
other GPIO states, inputs with nothing wired to them, read their ``initial_value`` or 0).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import mujoco
import numpy as np

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.hardware.mujoco_config import simulation_request
from rrbot_workshop.hardware.mujoco_io import (
    CommandWrite,
    GpioMirror,
    command_write_steps,
    plan_command_writes,
    plan_gpio_mirrors,
    plan_state_reads,
)
from rrbot_workshop.hardware.mujoco_model import MujocoModel, build_model
from rrbot_workshop.hardware.mujoco_modes import command_modes_after_switch
from rrbot_workshop.hardware_interface.component_interface import SystemInterface
from rrbot_workshop.hardware_interface.handles import ADOPTIONS
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

__all__ = ["MujocoSystem"]


_OK = ReturnType.OK  # looked up once: reading a member off an enum class takes ~70 ns, read and write run every cycle


def _nothing() -> None:
    """The read plan before configure: no states to fill."""


class MujocoSystem(SystemInterface):
    """A ``<ros2_control>`` system simulated in MuJoCo. Plugin name ``rrbot_workshop/MujocoSystem``."""

    def __init__(self) -> None:
        super().__init__()
        self._sim: MujocoModel | None = None
        self._data: mujoco.MjData | None = None
        self._modes: dict[str, str | None] = {}
        self._pending_time: float = 0.0
        self._powered: bool = False
        self._timestep: float = 0.001
        self._model: mujoco.MjModel | None = None  # self._sim.model, for read
        self._ctrl: np.ndarray = np.zeros(0)  # data.ctrl, one view kept (each attribute access makes a new one)
        self._read_plan: Callable[[], None] = _nothing  # fills the joint and sensor states (see mujoco_io)
        self._read_plan_adoptions = -1
        self._write_plan: list[CommandWrite] = []
        self._write_steps: list[tuple[list[Any], int, int]] = []  # the write plan as (store, slot, actuator)
        self._write_steps_adoptions = -1
        self._gpio_mirrors: list[GpioMirror] = []
        #: Why the last ``prepare_command_mode_switch`` returned ERROR, or ``""``.
        self.mode_switch_rejection: str = ""

    # ----------------------------------------------------------------- description
    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        """Check the description and compile the MuJoCo model from the URDF.

        Returns ERROR, with the reason logged, when the URDF is missing or cannot be compiled, a parameter is
        not a number, or an interface cannot be simulated.
        """
        result = super().on_init(info)
        if result is not CallbackReturn.SUCCESS:
            return result
        try:
            request = simulation_request(info)
            self._sim = build_model(
                request.urdf,
                request.command_interfaces,
                request.force_torque_sensors,
                timestep=request.timestep,
                gains=request.gains,
                joint_dynamics=request.joint_dynamics,
                gravity=request.gravity,
                add_floor=request.add_floor,
            )
        except DescriptionError as exc:
            self.logger.error("MujocoSystem '%s': %s", info.name, exc)
            return CallbackReturn.ERROR
        if info.mimic_joints:
            self.logger.warning("MujocoSystem '%s': mimic joints are not simulated; they stay passive", info.name)
        self._timestep = request.timestep
        self._model = self._sim.model
        self._data = mujoco.MjData(self._model)
        self._ctrl = self._data.ctrl
        self._modes = {joint.name: None for joint in info.joints}
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- lifecycle
    def on_configure(self, previous_state: State) -> CallbackReturn:
        """Reset the simulation to ``initial_value`` positions and velocities and fill every state interface."""
        if self._sim is None:
            return CallbackReturn.ERROR
        self._modes = dict.fromkeys(self._modes)
        self._plan_read()
        self.reset()
        return CallbackReturn.SUCCESS

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        """Forget the command modes; every joint becomes passive."""
        self._set_all_passive(forget=True)
        return CallbackReturn.SUCCESS

    def on_activate(self, previous_state: State) -> CallbackReturn:
        """Power the actuators of the joints that have a command mode, holding where they are."""
        self._powered = True
        for joint, mode in self._modes.items():
            if mode is not None:
                self._enable(joint, mode)
        self._plan_write()
        return CallbackReturn.SUCCESS

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        """Motors off: all joints become passive (modes are remembered for the next activation)."""
        self._set_all_passive(forget=False)
        return CallbackReturn.SUCCESS

    def on_shutdown(self, previous_state: State) -> CallbackReturn:
        """Motors off."""
        self._set_all_passive(forget=True)
        return CallbackReturn.SUCCESS

    def on_error(self, previous_state: State) -> CallbackReturn:
        """Motors off; the component may be configured again."""
        self._set_all_passive(forget=True)
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------- mode switching
    def prepare_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        """Accept a switch only if every joint ends with at most one of position, velocity and effort.

        Returns ERROR (reason logged and kept in :attr:`mode_switch_rejection`) for an interface this component
        does not have, two modes started for one joint, or a mode started on a joint whose current mode is not
        stopped in the same switch.
        """
        self.mode_switch_rejection = ""
        try:
            command_modes_after_switch(self.info, self._modes, start_interfaces, stop_interfaces)
        except ValueError as exc:
            self.mode_switch_rejection = str(exc)
            self.logger.error("MujocoSystem '%s' rejects the mode switch: %s", self.get_name(), exc)
            return ReturnType.ERROR
        return ReturnType.OK

    def perform_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        """Switch actuators: stopped joints go passive, started joints hold their current state."""
        try:
            modes = command_modes_after_switch(self.info, self._modes, start_interfaces, stop_interfaces)
        except ValueError as exc:
            self.logger.error("MujocoSystem '%s' cannot perform the mode switch: %s", self.get_name(), exc)
            return ReturnType.ERROR
        for joint, mode in modes.items():
            if mode == self._modes[joint]:
                continue
            self._disable(joint)
            self._modes[joint] = mode
            if mode is not None and self._powered:
                self._enable(joint, mode)
        self._plan_write()
        return ReturnType.OK

    # ----------------------------------------------------------------- actuators
    def _enable(self, joint: str, mode: str) -> None:
        """Power the actuator of ``mode`` and seed its control and command from the current state."""
        assert self._sim is not None and self._data is not None
        binding = self._sim.joints[joint]
        actuator = binding.actuators[mode]
        if mode == "position":
            seed = float(self._data.qpos[binding.qpos_adr])
        elif mode == "velocity":
            seed = 0.0
        else:
            seed = float(self._data.qfrc_bias[binding.dof_adr])
        self._sim.enable(actuator)
        self._data.ctrl[actuator] = seed
        name = f"{joint}/{mode}"
        if name in self._command_handles:
            self.set_command(name, seed)

    def _disable(self, joint: str) -> None:
        assert self._sim is not None and self._data is not None
        for actuator in self._sim.joints[joint].actuators.values():
            self._sim.disable(actuator)
            self._data.ctrl[actuator] = 0.0

    def _set_all_passive(self, forget: bool) -> None:
        if self._sim is None or self._data is None:
            return
        self._powered = False
        self._sim.disable_all()
        self._data.ctrl[:] = 0.0
        self._write_plan = []
        self._write_steps = []
        if forget:
            self._modes = dict.fromkeys(self._modes)

    # ----------------------------------------------------------------- cyclic
    def _plan_read(self) -> None:
        """Work out, once, where each state interface reads from, so ``read`` is a flat loop."""
        assert self._sim is not None and self._data is not None
        self._read_plan = plan_state_reads(self.info, self._sim, self._data, self._state_handles)
        self._read_plan_adoptions = ADOPTIONS.value
        self._gpio_mirrors = plan_gpio_mirrors(self.info, self._state_handles, self._command_handles)

    def _plan_write(self) -> None:
        assert self._sim is not None
        self._write_plan = plan_command_writes(self._modes, self._sim, self._command_handles)
        self._write_steps = command_write_steps(self._write_plan)
        self._write_steps_adoptions = ADOPTIONS.value

    def read(self, time: float, period: float) -> ReturnType:
        """Advance physics by ``period`` (whole time steps, remainder carried over), then fill the states.

        Args:
            time: Controller manager time in [s] (unused: the simulation counts its own steps).
            period: Time since the last read in [s].
        """
        data = self._data
        assert data is not None, "on_init has not succeeded"
        if period > 0.0:  # also false for NaN
            pending = self._pending_time + period
            steps = int(pending / self._timestep + 1e-9)
            if steps > 0:
                mujoco.mj_step(self._model, data, steps)  # nstep passed by position: cheaper than by keyword
                pending -= steps * self._timestep
            self._pending_time = pending
        self._publish_states()
        return _OK

    def _publish_states(self) -> None:
        if self._read_plan_adoptions != ADOPTIONS.value:  # the handles moved since the plan was made
            self._plan_read()
        self._read_plan()
        if self._gpio_mirrors:
            self._mirror_gpios()

    def _mirror_gpios(self) -> None:
        """Copy each mirrored GPIO command into its state, except NaN (an unset command)."""
        for command_store, command_slot, state_store, state_slot in self._gpio_mirrors:
            value = command_store[command_slot]
            if not isinstance(value, float) or value == value:  # a NaN command leaves the state as it is
                state_store[state_slot] = value

    def write(self, time: float, period: float) -> ReturnType:
        """Copy the commands of the active modes into ``data.ctrl``; non-finite commands keep the last control.

        Args:
            time: Controller manager time in [s].
            period: Time since the last write in [s].
        """
        assert self._data is not None, "on_init has not succeeded"
        if self._write_steps_adoptions != ADOPTIONS.value:  # the command handles moved since the plan was made
            self._write_steps = command_write_steps(self._write_plan)
            self._write_steps_adoptions = ADOPTIONS.value
        ctrl, isfinite = self._ctrl, math.isfinite
        for store, slot, actuator in self._write_steps:  # the commands' flat lists and indices
            value = store[slot]
            if isfinite(value):
                ctrl[actuator] = value
        return _OK

    # ----------------------------------------------------------------- simulation access
    def reset(self, positions: Mapping[str, float] | None = None, velocities: Mapping[str, float] | None = None) -> None:
        """Put the robot back to its initial state (the only place joint positions are written directly).

        The initial state is the URDF zero, overridden by each joint's ``position``/``velocity`` state
        ``initial_value``, overridden by ``positions``/``velocities``. Time restarts at 0. Joints that have a
        command mode hold the new position.

        Args:
            positions: Joint name -> position in [rad] or [m].
            velocities: Joint name -> velocity in [rad/s] or [m/s].

        Raises:
            KeyError: If a joint name is not a joint of this component.
        """
        assert self._sim is not None and self._data is not None
        for name in [*(positions or {}), *(velocities or {})]:
            if name not in self._sim.joints:
                raise KeyError(f"'{name}' is not a joint of '{self.get_name()}' (valid: {', '.join(self._sim.joints)})")
        model, data = self._sim.model, self._data
        mujoco.mj_resetData(model, data)
        self._pending_time = 0.0
        for joint in self.info.joints:
            binding = self._sim.joints[joint.name]
            for itf in joint.state_interfaces:
                if itf.name in ("position", "velocity") and itf.initial_value.strip():
                    array = data.qpos if itf.name == "position" else data.qvel
                    array[binding.qpos_adr if itf.name == "position" else binding.dof_adr] = float(itf.initial_value)
            if positions and joint.name in positions:
                data.qpos[binding.qpos_adr] = positions[joint.name]
            if velocities and joint.name in velocities:
                data.qvel[binding.dof_adr] = velocities[joint.name]
            joint_id = binding.joint_id
            q = data.qpos[binding.qpos_adr]
            low, high = model.jnt_range[joint_id]
            if model.jnt_limited[joint_id] and not low <= q <= high:
                self.logger.warning(
                    "MujocoSystem '%s': initial position %.4g of '%s' is outside its limits [%.4g, %.4g]",
                    self.get_name(), q, joint.name, low, high,
                )
        mujoco.mj_forward(model, data)
        if self._powered:
            for joint_name, mode in self._modes.items():
                if mode is not None:
                    self._enable(joint_name, mode)
        self._publish_states()

    def get_model(self) -> mujoco.MjModel:
        """The compiled MuJoCo model (for viewers and notebooks; do not change its sizes)."""
        assert self._sim is not None, "on_init has not succeeded"
        return self._sim.model

    def get_data(self) -> mujoco.MjData:
        """The live MuJoCo data (read it; writing it bypasses the actuators)."""
        assert self._data is not None, "on_init has not succeeded"
        return self._data

    @property
    def simulation(self) -> MujocoModel:
        """The model with its joint, actuator and sensor tables."""
        assert self._sim is not None, "on_init has not succeeded"
        return self._sim

    @property
    def sim_time(self) -> float:
        """Simulated time since the last configure or reset in [s]."""
        return float(self._data.time) if self._data is not None else 0.0

    @property
    def command_modes(self) -> dict[str, str | None]:
        """Joint name -> the command interface driving it, or None for a passive joint."""
        return dict(self._modes)
