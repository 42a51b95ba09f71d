"""The status model of the instructor's views: not started, working, stuck or passed, from attempt records alone."""

from __future__ import annotations

import math

import pytest

from rrbot_workshop.classroom.task_status import (
    NOT_STARTED,
    PASSED,
    STUCK,
    WORKING,
    Attempt,
    TaskState,
    classify,
    last_activity,
)
from rrbot_workshop.exceptions import CourseError

T0 = 1_800_000_000.0
HANDED_OUT = "v-handed-out"
TEN_MIN = 600.0


def _at(minute: float, score: float = 0.0, failed: tuple[str, ...] = ("a",), version: str = "",
        max_score: float = 10.0) -> Attempt:
    return Attempt(T0 + 60 * minute, score, max_score, failed, {c: f"{c} is wrong" for c in failed},
                   version or f"v{minute}")


def _now(minute: float) -> float:
    return T0 + 60 * minute


def test_no_attempt_is_not_started() -> None:
    assert classify([], _now(0)) == TaskState(NOT_STARTED)


def test_self_checks_of_the_exercise_as_handed_out_are_not_a_start_however_long_ago() -> None:
    attempts = [_at(0, failed=("a", "b"), version=HANDED_OUT), _at(40, failed=("a", "b"), version=HANDED_OUT)]
    state = classify(attempts, _now(90), TEN_MIN, untouched={HANDED_OUT})
    assert state.status == NOT_STARTED and state.attempts == 2 and state.stuck_on == ()


def test_the_same_attempts_without_knowing_the_handed_out_version_are_stuck() -> None:
    attempts = [_at(0, version=HANDED_OUT), _at(40, version=HANDED_OUT)]
    assert classify(attempts, _now(90), TEN_MIN).status == STUCK


def test_a_check_failing_for_less_than_stuck_after_is_working() -> None:
    state = classify([_at(0), _at(5)], _now(9), TEN_MIN)
    assert state.status == WORKING and state.failing_since == {"a": _now(0)} and state.stuck_on == ()


def test_the_same_check_failing_for_stuck_after_is_stuck_and_names_the_check() -> None:
    state = classify([_at(0, failed=("a", "b")), _at(5, failed=("a",))], _now(10), TEN_MIN)
    assert state.status == STUCK and state.stuck_on == ("a",) and state.failing == {"a": "a is wrong"}


def test_fixing_a_check_restarts_the_clock_of_the_next_one() -> None:
    """a fails from minute 0 to 8, then b fails from minute 9: at minute 15 b has failed for 6 minutes only."""
    attempts = [_at(0, failed=("a",)), _at(8, failed=("a",)), _at(9, failed=("b",)), _at(14, failed=("b",))]
    state = classify(attempts, _now(15), TEN_MIN)
    assert state.status == WORKING and state.failing_since == {"b": _now(9)}


def test_a_check_that_passed_in_between_starts_its_clock_again() -> None:
    attempts = [_at(0, failed=("a",)), _at(3, failed=("b",)), _at(4, failed=("a",))]
    assert classify(attempts, _now(12), TEN_MIN).failing_since == {"a": _now(4)}


def test_a_check_of_the_untouched_files_does_not_start_the_stuck_clock() -> None:
    attempts = [_at(0, version=HANDED_OUT), _at(30), _at(35)]
    state = classify(attempts, _now(38), TEN_MIN, untouched={HANDED_OUT})
    assert state.status == WORKING and state.failing_since == {"a": _now(30)}


def test_stuck_after_is_an_option() -> None:
    attempts = [_at(0), _at(5)]
    assert classify(attempts, _now(6), stuck_after=300.0).status == STUCK
    assert classify(attempts, _now(6), stuck_after=3600.0).status == WORKING


def test_a_first_try_pass_has_no_time_to_pass() -> None:
    state = classify([_at(12, score=10, failed=())], _now(20))
    assert state.status == PASSED and state.first_try and state.time_to_pass_s is None


def test_a_pass_after_a_check_of_the_untouched_files_is_still_a_first_try() -> None:
    state = classify([_at(0, version=HANDED_OUT), _at(25, score=10, failed=())], _now(30), untouched={HANDED_OUT})
    assert state.status == PASSED and state.first_try and state.time_to_pass_s is None


def test_time_to_pass_runs_from_the_first_check_of_own_work_to_the_first_full_score() -> None:
    attempts = [_at(0, version=HANDED_OUT), _at(10), _at(19, score=10, failed=()), _at(25, score=4)]
    state = classify(attempts, _now(30), untouched={HANDED_OUT})
    assert state.status == PASSED and not state.first_try and state.time_to_pass_s == 540.0
    assert state.passed_at == _now(19) and (state.points, state.attempts) == (4, 4)  # the latest attempt's points


def test_attempts_are_taken_in_time_order() -> None:
    state = classify([_at(9, score=10, failed=()), _at(0)], _now(10))
    assert state.time_to_pass_s == 540.0 and state.first_check == _now(0)


def test_attempt_times_after_now_are_never_stuck() -> None:
    assert classify([_at(50), _at(60)], _now(0), TEN_MIN).status == WORKING


@pytest.mark.parametrize("bad", [math.nan, math.inf, -1.0, "600", True])
def test_classify_refuses_a_stuck_after_that_is_not_seconds(bad: object) -> None:
    with pytest.raises(CourseError, match="stuck_after"):
        classify([], _now(0), bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("bad", [math.nan, -math.inf, None])
def test_classify_refuses_a_now_that_is_not_a_time(bad: object) -> None:
    with pytest.raises(CourseError, match="now"):
        classify([], bad)  # type: ignore[arg-type]


def test_a_record_from_the_log_becomes_an_attempt_with_its_reasons_cut_to_size() -> None:
    attempt = Attempt.from_record({"time": T0, "score": 3, "max_score": 10, "failed": ["b", "a"], "version": "x",
                                   "reasons": {"a": "r" * 1000, "b": ["not", "text"]}})
    assert attempt.failed == ("a", "b") and attempt.reasons == {"a": "r" * 300, "b": ""} and not attempt.full


@pytest.mark.parametrize("record, why", [
    ([], "an object"), ({"score": 1}, "'time' must be a number"), ({"time": True}, "'time' must be a number"),
    ({"time": math.nan}, "'time' must be between"), ({"time": 10**400}, "'time' is out of range"),
    ({"time": -5}, "'time' must be between"), ({"time": T0, "score": 11, "max_score": 10}, "'score' must be between"),
    ({"time": T0, "failed": "a"}, "'failed' must be a list"), ({"time": T0, "failed": [1]}, "'failed' must be a list"),
])
def test_from_record_raises_value_error_naming_the_field(record: object, why: str) -> None:
    with pytest.raises(ValueError, match=why):
        Attempt.from_record(record)


def test_last_activity_is_the_latest_self_check_of_any_task() -> None:
    assert last_activity([_at(3), _at(1), _at(7)]) == _now(7) and last_activity([]) is None


def test_to_dict_is_json_ready() -> None:
    data = classify([_at(0), _at(11)], _now(11), TEN_MIN).to_dict()
    assert data["status"] == STUCK and data["stuck_on"] == ["a"] and data["failing_since"] == {"a": _now(0)}
