"""Task 8: the DisplacementController, a ros2_control controller written from scratch.

It moves joints by *displacements*: each ``control_msgs/JointJog`` received on ``~/reference`` says how far each
joint should move from where it is now; the controller applies each displacement once, in the next update, as
``command = current state + displacement`` (halved in slow mode, switched with the ``~/set_slow_control_mode``
service), and publishes ``~/state``. Plugin names: ``controlko_controllers/DisplacementController`` and
``displacement_controller/DisplacementController``, both resolving to the class in this file.

The life of a controller, as the controller manager drives it:

* load: ``on_init`` declares the parameters (here from ``PARAMETERS``, as generate_parameter_library would);
* configure: ``on_configure`` reads them and creates topics and services;
* the manager asks which interfaces to claim (``command_interface_configuration`` and
  ``state_interface_configuration``), and loans them in that order;
* activate: ``on_activate``; then ``update`` every cycle, the only method that runs in the real-time loop;
* deactivate: ``on_deactivate`` leaves the commanded interfaces in a safe state.

The rules hold for any joints, interface, controller name and rate the parameters and the manager give (the
grader tries others than the notebook's). Commands and ``~/state`` are compared to 1e-9: the arithmetic is exact.

Work through the TODOs in order; notebook 08 runs your class after each step. ``rrbot-workshop grade 8`` checks it.
"""

from __future__ import annotations

import math
from typing import ClassVar

from rrbot_workshop.controller_interface import (
    CallbackReturn,
    ControllerInterface,
    InterfaceConfiguration,
    InterfaceConfigurationType,
    ReturnType,
)
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.middleware.params import register_validator
from rrbot_workshop.msgs import Header, JointControllerState, JointJog, SetBoolRequest, SetBoolResponse

__all__ = ["DisplacementController", "forbidden_interface_name_prefix"]


# ------------------------------------------------------------------------------------------ 8.1 parameters


def forbidden_interface_name_prefix(value: str, prefix: str) -> str | None:
    """A custom parameter validator: None if ``value`` is fine, else the reason it is refused."""
    # TODO(task 8.1): refuse a value that starts with the prefix given in the schema. A validator never raises:
    #   it answers None (valid) or a sentence saying why not; the parameter library adds the parameter's name.
    raise NotImplementedError("TODO(task 8.1): write the forbidden_interface_name_prefix validator")


# The schema below names it as displacement_controller::forbidden_interface_name_prefix.
register_validator("displacement_controller::forbidden_interface_name_prefix", forbidden_interface_name_prefix)


class DisplacementController(ControllerInterface):
    """Applies each received joint displacement once: ``command = state + displacement``."""

    # generate_parameter_library's YAML: names, types, defaults and validation of every parameter
    PARAMETERS: ClassVar[str | None] = """
displacement_controller:
  joints:
    type: string_array
    default_value: []
    description: "Joints to command, in the order the commands are claimed."
    read_only: true
    validation:
      unique<>: []
      not_empty<>: []
  state_joints:
    type: string_array
    default_value: []
    description: "Joints whose state is read; empty: the same as 'joints'."
    read_only: true
    validation:
      unique<>: []
  interface_name:
    type: string
    default_value: ""
    description: "The interface commanded and read on every joint."
    read_only: true
    validation:
      not_empty<>: []
      one_of<>: [["position", "velocity", "acceleration", "effort"]]
"""
    # TODO(task 8.1): the original workshop refuses interface names that start with "blup_", with the custom
    #   validator above. Add it to the validation of interface_name (before one_of<>, so its message is the one
    #   a learner sees), with the prefix as its argument.

    def __init__(self) -> None:
        super().__init__()
        self.joints: list[str] = []
        self.state_joints: list[str] = []
        self.interface_name = ""
        self.slow_mode = False
        #: The displacement waiting for the next update, per joint (NaN: none).
        self.displacements: list[float] = []
        self._state_publisher = None

    # -------------------------------------------------------------------------------------- 8.2 configure

    def on_configure(self, previous_state: State) -> CallbackReturn:
        # TODO(task 8.2): read the parameters (self.param_listener.get_params()). state_joints falls back to joints
        #   when empty; a different size is a configuration error (say so in the log, return FAILURE). Start with
        #   no displacement pending and in fast mode, then create the node's ~/reference subscription (JointJog),
        #   ~/set_slow_control_mode service (SetBoolRequest) and ~/state publisher (JointControllerState).
        raise NotImplementedError("TODO(task 8.2): on_configure")

    def command_interface_configuration(self) -> InterfaceConfiguration:
        # TODO(task 8.2): which command interfaces does the manager loan to this controller, in which order?
        raise NotImplementedError("TODO(task 8.2): command_interface_configuration")

    def state_interface_configuration(self) -> InterfaceConfiguration:
        # TODO(task 8.2): and which state interfaces does it read?
        raise NotImplementedError("TODO(task 8.2): state_interface_configuration")

    # --------------------------------------------------------------------- 8.3 topic and service callbacks

    def _on_reference(self, msg: JointJog) -> None:
        # TODO(task 8.3): keep the message's displacements for the next update, one per joint of the controller,
        #   matched to the joints by name; a newer message replaces one not applied yet (they do not add up). A
        #   message that does not give one displacement for each joint (fewer or more, an unknown joint, a joint
        #   named twice, another number of displacements than names) is refused with a logged reason, and changes
        #   nothing, not even a displacement still waiting for the update.
        raise NotImplementedError("TODO(task 8.3): _on_reference")

    def _on_set_slow_control_mode(self, request: SetBoolRequest) -> SetBoolResponse:
        # TODO(task 8.3): data=True switches to slow mode (displacements halved), False back to fast, whatever the
        #   mode was before; answer success=True. The controller starts fast; the mode at the update counts.
        raise NotImplementedError("TODO(task 8.3): _on_set_slow_control_mode")

    # ------------------------------------------------------------------------- 8.4 activate, update, deactivate

    def on_activate(self, previous_state: State) -> CallbackReturn:
        # TODO(task 8.4): what should happen to a displacement received while the controller was inactive, or left
        #   pending when it was deactivated?
        raise NotImplementedError("TODO(task 8.4): on_activate")

    def update(self, time: float, period: float) -> ReturnType:
        # TODO(task 8.4): the real-time part. For each joint with a pending displacement, command where the joint is
        #   now plus the displacement (halved in slow mode), and use each displacement only once. Then publish
        #   ~/state for the first joint after every update, also one that moved nothing: header stamp the time,
        #   frame_id that joint; set_point and command its command, process_value its state,
        #   error = set_point - process_value, time_step the period this update received (a controller may run
        #   slower than the loop: never assume 0.01 s).
        raise NotImplementedError("TODO(task 8.4): update")

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        # TODO(task 8.4): leave no stale command behind, on any of the command interfaces, for the next controller
        #   that claims them.
        raise NotImplementedError("TODO(task 8.4): on_deactivate")
