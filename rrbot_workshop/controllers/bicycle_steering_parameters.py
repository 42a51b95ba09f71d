"""Declared parameters of ``bicycle_steering_controller/BicycleSteeringController`` (our wording).

Jazzy declares them in two files, ``steering_controllers_library.yaml`` (common to the bicycle, tricycle and
Ackermann controllers) and ``bicycle_steering_controller.yaml``; both are flat, so they share one namespace here.
The deprecated names (``front_steering``, ``rear_wheels_names``, ``front_wheels_names``, their ``*_state_names``,
``front_wheel_radius``, ``rear_wheel_radius``) are still declared in Jazzy and still read, with a warning.
"""

from __future__ import annotations

__all__ = ["BICYCLE_STEERING_CONTROLLER_PARAMETERS"]

_NAMES = "type: string_array, default_value: [], read_only: true, validation: {size_lt<>: [5], unique<>: null}"

#: generate_parameter_library YAML of :class:`~rrbot_workshop.controllers.bicycle_steering.BicycleSteeringController`.
BICYCLE_STEERING_CONTROLLER_PARAMETERS = f"""
bicycle_steering_controller:
  reference_timeout: {{type: double, default_value: 1.0, description: "Age in [s] after which a reference is dropped (the
    wheel stops); 0 uses each reference for one cycle only."}}
  front_steering: {{type: bool, default_value: true, read_only: true, description: "Deprecated: with rear_wheels_names
    or front_wheels_names, whether the front axle steers. Use traction_joints_names and steering_joints_names."}}
  traction_joints_names: {{{_NAMES}, description: "The traction (driven) wheel joint: one for a bicycle."}}
  steering_joints_names: {{{_NAMES}, description: "The steering joint: one for a bicycle. A positive angle turns the
    robot towards +z (REP-103)."}}
  traction_joints_state_names: {{{_NAMES}, description: "Joints to read the traction state from (default:
    traction_joints_names)."}}
  steering_joints_state_names: {{{_NAMES}, description: "Joints to read the steering state from (default:
    steering_joints_names)."}}
  rear_wheels_names: {{{_NAMES}, description: "Deprecated: use traction_joints_names (or steering_joints_names)."}}
  front_wheels_names: {{{_NAMES}, description: "Deprecated: use steering_joints_names (or traction_joints_names)."}}
  rear_wheels_state_names: {{{_NAMES}, description: "Deprecated: use traction_joints_state_names."}}
  front_wheels_state_names: {{{_NAMES}, description: "Deprecated: use steering_joints_state_names."}}
  open_loop: {{type: bool, default_value: false, description: "Integrate the odometry from the references instead of
    the joint feedback."}}
  reduce_wheel_speed_until_steering_reached: {{type: bool, default_value: false, description: "Slow the traction wheel
    while the steering angle is far from its target (closed loop only)."}}
  velocity_rolling_window_size: {{type: int, default_value: 10, description: "Steps averaged for the odometry twist."}}
  base_frame_id: {{type: string, default_value: base_link, description: "child_frame_id of the odometry."}}
  odom_frame_id: {{type: string, default_value: odom, description: "frame_id of the odometry."}}
  enable_odom_tf: {{type: bool, default_value: true, description: "Publish odom -> base on ~/tf_odometry (not modelled:
    there is no tf here)."}}
  twist_covariance_diagonal: {{type: double_array, default_value: [0.0, 7.0, 14.0, 21.0, 28.0, 35.0], description:
    "Diagonal of the odometry twist covariance."}}
  pose_covariance_diagonal: {{type: double_array, default_value: [0.0, 7.0, 14.0, 21.0, 28.0, 35.0], description:
    "Diagonal of the odometry pose covariance."}}
  position_feedback: {{type: bool, default_value: false, description: "Traction feedback is the wheel position (true)
    or velocity (false)."}}
  wheelbase: {{type: double, default_value: 0.0, description: "Distance between the front and rear axles in [m].",
    validation: {{gt<>: [0.0]}}}}
  traction_wheel_radius: {{type: double, default_value: 0.0, description: "Radius of the traction wheel in [m]."}}
  front_wheel_radius: {{type: double, default_value: 0.0, read_only: true, description: "Deprecated: use
    traction_wheel_radius."}}
  rear_wheel_radius: {{type: double, default_value: 0.0, read_only: true, description: "Deprecated: use
    traction_wheel_radius."}}
"""
