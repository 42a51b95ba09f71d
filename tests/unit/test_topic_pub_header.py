"""``%topic pub`` with ``header: auto`` and ``stamp: now``, as ``ros2 topic pub`` expands them.

Jazzy's ``ros2 topic pub`` fills the message with ``set_message_fields(..., expand_header_auto=True,
expand_time_now=True)``: ``header: auto`` is a header with an empty ``frame_id`` stamped with the publishing node's
clock, and ``now`` in a ``builtin_interfaces/Time`` field is that clock's time. Here the clock is the system's
(simulated) one.
"""

from __future__ import annotations

import pytest

import rrbot_workshop as rw
from rrbot_workshop.course.magics import topic
from rrbot_workshop.exceptions import MessageError
from rrbot_workshop.msgs import Header, JointTrajectory, TwistStamped
from rrbot_workshop.tools.message_yaml import message_from_dict


@pytest.fixture
def diffbot():
    system = rw.bringup("diffbot", "diffbot_controllers.yaml",
                        spawn=["joint_state_broadcaster", "diffbot_base_controller"])
    yield system
    system.shutdown()


def test_header_auto_is_now_with_an_empty_frame() -> None:
    msg = message_from_dict(TwistStamped, {"header": "auto", "twist": {"linear": {"x": 0.1}}}, now=2.5)
    assert msg.header == Header(stamp=2.5, frame_id="")
    assert msg.twist.linear.x == 0.1


def test_stamp_now_anywhere_a_time_is() -> None:
    msg = message_from_dict(JointTrajectory, {"header": {"stamp": "now", "frame_id": "base"},
                                              "joint_names": ["j1"]}, now=1.25)
    assert msg.header == Header(stamp=1.25, frame_id="base")


def test_without_a_clock_auto_and_now_are_refused() -> None:
    with pytest.raises(MessageError, match="header: auto"):
        message_from_dict(TwistStamped, {"header": "auto"})
    with pytest.raises(MessageError, match="'now' needs a clock"):
        message_from_dict(Header, {"stamp": "now"})


def test_auto_is_for_headers_only() -> None:
    with pytest.raises(MessageError, match="must be given as a mapping"):
        message_from_dict(TwistStamped, {"twist": "auto"}, now=1.0)


def test_a_stamped_command_with_header_auto_drives_the_base(diffbot: rw.System,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    """The diff drive drops twists older than cmd_vel_timeout (0.5 s): a twist stamped 'now' by header: auto after 2 s
    of simulated time is fresh, one stamped at 0.1 s is stale."""
    diffbot.spin(2.0)
    topic("pub /diffbot_base_controller/cmd_vel geometry_msgs/msg/TwistStamped "
          "'{header: {stamp: {sec: 0, nanosec: 100000000}}, twist: {linear: {x: 0.2}}}'")
    diffbot.spin(0.1)
    assert diffbot.latest("/diffbot_base_controller/odom").twist.twist.linear.x == pytest.approx(0.0)
    topic("pub /diffbot_base_controller/cmd_vel geometry_msgs/msg/TwistStamped "
          "'{header: auto, twist: {linear: {x: 0.2}}}'")
    out = capsys.readouterr().out
    assert "frame_id=''" in out and "Error" not in out
    sent = diffbot.latest("/diffbot_base_controller/cmd_vel")
    assert sent.header.stamp == pytest.approx(diffbot.time)
    diffbot.spin(0.3)
    assert diffbot.latest("/diffbot_base_controller/odom").twist.twist.linear.x == pytest.approx(0.2, abs=1e-6)
