"""Fuzz tests (Hypothesis, derandomized and bounded): files, YAML, names, messages, API argument types and CLI
arguments. Each case ends in success or in the package's own exception (``RRBotWorkshopError``), never in a raw
exception or a hang; the CLI always returns 0, 1 or 2 and prints no traceback."""

from __future__ import annotations

import logging
import math
from typing import Any

import pytest
import yaml
from core_helpers import load_configure, make_cm
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rrbot_workshop import cli
from rrbot_workshop.control_toolbox.pid import Pid
from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.middleware.names import node_name_problem
from rrbot_workshop.middleware.params import load_controllers_yaml
from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.msgs import Float64MultiArray, JointState, JointTrajectory, JointTrajectoryPoint
from rrbot_workshop.tools.lint import lint_controllers

FUZZ = settings(derandomize=True, max_examples=40, deadline=None, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


@pytest.fixture(autouse=True)
def _quiet() -> Any:
    logging.disable(logging.CRITICAL)
    yield
    logging.disable(logging.NOTSET)


# ----------------------------------------------------------------------------------------------------- values
scalars = st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(allow_nan=True),
                    st.text(max_size=12), st.binary(max_size=8))
values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                        st.dictionaries(st.text(max_size=8), inner, max_size=4)),
                      max_leaves=12)
yaml_docs = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-1000, 1000), st.floats(allow_nan=False), st.text(max_size=10)),
    lambda inner: st.one_of(st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=10), inner, max_size=3)),
    max_leaves=15,
)
controller_docs = st.fixed_dictionaries({
    "controller_manager": st.fixed_dictionaries({"ros__parameters": st.dictionaries(
        st.sampled_from(["update_rate", "fwd", "jsb", "pid", "handle_exceptions", "x y"]),
        st.one_of(yaml_docs, st.fixed_dictionaries({"type": st.one_of(st.text(max_size=20), st.sampled_from([
            "forward_command_controller/ForwardCommandController",
            "joint_state_broadcaster/JointStateBroadcaster", "pid_controller/PidController"]))})),
        max_size=4)}),
}).flatmap(lambda doc: st.dictionaries(st.sampled_from(["fwd", "jsb", "pid", "/**"]),
                                       st.fixed_dictionaries({"ros__parameters": yaml_docs}), max_size=3)
           .map(lambda extra: {**doc, **extra}))


def _project_error_or_none(fn: Any, *args: Any, **kwargs: Any) -> Any:
    try:
        return fn(*args, **kwargs)
    except RRBotWorkshopError:
        return None


# ----------------------------------------------------------------------------------------------------- files
@FUZZ
@given(data=st.binary(max_size=400))
def test_any_bytes_as_a_controllers_file(data: bytes, tmp_path_factory: pytest.TempPathFactory) -> None:
    path = tmp_path_factory.mktemp("fuzz") / "controllers.yaml"
    path.write_bytes(data)
    _project_error_or_none(load_controllers_yaml, path)
    findings = lint_controllers(path)
    assert all(f.level in ("error", "warning", "note") for f in findings)


# ----------------------------------------------------------------------------------------------------- YAML
@FUZZ
@given(doc=st.one_of(yaml_docs, controller_docs))
def test_any_yaml_document_as_controllers(doc: Any, tmp_path_factory: pytest.TempPathFactory) -> None:
    text = yaml.safe_dump(doc)
    _project_error_or_none(load_controllers_yaml, text + "\n")
    path = tmp_path_factory.mktemp("fuzz") / "c.yaml"
    path.write_text(text)
    lint_controllers(path)


@FUZZ
@given(depth=st.integers(1, 3000), flow=st.booleans())
def test_deep_yaml_is_refused_clearly(depth: int, flow: bool) -> None:
    text = "a: " + "[" * depth + "]" * depth if flow else "a:\n" + "".join(" " * k + "- \n" for k in range(1, 60))
    _project_error_or_none(load_controllers_yaml, text + "\n")


# ----------------------------------------------------------------------------------------------------- names
@FUZZ
@given(name=st.one_of(st.text(max_size=40), st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,20}", fullmatch=True),
                      scalars))
def test_any_controller_name_is_loaded_only_if_it_is_a_node_name(name: Any) -> None:
    cm = make_cm({})
    loaded = _project_error_or_none(cm.load_controller, name, "test_controller/TestController")
    assert (loaded is not None) == (node_name_problem(name) == "")
    assert list(cm.controllers) == ([name] if loaded is not None else [])


# ----------------------------------------------------------------------------------------------------- messages
message_like = st.one_of(
    values,
    st.builds(Float64MultiArray, data=st.one_of(st.lists(st.floats(), max_size=4), values)),
    st.builds(JointState, name=st.one_of(st.lists(st.text(max_size=6), max_size=3), values),
              position=st.one_of(st.lists(st.floats(), max_size=3), values)),
    st.builds(JointTrajectory, joint_names=st.one_of(st.lists(st.sampled_from(["joint1", "joint2", "x"]), max_size=3),
                                                     values),
              points=st.one_of(st.lists(st.builds(JointTrajectoryPoint, positions=st.one_of(
                  st.lists(st.floats(), max_size=3), values), time_from_start=st.one_of(st.floats(), values)),
                  max_size=3), values)),
)


@pytest.fixture(scope="module")
def running():  # noqa: ANN201
    import rrbot_workshop as rw

    system = rw.bringup(description="rrbot", controllers="rrbot_controllers.yaml",
                        spawn=["joint_state_broadcaster", "forward_position_controller"])
    yield system
    system.shutdown()


@FUZZ
@given(topic=st.sampled_from(["/forward_position_controller/commands", "/joint_trajectory_controller/joint_trajectory",
                              "/joint_states", None, "", "a b", 3]), msg=message_like)
def test_any_message_to_a_running_system(running: Any, topic: Any, msg: Any) -> None:
    try:
        running.bus.publish(topic, msg)
    except RRBotWorkshopError:
        return
    running.spin_cycles(2)  # callbacks and cycles run; nothing escapes
    cm = running.controller_manager
    assert cm.controllers["forward_position_controller"].state.label == "active"


# ----------------------------------------------------------------------------------------------------- API types
@FUZZ
@given(activate=values, deactivate=values, strictness=values)
def test_switch_controllers_with_any_argument_types(activate: Any, deactivate: Any, strictness: Any) -> None:
    cm = make_cm({"a": {"command_interfaces": ["joint1/position"]}})
    load_configure(cm, "a")
    _project_error_or_none(cm.switch_controllers, activate=activate, deactivate=deactivate, strictness=strictness)
    _project_error_or_none(cm.explain_switch, activate=activate, deactivate=deactivate, strictness=strictness)


@FUZZ
@given(name=values, state=values)
def test_lifecycle_requests_with_any_argument_types(name: Any, state: Any) -> None:
    cm = make_cm({"a": {"command_interfaces": ["joint1/position"]}})
    load_configure(cm, "a")
    for call, args in ((cm.set_controller_state, (name, state)), (cm.configure_controller, (name,)),
                       (cm.cleanup_controller, (name,)), (cm.unload_controller, (name,)),
                       (cm.get_controller, (name,)), (cm.load_controller, (name, state))):
        _project_error_or_none(call, *args)


@FUZZ
@given(gains=st.lists(values, max_size=4))
def test_pid_with_any_gains(gains: list[Any]) -> None:
    pid = _project_error_or_none(Pid, *gains)
    if pid is None:
        return
    assert pid.set_gains(*gains) in (True, False)
    out = pid.compute_command(1.0, 0.01)
    assert isinstance(out, float) or math.isnan(out)


@FUZZ
@given(topic=values, msg=values)
def test_publish_with_any_argument_types(topic: Any, msg: Any) -> None:
    _project_error_or_none(TopicBus().publish, topic, msg)


# ----------------------------------------------------------------------------------------------------- CLI
argument = st.one_of(st.text(max_size=20), st.sampled_from(["-1", "0", "nan", "inf", "-inf", "/", "", "\n", "x.yaml"]))


@FUZZ
@given(argv=st.one_of(
    st.tuples(st.just("lint"), argument, st.sampled_from(["--xacro-arg", "--description"]), argument),
    st.tuples(st.just("grade"), argument, st.just("--timeout"), st.sampled_from(["-1", "0", "nan", "inf", "-inf",
                                                                                  "x", ""])),
    st.tuples(st.just("progress"), st.just("--root"), st.sampled_from(["/nonexistent/rr", "/", "", "/etc/hostname"])),
    st.lists(argument, max_size=3).map(tuple),
))
def test_cli_with_any_arguments(argv: tuple[str, ...], capsys: pytest.CaptureFixture[str],
                                tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path_factory.mktemp("cli"))
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    assert code in (0, 1, 2) and "Traceback" not in out + err
    if code == 2 and err.strip():
        assert len(err.strip().splitlines()) <= 2  # argparse's --help is on stdout; errors are one line
