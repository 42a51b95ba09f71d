"""Task 10: the original workshop's questions about RRBot on DiffBot, answered as numbers.

Each answer is checked against a running system built from your description.
"""

# TODO(task 10.3): replace each None with a number. Count from what your description declares, then check it in
#   notebook 10 with %control list_hardware_components.

#: How many hardware components does the controller manager load for RRBot on DiffBot?
HARDWARE_COMPONENTS = None

#: How many hardware plugins does each <ros2_control> tag name (in simulation: how many MujocoSystem per tag)?
PLUGINS_PER_ROS2_CONTROL_TAG = None

#: How many controller managers run the two robots?
CONTROLLER_MANAGERS = None
