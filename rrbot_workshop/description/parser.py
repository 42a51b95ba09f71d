"""Placeholder: the <ros2_control> parser is being written."""
from .info import HardwareInfo


def parse_ros2_control(urdf: str, source: str | None = None) -> list[HardwareInfo]:
    raise NotImplementedError
