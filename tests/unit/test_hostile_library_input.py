"""Hostile input to the library's entry points: one clear error or one clear log line, never a raw traceback."""

from __future__ import annotations

import pytest
from core_helpers import make_info

from rrbot_workshop.description.info import ComponentInfo, InterfaceInfo
from rrbot_workshop.exceptions import MessageError, ParameterError
from rrbot_workshop.hardware.mock import GenericSystem
from rrbot_workshop.hardware_interface.resource_manager import ResourceManager
from rrbot_workshop.middleware.params import load_controllers_yaml
from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.msgs import JointState


def test_a_gpio_command_holding_none_fails_the_read_in_one_line(caplog: pytest.LogCaptureFixture) -> None:
    info = make_info("arm", {"joint1": (["position"], ["position"])}, plugin="mock_components/GenericSystem")
    info.gpios.append(ComponentInfo(name="flange", type="gpio",
                                    command_interfaces=[InterfaceInfo("vacuum", initial_value="0.0")],
                                    state_interfaces=[InterfaceInfo("vacuum", initial_value="0.0")]))
    rm = ResourceManager(update_rate=100)
    rm.import_component(GenericSystem(), info)
    rm.claim_command_interface("flange/vacuum").set_value(None)
    with caplog.at_level("ERROR"):
        status = rm.read(0.0, 0.01)
    assert not status.ok and "not a number" in caplog.text and "Traceback" not in caplog.text


@pytest.mark.parametrize("topic", [None, 3, "", "a b", "/a//b", "/a/"])
def test_publish_on_a_topic_that_is_not_a_topic_name(topic: object) -> None:
    with pytest.raises(MessageError, match="not a valid ROS topic name"):
        TopicBus().publish(topic, JointState())  # type: ignore[arg-type]


def test_publish_none() -> None:
    with pytest.raises(MessageError, match="cannot publish None"):
        TopicBus().publish("/joint_states", None)


@pytest.mark.parametrize("source", [None, 3, b"controller_manager: {}", 1.5])
def test_controllers_yaml_of_a_wrong_type(source: object) -> None:
    with pytest.raises(ParameterError, match="must be a path, YAML text or a mapping"):
        load_controllers_yaml(source)  # type: ignore[arg-type]


@pytest.mark.parametrize(("data", "says"), [
    (b"", "is empty"), (b"\x00\x01", "binary"), (b"a: \xff\n", "not UTF-8"),
    (b"\xef\xbb\xbfcontroller_manager:\n  ros__parameters: {update_rate: 50}\n", ""),
    (b"a: " + b"[" * 5000 + b"]" * 5000, "nested too deeply"),
])
def test_controllers_file_encodings_and_sizes(data: bytes, says: str, tmp_path) -> None:  # noqa: ANN001
    path = tmp_path / "c.yaml"
    path.write_bytes(data)
    if not says:
        assert load_controllers_yaml(path).update_rate == 50  # a byte order mark is fine
        return
    with pytest.raises(ParameterError, match=says):
        load_controllers_yaml(path)
