"""Bad input to the library's public API, as a learner meets it: refused with a project error naming the argument,
never a raw traceback, a hang or a silent acceptance of what ROS would refuse; a refused request changes nothing.

The cases are :data:`hostile_api_cases.CASES` (bringup, System, topics, the trajectory and forward command
controllers, the controller manager, parameters, descriptions and xacro, hardware parameters, joint limits, Pid,
interpolation, ControllerHarness, learner code that raises); :mod:`hostile_api` runs and judges each one.
"""

from __future__ import annotations

import pytest
from hostile_api import ACCEPT, EITHER, REFUSE, run_case, verdict
from hostile_api_cases import CASES

#: Cases the library still accepts although ROS would refuse them somewhere: each says where the gap is.
KNOWN_GAPS = {
    "System.call_service: list_controllers with a wrong request":
        "a service request is a plain mapping here; its field types are not checked",
    "parse_ros2_control: an unknown type":
        "Jazzy's parser takes any type too; its resource manager refuses it at load, this one loads it as a system",
    "parse_ros2_control: min above max": "neither Jazzy's parser nor this one compares an interface's min and max",
    "parse_ros2_control: a limit velocity negative":
        "urdfdom reads a negative velocity limit as Jazzy does; this one does not refuse it either",
}


def _param(case):  # noqa: ANN001, ANN202 - a Case
    marks = [pytest.mark.xfail(reason=KNOWN_GAPS[case.id], strict=True)] if case.id in KNOWN_GAPS else []
    return pytest.param(case, id=case.id, marks=marks)


@pytest.mark.parametrize("case", [_param(c) for c in CASES])
def test_bad_input_is_refused_with_a_project_error_naming_the_argument(case, tmp_path) -> None:  # noqa: ANN001
    """Each hostile call: no raw exception (in the call or in a callback it runs), no hang; a refusal is of the
    case's project error type, names the argument and changes nothing; an accepted odd value says why."""
    outcome = run_case(case, tmp_path)
    assert outcome.kind != "hang", outcome.describe()
    assert outcome.kind != "raw", outcome.describe()
    assert not outcome.logged_raw, outcome.describe()
    if case.expect == REFUSE and outcome.kind == "refused":
        assert isinstance(outcome.error, case.error), outcome.describe()
        message = str(outcome.error).lower()
        assert all(name.lower() in message for name in case.names), outcome.describe()
        assert outcome.unchanged is not False, outcome.describe()
    elif case.expect == REFUSE:
        assert case.by_log, outcome.describe()  # refused in a subscriber's log line, as ROS does, or not at all
        said = [t for t in outcome.logged if all(n.lower() in t.lower() for n in case.names)]
        assert said, outcome.describe()
    elif case.expect == ACCEPT:
        assert outcome.kind in ("ok", "user-raised"), outcome.describe()
        assert case.why, "an odd input accepted on purpose says why"
    else:
        assert case.expect == EITHER and case.why, "a case that allows both says why"
    assert verdict(outcome) == "good", outcome.describe()
