"""What ROS 2 gives a node, in process: clock, lifecycle states, parameters, topics and services, plugins.

Everything above this layer (hardware interfaces, controllers, the controller manager) uses these; nothing
here knows about ros2_control.
"""
