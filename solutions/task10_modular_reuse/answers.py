"""Task 10: the original workshop's questions about RRBot on DiffBot, answered as numbers.

Each answer is checked against a running system built from your description.
"""

#: How many hardware components does the controller manager load for RRBot on DiffBot?
HARDWARE_COMPONENTS = 2

#: How many hardware plugins does each <ros2_control> tag name (in simulation: how many MujocoSystem per tag)?
PLUGINS_PER_ROS2_CONTROL_TAG = 1

#: How many controller managers run the two robots?
CONTROLLER_MANAGERS = 1
