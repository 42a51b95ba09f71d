"""Declared parameters of ``pid_controller/PidController`` (Jazzy's ``pid_controller.yaml``, our wording).

Per-DOF gains live under ``gains.<dof>`` (``__map_dof_names``), as control_toolbox's ``PidROS`` reads them.
"""

from __future__ import annotations

__all__ = ["PID_CONTROLLER_PARAMETERS"]

#: generate_parameter_library YAML for :class:`~rrbot_workshop.controllers.pid.PidController`.
PID_CONTROLLER_PARAMETERS = """
pid_controller:
  dof_names:
    type: string_array
    default_value: []
    description: "DOFs to command: commands go to <dof>/<command_interface>."
    read_only: true
    validation:
      unique<>: []
      not_empty<>: []
  reference_and_state_dof_names:
    type: string_array
    default_value: []
    description: "DOFs for references and states, when they differ from dof_names (default: dof_names)."
    read_only: true
    validation:
      unique<>: []
  command_interface:
    type: string
    default_value: ""
    description: "Command interface written on every DOF."
    read_only: true
    validation:
      not_empty<>: []
  reference_and_state_interfaces:
    type: string_array
    default_value: []
    description: "One interface, or two where the second is the derivative of the first."
    read_only: true
    validation:
      not_empty<>: []
      size_gt<>: [0]
      size_lt<>: [3]
  set_current_state_as_first_setpoint:
    type: bool
    default_value: true
    description: "On activation, take the measured state as the reference."
  use_external_measured_states:
    type: bool
    default_value: false
    description: "Read the measured state from ~/measured_state instead of state interfaces."
  enable_feedforward:
    type: bool
    default_value: false
    description: "Add feedforward_gain times the reference to the command (also switched by ~/set_feedforward_control)."
  gains:
    __map_dof_names:
      p:
        type: double
        default_value: 0.0
        description: "Proportional gain."
      i:
        type: double
        default_value: 0.0
        description: "Integral gain."
      d:
        type: double
        default_value: 0.0
        description: "Derivative gain."
      feedforward_gain:
        type: double
        default_value: 0.0
        description: "Gain on the reference (or on its derivative with two interfaces)."
      u_clamp_max:
        type: double
        default_value: .inf
        description: "Upper output limit."
      u_clamp_min:
        type: double
        default_value: -.inf
        description: "Lower output limit."
      i_clamp_max:
        type: double
        default_value: .inf
        description: "Upper limit of the integral term."
      i_clamp_min:
        type: double
        default_value: -.inf
        description: "Lower limit of the integral term."
      antiwindup:
        type: bool
        default_value: false
        description: "Deprecated in Jazzy (legacy strategy): keep the stored integral within the integral clamps."
      antiwindup_strategy:
        type: string
        default_value: "legacy"
        description: "legacy (Jazzy's default), none, back_calculation or conditional_integration."
        validation:
          one_of<>: [["legacy", "none", "back_calculation", "conditional_integration"]]
      tracking_time_constant:
        type: double
        default_value: 0.0
        description: "Back-calculation time constant in [s]; 0 picks the default."
      error_deadband:
        type: double
        default_value: 1.0e-16
        description: "No integration while |error| is at most this."
      angle_wraparound:
        type: bool
        default_value: false
        description: "Wrap the error to [-pi, pi) for continuous joints."
      save_i_term:
        type: bool
        default_value: true
        description: "Keep the integral term when the controller is re-activated."
"""
