"""Tests of the matplotlib figures drawn from a Recorder."""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import rrbot_workshop as rw  # noqa: E402
from rrbot_workshop.viz.plots import plot_interfaces, plot_tracking, unit_of  # noqa: E402
from rrbot_workshop.viz.recorder import Recorder  # noqa: E402


@pytest.fixture(scope="module")
def recorder():
    system = rw.bringup("rrbot", controllers="rrbot_controllers.yaml",
                        spawn=["joint_state_broadcaster", "forward_position_controller"])
    rec = Recorder(system, ["joint1/position", "command:joint1/position", "joint2/position",
                            "command:joint2/position", "joint1/velocity"])
    system.publish("/forward_position_controller/commands", rw.msgs.Float64MultiArray(data=[0.7, -0.4]))
    system.spin(0.3)
    system.shutdown()
    return rec


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def test_tracking_has_values_and_error_rows_per_joint(recorder):
    fig = plot_tracking(recorder, ["joint1", "joint2"])
    axes = np.array(fig.axes).reshape(2, 2)
    assert [a.get_title() for a in axes[0]] == ["joint1", "joint2"]
    assert axes[0, 0].get_ylabel() == "position [rad]"
    assert axes[1, 0].get_ylabel() == "error [rad]"
    assert axes[1, 1].get_xlabel() == "time [s]"


def test_tracking_error_is_commanded_minus_actual(recorder):
    fig = plot_tracking(recorder, ["joint1"])
    error = fig.axes[1].lines[0].get_ydata()
    expected = recorder["command:joint1/position"] - recorder["joint1/position"]
    assert np.allclose(error, expected)


def test_tracking_accepts_a_mapping_of_columns(recorder):
    fig = plot_tracking(recorder, ["joint1"], commanded={"joint1": "command:joint1/position"},
                        actual={"joint1": "joint1/position"})
    assert len(fig.axes[0].lines) == 2


def test_tracking_without_joints_raises_value_error(recorder):
    with pytest.raises(ValueError, match="joint"):
        plot_tracking(recorder, [])


def test_tracking_of_an_unrecorded_column_raises_key_error(recorder):
    with pytest.raises(KeyError):
        plot_tracking(recorder, ["joint1"], interface="effort")


def test_interfaces_one_row_each_with_units(recorder):
    fig = plot_interfaces(recorder, ["joint1/position", "joint1/velocity"])
    assert [a.get_ylabel() for a in fig.axes] == ["[rad]", "[rad/s]"]
    assert fig.axes[-1].get_xlabel() == "time [s]"


def test_interfaces_without_names_raises_value_error(recorder):
    with pytest.raises(ValueError):
        plot_interfaces(recorder, [])


def test_units_from_interface_names():
    assert unit_of("command:joint1/effort") == "N m"
    assert unit_of("tcp_fts_sensor/force.x") == "N"
    assert unit_of("slider/position", {"position": "m"}) == "m"
    assert unit_of("gpio/digital_output") == "-"


def test_figures_are_deterministic(recorder):
    """Two drawings of the same data give the same PNG bytes (what a notebook shows; no dates in it)."""

    def png() -> bytes:
        buf = io.BytesIO()
        plot_tracking(recorder, ["joint1", "joint2"], title="tracking").savefig(buf, format="png")
        return buf.getvalue()

    assert png() == png()
