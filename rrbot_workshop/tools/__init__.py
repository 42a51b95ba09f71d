"""Tools for anybody's ROS files: lint a controllers YAML and a description, bring a robot up from a terminal, and
read and write messages as ``ros2 topic`` does.

They read the files they are given and never change them. They know nothing of the course; the course uses them.
"""
