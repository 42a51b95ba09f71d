"""What two robot descriptions are made of, compared: the graders of tasks 10 and 11 hold a learner's composed
description against the library's for the same arguments.

A description is summed up as its links, its joints (type, parent, child, origin) and its ``<ros2_control>``
components (joints, plugin, sensors, GPIOs); :func:`difference` names the first thing that differs, in a sentence, and
:func:`first_difference` searches generated xacro arguments for the smallest set under which the two differ.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from rrbot_workshop.course.learner import shown
from rrbot_workshop.description import parse_ros2_control, process_xacro
from rrbot_workshop.exceptions import RRBotWorkshopError

__all__ = ["summary", "difference", "first_difference", "arguments", "as_shown"]

#: Hypothesis's phases without "explain", which would run the learner's xacro again for minutes on a failure.
NO_EXPLAIN = (Phase.explicit, Phase.generate, Phase.shrink)


def arguments(**args: Any) -> str:
    """xacro arguments as a learner writes them: ``prefix:=left_ use_mock_hardware:=false``."""
    return " ".join(f"{k}:={str(v).lower() if isinstance(v, bool) else v}" for k, v in args.items()) or "its defaults"


def as_shown(text: str, path: Path) -> str:
    """``text`` with the learner's absolute path written as the learner knows it."""
    return text.replace(str(path), shown(path))


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


def first_difference(description: Path, reference: Path, scenario: st.SearchStrategy[dict[str, Any]]) -> str:
    """The smallest generated set of xacro arguments (from ``scenario``, seeded, 8 examples) under which the
    learner's ``description`` and the ``reference`` differ, as a sentence naming the learner's file; ``""`` if none."""
    failing: list[dict[str, Any]] = []
    seen: dict[tuple[Any, ...], str] = {}  # scenario -> difference ("" when none): shrinking revisits scenarios

    def differs(args: dict[str, Any]) -> str:
        key = tuple(sorted(args.items()))
        if key not in seen:
            expected = summary(process_xacro(reference, **args))
            try:
                seen[key] = difference(summary(process_xacro(description, **args)), expected)
            except RRBotWorkshopError as exc:
                seen[key] = f"it is refused: {as_shown(str(exc), description)}"
        return seen[key]

    @settings(derandomize=True, database=None, deadline=None, max_examples=8,
              suppress_health_check=list(HealthCheck), phases=NO_EXPLAIN, report_multiple_bugs=False)
    @given(scenario)
    def compare(args: dict[str, Any]) -> None:
        found = differs(args)
        if found:
            failing.append(args)
            raise AssertionError(found)

    try:
        compare()
    except AssertionError as exc:
        # Hypothesis replays the smallest failing scenario last: its arguments are the last ones recorded.
        given_args = arguments(**failing[-1]) if failing else "some arguments"
        return f"your {description.name} with {given_args}: {exc.args[0] if exc.args else exc}."
    return ""
