"""Topic bus: name resolution, queued delivery, latest/history, types, services, nodes."""

from __future__ import annotations

import logging

import pytest

from rrbot_workshop.exceptions import MessageError
from rrbot_workshop.middleware.topics import Node, TopicBus, resolve_name
from rrbot_workshop.msgs import Float64, Float64MultiArray, JointState, SetBoolRequest, SetBoolResponse, String


@pytest.mark.parametrize(
    ("name", "node", "ns", "expected"),
    [("~/commands", "fwd", "/", "/fwd/commands"), ("cmd", "fwd", "/", "/cmd"), ("cmd", "n", "/robot1", "/robot1/cmd"),
     ("/abs", "n", "/robot1", "/abs"), ("~", "n", "/r", "/r/n")],
)
def test_resolve_name_like_ros2(name: str, node: str, ns: str, expected: str) -> None:
    assert resolve_name(name, node, ns) == expected


def test_resolve_name_errors() -> None:
    with pytest.raises(MessageError, match="empty"):
        resolve_name("")
    with pytest.raises(MessageError, match="no node name"):
        resolve_name("~/x")


def test_publishing_queues_until_deliver() -> None:
    bus = TopicBus()
    got: list[float] = []
    bus.create_subscription(Float64, "/x", lambda m: got.append(m.data))
    bus.publish("/x", Float64(data=1.0))
    assert got == [] and bus.latest("/x").data == 1.0
    assert bus.deliver() == 1 and got == [1.0]
    assert bus.deliver() == 0


def test_history_is_bounded_and_clearable() -> None:
    bus = TopicBus(history_depth=3)
    for k in range(5):
        bus.publish("/x", Float64(data=float(k)))
    assert [m.data for m in bus.history("/x")] == [2.0, 3.0, 4.0]
    bus.clear_history("/x")
    assert bus.history("/x") == [] and bus.latest("/x").data == 4.0


def test_topic_type_is_enforced() -> None:
    bus = TopicBus()
    pub = bus.create_publisher(Float64, "/x")
    with pytest.raises(MessageError, match="Float64"):
        bus.create_subscription(String, "/x", lambda m: None)
    with pytest.raises(MessageError, match="got String"):
        pub.publish(String(data="no"))
    with pytest.raises(MessageError, match="carries Float64"):
        bus.publish("/x", String(data="no"))


def test_failing_subscriber_is_logged_and_others_still_run(caplog: pytest.LogCaptureFixture) -> None:
    bus = TopicBus()
    got: list[str] = []

    def bad(msg: String) -> None:
        raise RuntimeError("boom")

    bus.create_subscription(String, "/s", bad, owner="bad_node")
    bus.create_subscription(String, "/s", lambda m: got.append(m.data))
    bus.publish("/s", String(data="hi"))
    with caplog.at_level(logging.ERROR):
        bus.deliver()
    assert got == ["hi"] and "bad_node" in caplog.text


def test_subscription_destroy_and_counts() -> None:
    bus = TopicBus()
    sub = bus.create_subscription(Float64, "/x", lambda m: None)
    pub = bus.create_publisher(Float64, "/x")
    assert pub.get_subscription_count() == 1 and sub.topic_name == "/x"
    sub.destroy()
    assert pub.get_subscription_count() == 0


def test_topic_names_and_types_include_externally_published_topics() -> None:
    bus = TopicBus()
    bus.create_publisher(Float64, "/typed")
    bus.publish("/free", Float64MultiArray(data=[1.0]))
    assert bus.topic_names_and_types() == [("/free", "std_msgs/msg/Float64MultiArray"), ("/typed", "std_msgs/msg/Float64")]


def test_services_call_check_type_and_refuse_duplicates() -> None:
    bus = TopicBus()
    bus.create_service("/set", lambda req: SetBoolResponse(success=req.data), SetBoolRequest)
    assert bus.call_service("/set", SetBoolRequest(data=True)).success
    with pytest.raises(MessageError, match="takes SetBoolRequest"):
        bus.call_service("/set", String())
    with pytest.raises(MessageError, match="already exists"):
        bus.create_service("/set", lambda req: None)
    with pytest.raises(MessageError, match="no service '/nope'"):
        bus.call_service("/nope", None)


def test_a_node_creating_its_service_again_replaces_it_another_node_cannot() -> None:
    """A controller configured again after a cleanup creates its service again (as C++'s reassigned pointer does)."""
    bus = TopicBus()
    node = Node("disp", bus)
    node.create_service(SetBoolRequest, "~/set_mode", lambda req: SetBoolResponse(success=False))
    node.create_service(SetBoolRequest, "~/set_mode", lambda req: SetBoolResponse(success=True))
    assert bus.service_names().count("/disp/set_mode") == 1
    assert bus.call_service("/disp/set_mode", SetBoolRequest(data=True)).success
    with pytest.raises(MessageError, match="already exists"):
        Node("other", bus).create_service(SetBoolRequest, "/disp/set_mode", lambda req: None)


def test_node_expands_names_and_destroy_removes_its_endpoints() -> None:
    bus = TopicBus()
    node = Node("fwd", bus, clock=lambda: 1.5)
    node.create_subscription(Float64, "~/commands", lambda m: None)
    node.create_service(SetBoolRequest, "~/enable", lambda r: SetBoolResponse())
    assert bus.subscription_count("/fwd/commands") == 1 and "/fwd/enable" in bus.service_names()
    assert node.now() == 1.5 and node.get_fully_qualified_name() == "/fwd"
    node.destroy()
    assert bus.subscription_count("/fwd/commands") == 0 and bus.service_names() == []


def test_every_message_class_has_its_ros_type_name() -> None:
    """Each message dataclass maps to 'pkg/msg/Name' (or 'pkg/srv/Name' for service parts) with its own name."""
    import dataclasses

    from rrbot_workshop import msgs

    for name in msgs.__all__:
        cls = getattr(msgs, name)
        if not dataclasses.is_dataclass(cls):
            continue
        pkg, kind, short = msgs.ros_type_name(cls).split("/")
        assert kind in ("msg", "srv") and pkg.endswith("_msgs") or pkg == "std_srvs", name
        assert name.startswith(short) or name == f"Lifecycle{short}", name  # lifecycle_msgs/State: LifecycleState


def test_topic_list_reports_ros_type_names() -> None:
    """topic_names_and_types gives full ROS names, as `ros2 topic list -t` prints them."""
    from rrbot_workshop.middleware.topics import TopicBus
    from rrbot_workshop.msgs import JointState

    bus = TopicBus()
    bus.create_publisher(JointState, "/joint_states")
    assert bus.topic_names_and_types() == [("/joint_states", "sensor_msgs/msg/JointState")]


def test_publishing_where_nobody_listens_warns_once_with_the_close_name(caplog: pytest.LogCaptureFixture) -> None:
    bus = TopicBus()
    bus.create_subscription(Float64MultiArray, "/forward_position_controller/commands", lambda m: None, owner="fwd")
    with caplog.at_level(logging.WARNING, logger="rrbot_workshop.middleware.topics"):
        bus.publish("/forward_position_controler/commands", Float64MultiArray(data=[0.7]))
        bus.publish("/forward_position_controler/commands", Float64MultiArray(data=[0.8]))
        bus.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.9]))
    warnings = [r.getMessage() for r in caplog.records]
    assert warnings == [
        "no subscriber on '/forward_position_controler/commands'; did you mean '/forward_position_controller/commands'?"
    ]
    assert bus.latest("/forward_position_controler/commands").data == [0.8]  # still kept as its latest


def test_no_subscriber_warning_without_a_close_name(caplog: pytest.LogCaptureFixture) -> None:
    bus = TopicBus()
    with caplog.at_level(logging.WARNING, logger="rrbot_workshop.middleware.topics"):
        bus.publish("/lonely", Float64MultiArray(data=[1.0]))
    assert [r.getMessage() for r in caplog.records] == [
        "no subscriber on '/lonely' (the message is kept as its latest; nobody receives it)"
    ]


def test_publisher_and_subscription_owners() -> None:
    bus = TopicBus()
    bus.create_publisher(JointState, "/joint_states", owner="joint_state_broadcaster")
    bus.create_subscription(JointState, "/joint_states", lambda m: None, owner="viewer")
    assert (bus.publisher_count("/joint_states"), bus.subscription_count("/joint_states")) == (1, 1)
    assert bus.publisher_owners("/joint_states") == ["joint_state_broadcaster"]
    assert bus.subscription_owners("/joint_states") == ["viewer"]
    assert bus.topic_type_name("/joint_states") == "sensor_msgs/msg/JointState"
    assert bus.topic_type_name("/nope") is None
    assert bus.similar_topics("/joint_state") == ["/joint_states"]
