"""Malformed descriptions, generated: every one ends in a clear library error or is a description ros2_control
accepts too; none ends in a raw traceback, and the kinds that are always invalid are always rejected.

400 seeded mutations of the course's RRBot URDF (processed xacro) go through the whole path a learner's file takes:
URDF model, ``<ros2_control>`` parser, and a bringup on the mock hardware.
"""

from __future__ import annotations

import logging
import random
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

import rrbot_workshop as rw
from rrbot_workshop.description import process_xacro
from rrbot_workshop.exceptions import RRBotWorkshopError

CASES = 400
SEED = 20261124


RRBOT_XACRO = Path(__file__).resolve().parents[2] / "descriptions" / "rrbot" / "urdf" / "rrbot.urdf.xacro"


@pytest.fixture(scope="module")
def urdf() -> str:
    return process_xacro(RRBOT_XACRO)


@pytest.fixture(autouse=True)
def _quiet() -> Iterator[None]:
    logging.disable(logging.CRITICAL)
    yield
    logging.disable(logging.NOTSET)


# mutation kind -> (mutation, always invalid?)
Mutation = Callable[[ET.Element, random.Random], bool]


def _pick(root: ET.Element, rng: random.Random, path: str, attribute: str | None = None) -> ET.Element | None:
    found = [e for e in root.iter() if e.tag == path and (attribute is None or attribute in e.attrib)]
    return rng.choice(found) if found else None


def _set_number(values: list[str], tags: list[tuple[str, str]]) -> Mutation:
    def mutate(root: ET.Element, rng: random.Random) -> bool:
        tag, attribute = rng.choice(tags)
        element = _pick(root, rng, tag, attribute)
        if element is None:
            return False
        old = element.get(attribute, "").split()
        if len(old) > 1:  # a vector: spoil one component
            old[rng.randrange(len(old))] = rng.choice(values)
            element.set(attribute, " ".join(old))
        else:
            element.set(attribute, rng.choice(values))
        return True

    return mutate


def _swap_limits(root: ET.Element, rng: random.Random) -> bool:
    limit = _pick(root, rng, "limit", "lower")
    if limit is None:
        return False
    limit.set("lower", "2.0")
    limit.set("upper", "-2.0")
    return True


def _duplicate(tag: str) -> Mutation:
    def mutate(root: ET.Element, rng: random.Random) -> bool:
        for parent in root.iter():
            kids = [c for c in parent if c.tag == tag]
            if kids:
                parent.append(ET.fromstring(ET.tostring(rng.choice(kids))))
                return True
        return False

    return mutate


def _drop_attribute(tags: list[tuple[str, str]]) -> Mutation:
    def mutate(root: ET.Element, rng: random.Random) -> bool:
        tag, attribute = rng.choice(tags)
        element = _pick(root, rng, tag, attribute)
        if element is None:
            return False
        del element.attrib[attribute]
        return True

    return mutate


def _drop_child(tags: list[str]) -> Mutation:
    def mutate(root: ET.Element, rng: random.Random) -> bool:
        tag = rng.choice(tags)
        for parent in root.iter():
            for child in list(parent):
                if child.tag == tag:
                    parent.remove(child)
                    return True
        return False

    return mutate


def _rename_reference(root: ET.Element, rng: random.Random) -> bool:
    element = _pick(root, rng, rng.choice(["parent", "child"]), "link")
    if element is None:
        return False
    element.set("link", element.get("link", "") + "_typo")
    return True


def _unknown_tag(root: ET.Element, rng: random.Random) -> bool:
    block = _pick(root, rng, "ros2_control")
    if block is None:
        return False
    ET.SubElement(block, rng.choice(["joints", "sensors", "hardwares", "Joint"]), name="x")
    return True


MUTATIONS: dict[str, tuple[Mutation, bool]] = {
    "non-finite number": (_set_number(["nan", "inf", "-inf"], [("origin", "xyz"), ("origin", "rpy"), ("limit", "lower"),
                                                             ("limit", "upper"), ("mass", "value"), ("inertia", "ixx")]),
                          True),
    "text for a number": (_set_number(["abc", "", "1,5"], [("origin", "xyz"), ("limit", "velocity"), ("mass", "value"),
                                                          ("inertia", "izz"), ("box", "size"), ("cylinder", "radius")]),
                          True),
    "non-positive mass or inertia": (_set_number(["0", "-1"], [("mass", "value"), ("inertia", "ixx"),
                                                              ("inertia", "iyy"), ("inertia", "izz")]), True),
    "lower above upper": (_swap_limits, True),
    "duplicate joint in a ros2_control block": (_duplicate("joint"), True),
    "duplicate interface": (_duplicate("command_interface"), True),
    "duplicate link": (_duplicate("link"), True),
    "missing name": (_drop_attribute([("joint", "name"), ("link", "name"), ("ros2_control", "name"),
                                      ("command_interface", "name"), ("state_interface", "name")]), True),
    "missing plugin or hardware": (_drop_child(["plugin", "hardware"]), True),
    "dangling link reference": (_rename_reference, True),
    "unknown tag in ros2_control": (_unknown_tag, True),
    "missing joint type or axis": (_drop_attribute([("joint", "type"), ("axis", "xyz")]), False),
}


def _try(text: str) -> str:
    """'accepted', 'rejected' (a library error), or the raw exception's type."""
    try:
        with rw.bringup(text, name="malformed_case") as system:
            system.spin(0.02)
    except RRBotWorkshopError:
        return "rejected"
    except Exception as exc:  # noqa: BLE001 - that is what this test looks for
        return f"raw {type(exc).__name__}: {exc}"
    return "accepted"


def test_generated_malformed_descriptions_end_in_a_clear_error_and_never_in_a_raw_traceback(urdf: str) -> None:
    rng = random.Random(SEED)
    kinds = sorted(MUTATIONS)
    raw: list[str] = []
    silent: list[str] = []
    tried = 0
    while tried < CASES:
        kind = kinds[tried % len(kinds)]
        mutate, invalid = MUTATIONS[kind]
        root = ET.fromstring(urdf)
        if not mutate(root, rng):
            continue
        tried += 1
        text = ET.tostring(root, encoding="unicode")
        outcome = _try(text)
        if outcome.startswith("raw"):
            raw.append(f"{kind}: {outcome}")
        elif outcome == "accepted" and invalid:
            silent.append(kind)
    assert not raw, f"{len(raw)} of {tried} ended in a raw traceback, e.g. {raw[:3]}"
    assert not silent, f"{len(silent)} of {tried} invalid descriptions were accepted: {sorted(set(silent))}"
