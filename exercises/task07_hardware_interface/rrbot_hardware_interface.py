"""Task 7: the driver of the RRBot device, ``controlko_hardware_interface/RRBotHardwareInterface``.

A hardware component is the only part of ros2_control that talks to the robot. The controller manager drives it
through its lifecycle and calls ``read`` and ``write`` every control cycle; controllers only ever see the state and
command interfaces it exports. The device is :class:`rrbot_workshop.hardware.rrbot_device.RRBotDevice`, with the
contract of the original workshop's comms library: ``init()``/``stop()``, ``set_control_mode``,
``write_joint_commands(positions, velocities, dt)``, ``read_joint_states()``, ``read_sensor_values(n)``,
``write_gpios(outputs)`` and ``read_gpio()``.

The lifecycle, as the resource manager drives it:

* ``on_init(info)``: the ``<ros2_control>`` tag, parsed; refuse what the device cannot do;
* ``on_configure``: open the device (the robot is reachable, its motors are off);
* ``on_activate``: enable movement; ``on_deactivate``: disable it;
* ``read``/``write`` every cycle while active (``read`` also while inactive);
* ``prepare_command_mode_switch``/``perform_command_mode_switch`` when controllers start or stop claiming
  command interfaces.

How it is checked: every state must carry the device's own value, unchanged (compared to 1e-9); the joints' motion
through a running controller manager is compared within 0.01 rad (one cycle at the device's 0.5 rad/s).

The interfaces themselves are exported for you, one per ``<state_interface>`` and ``<command_interface>`` of the
description: use ``self.set_state(name, value)``, ``self.get_command(name)`` and ``self.set_command(name, value)`` with
full names such as ``"joint1/position"``. Work through the TODOs in order; notebook 07 runs your driver after each step,
and ``rrbot-workshop grade 7`` checks it.
"""

from __future__ import annotations

import math

from rrbot_workshop.description.info import HardwareInfo
from rrbot_workshop.hardware import SystemInterface
from rrbot_workshop.hardware.rrbot_device import ControlMode, RRBotDevice
from rrbot_workshop.middleware.lifecycle import CallbackReturn, ReturnType, State

__all__ = ["RRBotHardwareInterface"]


class RRBotHardwareInterface(SystemInterface):
    """The RRBot driver."""

    def __init__(self) -> None:
        super().__init__()
        self.device: RRBotDevice | None = None
        self.joints: list[str] = []
        self.claimed: set[str] = set()  # joint command interfaces controllers hold now
        self.next_mode = ControlMode.POSITION

    # ------------------------------------------------------------------------------------------ 7.1 on_init

    def on_init(self, info: HardwareInfo) -> CallbackReturn:
        if super().on_init(info) is not CallbackReturn.SUCCESS:
            return CallbackReturn.ERROR
        # TODO(task 7.1): the description decides what this driver must serve. Refuse (log why, naming the element;
        #   return ERROR) a joint whose command interfaces are not exactly the two the device takes, or whose state
        #   interfaces lack the two it reports, and more than one sensor or one GPIO. Remember the joints' names.
        raise NotImplementedError("TODO(task 7.1): check the description in on_init")

    # ---------------------------------------------------------------------------- 7.2 configure, activate

    def on_configure(self, previous_state: State) -> CallbackReturn:
        # TODO(task 7.2): open the device: one RRBotDevice for the whole robot, sized to the description's joints
        #   (number_of_dofs = the number of <joint> elements) and seeded by the hardware parameter 'seed' (default 0).
        #   No controller holds a command interface yet. The device measures no torque: what should an effort state
        #   report (which float means "unknown")? Then fill the states once, so they show the robot as it is before
        #   anything runs.
        raise NotImplementedError("TODO(task 7.2): on_configure")

    def on_activate(self, previous_state: State) -> CallbackReturn:
        # TODO(task 7.2): enable the device's movement. A controller that takes over must not make the robot jump,
        #   in position or in velocity mode: what should the command interfaces hold at this moment?
        raise NotImplementedError("TODO(task 7.2): on_activate")

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        # TODO(task 7.2): disable movement.
        raise NotImplementedError("TODO(task 7.2): on_deactivate")

    def on_cleanup(self, previous_state: State) -> CallbackReturn:
        self.device = None
        return CallbackReturn.SUCCESS

    # ----------------------------------------------------------------------------------- 7.3 read, write

    def read(self, time: float, period: float) -> ReturnType:
        # TODO(task 7.3): from the device into the state interfaces: the joints (position, velocity and, if declared,
        #   acceleration), the sensor's values in the order of its state interfaces, and the GPIOs: digital_in_N is
        #   input N, digital_out_N reads back output N (1.0 or 0.0). The original got these wrong: effort carried the
        #   acceleration and the sensor and GPIO values were swapped. Each interface gets its own value. read also
        #   runs while the component is inactive. If the device fails (raises), report it: let the exception through
        #   or return ERROR, never OK.
        raise NotImplementedError("TODO(task 7.3): read")

    def write(self, time: float, period: float) -> ReturnType:
        # TODO(task 7.3): the joints' position and velocity commands to the device, for the period that passed (the
        #   device uses those of its mode), then the digital outputs (a command above 0.5 is on, 0.5 and below off;
        #   NaN: no command yet, keep the output). A failing device is reported here too.
        raise NotImplementedError("TODO(task 7.3): write")

    # ---------------------------------------------------------------------------------- 7.4 control modes

    def prepare_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        # TODO(task 7.4): may this switch happen? The device runs all its joints in ONE mode, position or velocity.
        #   Work out which joint command interfaces are claimed once the switch is done (those held now, minus
        #   stop_interfaces, plus this component's joints among start_interfaces), and which modes they are. Two
        #   modes: refuse (set self.mode_switch_rejection to the reason, log it, return ERROR); nothing changes then.
        #   One mode: remember it for perform_command_mode_switch. (The original had this check commented out.)
        raise NotImplementedError("TODO(task 7.4): prepare_command_mode_switch")

    def perform_command_mode_switch(self, start_interfaces: list[str], stop_interfaces: list[str]) -> ReturnType:
        # TODO(task 7.4): the switch happens: remember what is claimed now and put the device in the chosen mode.
        raise NotImplementedError("TODO(task 7.4): perform_command_mode_switch")
