"""``rrbot-workshop lint`` on every controllers YAML of ros2_control_demos (jazzy), as its launch file uses it.

Each file is linted once per controller manager its launch file starts: in that manager's namespace, against the
description that manager's ``robot_state_publisher`` gets, with the arguments the launch file passes (their
defaults). The launch files install ``description/urdf/`` as ``share/<package>/urdf/``, so the source file is used.
Example 15's two-robot launch starts ``/rrbot_1/controller_manager`` on example 1's RRBot and
``/rrbot_2/controller_manager`` on example 5's, both from one YAML: each is checked against its own robot.

Lint may say only what Jazzy does with the file: :data:`EXPECTED` lists every finding, each with the reason it is
true. The demos come from ``shared/upstream`` through the ``ros2_control_demos`` fixture (``tests/unit/conftest.py``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from rrbot_workshop.cli import main
from rrbot_workshop.tools.lint import Finding, lint_controllers

#: One controller manager of a launch file: (namespace or None for the root, description, launch arguments).
Run = tuple[str | None, str, dict[str, str]]

#: The defaults the RRBot launch files of examples 3 to 6 pass to xacro.
_RRBOT = {"prefix": "", "use_mock_hardware": "false", "mock_sensor_commands": "false", "slowdown": "50.0"}
#: What example 15's multi_controller_manager_example_two_rrbots.launch.py passes to each rrbot_base.launch.py.
_TWO_RRBOTS = {"use_gazebo": "false", "use_mock_hardware": "false", "mock_sensor_commands": "false", "slowdown": "50.0"}

#: Controllers YAML -> the managers its launch files start with it (launch file named in the comment).
RUNS: dict[str, list[Run]] = {
    # rrbot.launch.py: joint_prefix (default "joint") is substituted in the YAML (ParameterFile, allow_substs)
    "example_1/bringup/config/rrbot_controllers.yaml":
        [(None, "example_1/description/urdf/rrbot.urdf.xacro", {"joint_prefix": "joint"})],
    # test_rrbot_launch.py spawns it into rrbot.launch.py's manager
    "example_1/bringup/config/rrbot_jtc.yaml": [(None, "example_1/description/urdf/rrbot.urdf.xacro", {})],
    "example_2/bringup/config/diffbot_controllers.yaml":
        [(None, "example_2/description/urdf/diffbot.urdf.xacro", {"use_mock_hardware": "false"})],
    "example_3/bringup/config/rrbot_multi_interface_forward_controllers.yaml":
        [(None, "example_3/description/urdf/rrbot_system_multi_interface.urdf.xacro", _RRBOT)],
    "example_4/bringup/config/rrbot_with_sensor_controllers.yaml":
        [(None, "example_4/description/urdf/rrbot_system_with_sensor.urdf.xacro", _RRBOT)],
    "example_5/bringup/config/rrbot_with_external_sensor_controllers.yaml":
        [(None, "example_5/description/urdf/rrbot_system_with_external_sensor.urdf.xacro", _RRBOT)],
    "example_6/bringup/config/rrbot_modular_actuators.yaml":
        [(None, "example_6/description/urdf/rrbot_modular_actuators.urdf.xacro", _RRBOT)],
    "example_7/bringup/config/r6bot_controller.yaml": [(None, "example_7/description/urdf/r6bot.urdf.xacro", {})],
    "example_8/bringup/config/rrbot_controllers.yaml":
        [(None, "example_8/description/urdf/rrbot_transmissions_system_position_only.urdf.xacro",
          {"prefix": "", "slowdown": "50.0"})],
    "example_9/bringup/config/rrbot_controllers.yaml": [(None, "example_9/description/urdf/rrbot.urdf.xacro", {})],
    "example_10/bringup/config/rrbot_controllers.yaml":
        [(None, "example_10/description/urdf/rrbot.urdf.xacro", {"use_mock_hardware": "false"})],
    "example_11/bringup/config/carlikebot_controllers.yaml":
        [(None, "example_11/description/urdf/carlikebot.urdf.xacro", {})],
    "example_12/bringup/config/rrbot_chained_controllers.yaml":
        [(None, "example_12/description/urdf/rrbot.urdf.xacro", {})],
    "example_13/bringup/config/three_robots_controllers.yaml":
        [(None, "example_13/description/urdf/three_robots.urdf.xacro", {"slowdown": "50.0"})],
    "example_14/bringup/config/rrbot_modular_actuators_without_feedback_sensors_for_position_feedback.yaml":
        [(None, "example_14/description/urdf/"
                "rrbot_modular_actuators_without_feedback_sensors_for_position_feedback.urdf.xacro",
          {"prefix": "", "slowdown": "50.0"})],
    # rrbot_namespace.launch.py: ros2_control_node in /rrbot, example 1's RRBot
    "example_15/bringup/config/rrbot_namespace_controllers.yaml":
        [("/rrbot", "example_1/description/urdf/rrbot.urdf.xacro", {})],
    # multi_controller_manager_example_two_rrbots.launch.py: rrbot_base.launch.py twice
    "example_15/bringup/config/multi_controller_manager_rrbot_generic_controllers.yaml": [
        ("/rrbot_1", "example_1/description/urdf/rrbot.urdf.xacro", {**_TWO_RRBOTS, "prefix": "rrbot_1_"}),
        ("/rrbot_2", "example_5/description/urdf/rrbot_system_with_external_sensor.urdf.xacro",
         {**_TWO_RRBOTS, "prefix": "rrbot_2_"}),
    ],
    "example_16/bringup/config/diffbot_chained_controllers.yaml":
        [(None, "example_16/description/urdf/diffbot.urdf.xacro", {"use_mock_hardware": "false"})],
    # rrbot.launch.xml
    "example_17/bringup/config/rrbot_controllers.yaml": [(None, "example_17/description/urdf/rrbot.urdf.xacro", {})],
}

#: YAML files of other nodes (the test publishers, the wrench transformer): no controller manager reads them.
OTHER_NODES = {
    *(f"example_{n}/bringup/config/rrbot_forward_position_publisher.yaml" for n in (1, 3, 4, 5, 6, 8, 9, 10, 17)),
    "example_1/bringup/config/rrbot_joint_trajectory_publisher.yaml",
    "example_5/bringup/config/wrench_transformer_params.yaml",
    "example_13/bringup/config/three_robots_position_command_publishers.yaml",
    "example_15/bringup/config/multi_controller_manager_forward_position_publisher.yaml",
    "example_15/bringup/config/multi_controller_manager_joint_trajectory_publisher.yaml",
    "example_15/bringup/config/rrbot_namespace_forward_position_publisher.yaml",
    "example_15/bringup/config/rrbot_namespace_joint_trajectory_publisher.yaml",
}

_STATE_PUBLISH_RATE = ("Jazzy's joint_trajectory_controller declares no state_publish_rate (removed before Jazzy): "
                       "the node takes the override and nothing reads it")
_MIN_ACCELERATION = "diff_drive_controller declares angular.z.min_acceleration deprecated, and does not use it"
_FEEDFORWARD = ("pid_controller applies feedforward_gain only in feed-forward mode, off unless enable_feedforward "
                "is true; the launch file does not call ~/set_feedforward_control")

#: (YAML, namespace) -> {(level, where): why it is true of Jazzy}. Everything else lint says would be false.
EXPECTED: dict[tuple[str, str | None], dict[tuple[str, str], str]] = {
    ("example_2/bringup/config/diffbot_controllers.yaml", None): {
        ("note", "diffbot_base_controller.angular.z.min_acceleration"): _MIN_ACCELERATION},
    ("example_7/bringup/config/r6bot_controller.yaml", None): {
        ("note", "r6bot_controller.type"): "the example's own C++ controller: Jazzy loads it, the library cannot"},
    ("example_15/bringup/config/rrbot_namespace_controllers.yaml", "/rrbot"): {
        ("warning", "/rrbot/position_trajectory_controller.state_publish_rate"): _STATE_PUBLISH_RATE},
    **{("example_15/bringup/config/multi_controller_manager_rrbot_generic_controllers.yaml", ns): {
        ("warning", "/**/position_trajectory_controller.state_publish_rate"): _STATE_PUBLISH_RATE}
       for ns in ("/rrbot_1", "/rrbot_2")},
    ("example_16/bringup/config/diffbot_chained_controllers.yaml", None): {
        ("note", "diffbot_base_controller.angular.z.min_acceleration"): _MIN_ACCELERATION,
        ("warning", "pid_controller_left_wheel_joint.gains.left_wheel_joint.feedforward_gain"): _FEEDFORWARD,
        ("warning", "pid_controller_right_wheel_joint.gains.right_wheel_joint.feedforward_gain"): _FEEDFORWARD},
}

EX15 = "example_15/bringup/config/multi_controller_manager_rrbot_generic_controllers.yaml"


def _lint(demos: Path, yaml_file: str, run: Run) -> list[Finding]:
    """Lint as the CLI's ``--arg`` does: each launch argument reaches the YAML's $(var) and the xacro."""
    namespace, description, args = run
    return lint_controllers(demos / yaml_file, demos / description, args, launch_args=args, package_path=[demos],
                            namespace=namespace)


def _said(findings: list[Finding]) -> set[tuple[str, str]]:
    return {(f.level, f.where) for f in findings}


def test_every_yaml_of_the_demos_is_linted_here(ros2_control_demos: Path) -> None:
    """The table covers each config YAML of the tree: a new file in the demos must be added with its launch file."""
    on_disk = {str(p.relative_to(ros2_control_demos)) for p in ros2_control_demos.glob("example_*/bringup/config/*.yaml")}
    assert on_disk == set(RUNS) | OTHER_NODES


@pytest.mark.parametrize(("yaml_file", "run"), [(y, r) for y, runs in RUNS.items() for r in runs],
                         ids=lambda v: v if isinstance(v, str) else (v[0] or "/"))
def test_each_manager_against_its_own_description_gets_only_true_findings(
        ros2_control_demos: Path, yaml_file: str, run: Run) -> None:
    """Lint says of each manager exactly what :data:`EXPECTED` lists: no error, and no warning Jazzy's behaviour
    does not bear out."""
    findings = _lint(ros2_control_demos, yaml_file, run)
    assert _said(findings) == set(EXPECTED.get((yaml_file, run[0]), {})), [str(f) for f in findings]


@pytest.mark.parametrize("yaml_file", sorted(OTHER_NODES))
def test_other_nodes_files_have_no_finding(ros2_control_demos: Path, yaml_file: str) -> None:
    """A publisher's or the wrench transformer's parameters are not a controller manager's: lint leaves them be."""
    assert lint_controllers(ros2_control_demos / yaml_file, package_path=[ros2_control_demos]) == []


def test_example_15_in_one_call_checks_each_manager_against_its_own_robot(ros2_control_demos: Path) -> None:
    """Descriptions by namespace, each with its own xacro arguments, in one call: the same findings as one call per
    manager."""
    D = ros2_control_demos  # noqa: N806
    by_namespace = {ns: (D / description, args) for ns, description, args in RUNS[EX15]}
    findings = lint_controllers(D / EX15, by_namespace, package_path=[D])
    assert _said(findings) == {("warning", "/**/position_trajectory_controller.state_publish_rate")}


def test_example_15_against_one_robot_for_both_managers_finds_the_other_robots_joints(
        ros2_control_demos: Path) -> None:
    """A plain description is for every manager: rrbot_2's controllers claim joints that rrbot_1's robot lacks
    (6 errors), as they would if the launch file gave both managers the same robot."""
    D = ros2_control_demos  # noqa: N806
    _, description, args = RUNS[EX15][0]
    findings = lint_controllers(D / EX15, D / description, args, package_path=[D])
    errors = [f for f in findings if f.level == "error"]
    assert len(errors) == 6 and all(f.where.startswith("/rrbot_2/") and "rrbot_2_joint" in f.message for f in errors)


def _cli(demos: Path, yaml_file: str, run: Run) -> list[str]:
    namespace, description, args = run
    return ["lint", str(demos / yaml_file), "--namespace", namespace or "/", "--description", str(demos / description),
            "--package-path", str(demos), *(f"--arg={k}:={v}" for k, v in args.items())]


def test_cli_lints_example_15_once_per_manager(ros2_control_demos: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``lint --namespace NS --description URDF --arg ...`` per include of the launch file: exit 0 for each, with the
    one true warning."""
    for run in RUNS[EX15]:
        assert main(_cli(ros2_control_demos, EX15, run)) == 0
        out = capsys.readouterr().out
        assert "state_publish_rate" in out and out.rstrip().endswith("0 error(s), 1 warning(s)")


def test_cli_description_for_a_namespace_the_file_does_not_configure(ros2_control_demos: Path,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """``--description /rrbot_3=URDF`` on example 15 is an error that lists the managers there are."""
    D = ros2_control_demos  # noqa: N806
    status = main(["lint", str(D / EX15), "--package-path", str(D), "--arg", "prefix:=rrbot_1_",
                   "--description", f"/rrbot_1={D / RUNS[EX15][0][1]}",
                   "--description", f"/rrbot_3={D / RUNS[EX15][1][1]}"])
    out = capsys.readouterr().out
    assert status == 1
    assert "description for '/rrbot_3': no controller manager of this file runs in or is named '/rrbot_3'" in out
    assert "valid: /rrbot_1, /rrbot_1/controller_manager, /rrbot_2, /rrbot_2/controller_manager" in out


def test_cli_namespace_the_file_has_no_section_for(ros2_control_demos: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """``--namespace /other`` on a file whose sections all name /rrbot: a warning that nothing was checked."""
    yaml_file = "example_15/bringup/config/rrbot_namespace_controllers.yaml"
    assert main(["lint", str(ros2_control_demos / yaml_file), "--namespace", "/other"]) == 0
    out = capsys.readouterr().out
    assert "warning: namespace /other: no section of this file applies to a controller manager" in out
    assert "(the file names /rrbot)" in out
