"""Tests of the Recorder: interface values sampled every control cycle of a running system."""

from __future__ import annotations

import json

import numpy as np
import pytest

import rrbot_workshop as rw
from rrbot_workshop.exceptions import InterfaceNotFound
from rrbot_workshop.viz.recorder import Recorder, split_kind


@pytest.fixture
def system():
    sys_ = rw.bringup("rrbot", controllers="rrbot_controllers.yaml",
                      spawn=["joint_state_broadcaster", "forward_position_controller"])
    yield sys_
    sys_.shutdown()


def _command(system, values):
    system.publish("/forward_position_controller/commands", rw.msgs.Float64MultiArray(data=list(values)))


def test_one_sample_per_cycle_with_a_time_column(system):
    rec = Recorder(system, ["joint1/position"])
    system.spin_cycles(10)
    data = rec.data
    assert len(rec) == 10
    assert np.allclose(np.diff(data["time"]), system.period)
    assert data["joint1/position"].shape == (10,)


def test_state_and_command_interfaces_are_told_apart(system):
    rec = Recorder(system, ["joint1/position", "command:joint1/position"])
    _command(system, [0.7, 0.7])
    system.spin(0.5)
    assert rec["command:joint1/position"][-1] == pytest.approx(0.7)
    assert rec["joint1/position"][-1] == pytest.approx(0.7)  # mock hardware mirrors the command


def test_unknown_interface_raises_interface_not_found(system):
    with pytest.raises(InterfaceNotFound):
        Recorder(system, ["joint9/position"])


def test_default_records_every_state_and_command_interface(system):
    rec = Recorder(system)
    rm = system.resource_manager
    assert set(rec.names) == set(rm.state_interface_keys()) | {f"command:{n}" for n in rm.command_interface_keys()}


def test_stop_ends_sampling_and_keeps_the_data(system):
    rec = Recorder(system, ["joint1/position"])
    system.spin_cycles(3)
    rec.stop()
    system.spin_cycles(3)
    assert len(rec) == 3


def test_topics_are_recorded_with_their_arrival_time(system):
    rec = Recorder(system, ["joint1/position"], topics=["/joint_states"])
    system.spin_cycles(5)
    messages = rec.messages("/joint_states")
    assert messages and all(isinstance(m, rw.msgs.JointState) for _, m in messages)
    assert [t for t, _ in messages] == sorted(t for t, _ in messages)


def test_unrecorded_column_or_topic_raises_key_error(system):
    rec = Recorder(system, ["joint1/position"])
    with pytest.raises(KeyError, match="recorded"):
        rec["joint2/position"]
    with pytest.raises(KeyError, match="not recorded"):
        rec.messages("/nothing")


def test_to_dict_is_json_serialisable(system):
    rec = Recorder(system, ["joint1/position", "command:joint2/position"])
    system.spin_cycles(4)
    loaded = json.loads(json.dumps(rec.to_dict()))
    assert set(loaded) == {"time", "joint1/position", "command:joint2/position"}
    assert len(loaded["time"]) == 4


def test_max_samples_keeps_the_newest(system):
    rec = Recorder(system, ["joint1/position"], max_samples=5)
    everything = Recorder(system, ["joint1/position"])
    system.spin_cycles(12)
    assert len(rec) == 5
    assert np.array_equal(rec.time, everything.time[-5:])


def test_split_kind_reads_the_prefix():
    assert split_kind("command:joint1/position") == ("command", "joint1/position")
    assert split_kind("joint1/position") == (None, "joint1/position")
    assert split_kind("pid:x/y") == (None, "pid:x/y")
