"""Tests for force_torque_sensor_broadcaster."""

from __future__ import annotations

import logging
import math

import pytest

from rrbot_workshop.controllers.force_torque_sensor_broadcaster import ForceTorqueSensorBroadcaster
from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware import plugins
from rrbot_workshop.middleware.lifecycle import State
from rrbot_workshop.msgs import WrenchStamped
from rrbot_workshop.testing import ControllerHarness

FTS = {f"tcp_fts_sensor/{g}.{a}": v for (g, a), v in zip(
    [(g, a) for g in ("force", "torque") for a in "xyz"], [1.1, 2.2, 3.3, 4.4, 5.5, 6.6], strict=True)}


def _harness(params, states=FTS) -> ControllerHarness:
    return ControllerHarness(ForceTorqueSensorBroadcaster(), "fts_broadcaster", params, state_values=states)


def _run(params, states=FTS) -> ControllerHarness:
    h = _harness(params, states)
    assert h.configure() is State.INACTIVE
    assert h.activate() is State.ACTIVE
    h.update()
    return h


def test_sensor_name_publishes_all_six_axes():
    h = _run({"sensor_name": "tcp_fts_sensor", "frame_id": "tool0"})
    msg = h.latest("~/wrench")
    assert isinstance(msg, WrenchStamped)
    w = msg.wrench
    assert (w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z) == (1.1, 2.2, 3.3, 4.4, 5.5, 6.6)
    assert msg.header.frame_id == "tool0" and msg.header.stamp == pytest.approx(0.01)


def test_sensor_name_interface_names_and_order():
    h = _harness({"sensor_name": "tcp_fts_sensor", "frame_id": "tool0"})
    h.configure()
    assert h.controller.state_interface_configuration().names == list(FTS)


def test_individual_interface_names_missing_axes_are_nan():
    params = {"frame_id": "tool0", "interface_names": {"force": {"x": "tcp_fts_sensor/force.x"},
                                                       "torque": {"z": "tcp_fts_sensor/torque.z"}}}
    h = _run(params)
    assert h.controller.state_interface_configuration().names == ["tcp_fts_sensor/force.x", "tcp_fts_sensor/torque.z"]
    w = h.latest("~/wrench").wrench
    assert w.force.x == 1.1 and w.torque.z == 6.6
    assert all(math.isnan(v) for v in (w.force.y, w.force.z, w.torque.x, w.torque.y))


def test_values_follow_the_sensor():
    h = _run({"sensor_name": "tcp_fts_sensor", "frame_id": "tool0"})
    h.set("tcp_fts_sensor/force.z", -9.81)
    h.update()
    assert h.latest("~/wrench").wrench.force.z == -9.81


def test_neither_sensor_name_nor_interfaces_fails_configure(caplog):
    h = _harness({"frame_id": "tool0"})
    with caplog.at_level(logging.ERROR):
        assert h.configure() is State.UNCONFIGURED
    assert "'sensor_name' or at least one" in caplog.text


def test_both_sensor_name_and_interfaces_fails_configure(caplog):
    h = _harness({"frame_id": "tool0", "sensor_name": "s", "interface_names": {"force": {"x": "s/force.x"}}})
    with caplog.at_level(logging.ERROR):
        assert h.configure() is State.UNCONFIGURED
    assert "cannot be used together" in caplog.text


def test_missing_frame_id_rejected_at_load():
    with pytest.raises(ParameterError, match="'frame_id'.*must not be empty"):
        _harness({"sensor_name": "tcp_fts_sensor"})


def test_plugin_name_resolves():
    assert plugins.resolve("controller", "force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster") \
        is ForceTorqueSensorBroadcaster


def test_offset_then_multiplier_correct_each_axis_in_the_message_and_the_exports():
    """Jazzy's offset.* and multiplier.* parameters: published = (measured + offset) * multiplier, per axis."""
    params = {"sensor_name": "tcp_fts_sensor", "frame_id": "tool0",
              "offset": {"force": {"x": -1.1, "z": 0.7}, "torque": {"y": 0.5}},
              "multiplier": {"force": {"z": 2.0}, "torque": {"x": -1.0, "y": 10.0}}}
    h = _run(params)
    w = h.latest("~/wrench").wrench
    got = [w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z]
    assert got == pytest.approx([0.0, 2.2, (3.3 + 0.7) * 2.0, -4.4, (5.5 + 0.5) * 10.0, 6.6])
    exported = [f"fts_broadcaster/tcp_fts_sensor/{g}.{a}" for g in ("force", "torque") for a in "xyz"]
    assert h.values(exported) == pytest.approx(got)


def test_the_broadcaster_is_chainable_and_exports_six_state_interfaces_but_no_references():
    """ros2_controllers force_torque_sensor_broadcaster/test/test_force_torque_sensor_broadcaster.cpp,
    SensorName_Publish_Success_with_Multipliers (jazzy): with sensor_name the exports are
    <controller>/<sensor_name>/force.x ... torque.z, carrying the corrected values."""
    h = _run({"sensor_name": "tcp_fts_sensor", "frame_id": "tool0", "multiplier": {"force": {"x": 2.0}}})
    c = h.controller
    assert c.is_chainable()
    names = [f"fts_broadcaster/tcp_fts_sensor/{g}.{a}" for g in ("force", "torque") for a in "xyz"]
    assert [i.name for i in c.exported_state_interfaces] == names
    assert h.values(names) == pytest.approx([2.2, 2.2, 3.3, 4.4, 5.5, 6.6])
    assert c.reference_interfaces == []


def test_interface_names_export_only_the_configured_axes():
    """ros2_controllers force_torque_sensor_broadcaster/test/test_force_torque_sensor_broadcaster.cpp,
    InterfaceNames_Publish_Success (jazzy): two configured axes, two exports named <controller>/<interface>."""
    params = {"frame_id": "tool0", "interface_names": {"force": {"x": "tcp_fts_sensor/force.x"},
                                                       "torque": {"z": "tcp_fts_sensor/torque.z"}}}
    h = _run(params)
    exported = h.controller.exported_state_interfaces
    assert [i.name for i in exported] == ["fts_broadcaster/tcp_fts_sensor/force.x",
                                          "fts_broadcaster/tcp_fts_sensor/torque.z"]
    assert [i.prefix_name for i in exported] == ["fts_broadcaster", "fts_broadcaster"]
    assert [i.get_value() for i in exported] == [1.1, 6.6]


def test_a_non_number_offset_is_rejected_at_load():
    with pytest.raises(ParameterError, match="offset.force.x"):
        _harness({"sensor_name": "tcp_fts_sensor", "frame_id": "tool0", "offset": {"force": {"x": "a lot"}}})
