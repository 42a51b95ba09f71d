"""What two robot descriptions are made of, compared: the graders of tasks 10 and 11 hold a learner's composed
description against the library's for the same arguments.

A description is summed up as its links, its joints (type, parent, child, origin) and its ``<ros2_control>``
components (joints, plugin, sensors, GPIOs); :func:`difference` names the first thing that differs, in a sentence.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

from rrbot_workshop.description import parse_ros2_control

__all__ = ["summary", "difference"]


def summary(urdf: str) -> dict[str, Any]:
    robot = ET.fromstring(urdf)
    joints = {}
    for joint in robot.findall("joint"):
        origin = joint.find("origin")
        xyz = [round(float(v), 6) + 0.0 for v in ((origin.get("xyz") if origin is not None else None) or "0 0 0").split()]
        rpy = [round(float(v), 6) + 0.0 for v in ((origin.get("rpy") if origin is not None else None) or "0 0 0").split()]
        joints[str(joint.get("name"))] = (joint.get("type"), joint.find("parent").get("link"),  # type: ignore[union-attr]
                                          joint.find("child").get("link"), xyz, rpy)  # type: ignore[union-attr]
    components = {tuple(sorted(j.name for j in i.joints)): (
        i.hardware_plugin_name, sorted(s.name for s in i.sensors), sorted(g.name for g in i.gpios))
        for i in parse_ros2_control(urdf)}
    return {"links": sorted(str(link.get("name")) for link in robot.findall("link")), "joints": joints,
            "components": components}


def difference(got: dict[str, Any], expected: dict[str, Any]) -> str:
    missing = sorted(set(expected["links"]) - set(got["links"]))
    extra = sorted(set(got["links"]) - set(expected["links"]))
    if missing or extra:
        return f"the links {missing} are missing and {extra} should not be there"
    for name, (kind, parent, child, xyz, rpy) in expected["joints"].items():
        mine = next((j for j in got["joints"].values() if j[2] == child), None)
        if mine is None:
            return f"no joint holds the link {child}"
        # the task places each robot's base_link but says nothing of its orientation: any rpy is right there
        turned = mine[4] != rpy and not child.endswith("base_link")
        if mine[1] != parent or mine[3] != xyz or turned or mine[0] != kind:
            return (f"{child} hangs from {mine[1]} at xyz {mine[3]} rpy {mine[4]} ({mine[0]}), expected from {parent} "
                    f"at xyz {xyz} rpy {rpy} ({kind}) (joint '{name}')")
    if len(got["components"]) != len(expected["components"]):
        return f"{len(got['components'])} hardware components, expected {len(expected['components'])}"
    for joints, (plugin, sensors, gpios) in expected["components"].items():
        mine = got["components"].get(joints)
        if mine is None:
            return f"no hardware component holds exactly the joints {list(joints)}"
        if mine[0] != plugin:
            return f"the component of {list(joints)} uses the plugin '{mine[0]}', expected '{plugin}'"
        if mine[1] != sensors or mine[2] != gpios:
            return (f"the component of {list(joints)} has sensors {mine[1]} and GPIOs {mine[2]}, expected {sensors} "
                    f"and {gpios}")
    return ""
