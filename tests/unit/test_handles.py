"""handles.py: data types, initial-value parsing, handles and loans."""

from __future__ import annotations

import locale
import math

import pytest

from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.hardware_interface.handles import (
    SUPPORTED_DATA_TYPES,
    CommandInterface,
    Handle,
    LoanedCommandInterface,
    LoanedStateInterface,
    StateInterface,
    parse_value,
)


def test_supported_data_types_are_those_of_ros2_control() -> None:
    assert set(SUPPORTED_DATA_TYPES) == {
        "double", "float32", "bool", "int8", "uint8", "int16", "uint16", "int32", "uint32",
    }


@pytest.mark.parametrize("text", ["", None, "   "])
def test_empty_initial_value_is_nan_for_floating_types(text: str | None) -> None:
    assert math.isnan(parse_value(text, "double")) and math.isnan(parse_value(text, "float32"))


def test_empty_initial_value_is_false_for_bool() -> None:
    assert parse_value("", "bool") is False


@pytest.mark.parametrize(
    ("data_type", "maximum"),
    [("int8", 127), ("uint8", 255), ("int16", 32767), ("uint16", 65535), ("int32", 2**31 - 1), ("uint32", 2**32 - 1)],
)
def test_empty_initial_value_is_the_integer_maximum(data_type: str, maximum: int) -> None:
    assert parse_value("", data_type) == maximum


@pytest.mark.parametrize(("text", "expected"), [("true", True), ("True", True), ("FALSE", False), ("false", False)])
def test_bool_parses_in_any_letter_case(text: str, expected: bool) -> None:
    assert parse_value(text, "bool") is expected


def test_bool_rejects_other_words() -> None:
    with pytest.raises(DescriptionError, match="yes"):
        parse_value("yes", "bool", where="gpio/flag")


def test_integer_parses() -> None:
    assert parse_value(" -12 ", "int16") == -12


def test_integer_rejects_a_fraction() -> None:
    with pytest.raises(DescriptionError, match="int32"):
        parse_value("1.5", "int32")


@pytest.mark.parametrize(("text", "expected"), [("1.57", 1.57), ("-3", -3.0), ("2.5e-3", 0.0025), (" 0.7854 ", 0.7854)])
def test_double_parses_with_a_dot(text: str, expected: float) -> None:
    assert parse_value(text, "double") == expected


def test_double_parsing_ignores_the_locale() -> None:
    """A decimal point is a dot whatever LC_NUMERIC says (ros2_control's locale-independent stod)."""
    saved = locale.setlocale(locale.LC_NUMERIC)
    for name in ("de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8"):
        try:
            locale.setlocale(locale.LC_NUMERIC, name)
            break
        except locale.Error:
            continue
    try:
        assert parse_value("1.5", "double") == 1.5
        with pytest.raises(DescriptionError):
            parse_value("1,5", "double")
    finally:
        locale.setlocale(locale.LC_NUMERIC, saved)


def test_unsupported_data_type_raises_in_parse_value() -> None:
    with pytest.raises(DescriptionError, match="cv::Mat") as info:
        parse_value("", "cv::Mat", where="camera/image")
    assert "camera/image" in str(info.value) and "double" in str(info.value)


def test_unsupported_data_type_raises_when_a_handle_is_built() -> None:
    with pytest.raises(DescriptionError, match="camera/image"):
        StateInterface("camera", "image", "cv::Mat")


def test_handle_names_and_default_value() -> None:
    h = CommandInterface("joint1", "position")
    assert (h.name, h.prefix_name, h.interface_name, h.data_type) == ("joint1/position", "joint1", "position", "double")
    assert (h.get_name(), h.get_prefix_name(), h.get_interface_name()) == ("joint1/position", "joint1", "position")
    assert math.isnan(h.get_value())


def test_handle_default_follows_its_type() -> None:
    assert Handle("gpio", "flag", "bool").get_value() is False
    assert Handle("gpio", "count", "uint8").get_value() == 255


def test_handle_stores_values() -> None:
    h = StateInterface("joint1", "velocity", initial_value=0.0)
    h.set_value(0.25)
    assert h.get_value() == 0.25


def test_loaned_state_interface_reads_through() -> None:
    h = StateInterface("joint1", "position", initial_value=1.0)
    loan = LoanedStateInterface(h)
    h.set_value(2.0)
    assert loan.get_value() == 2.0 and loan.name == "joint1/position"
    assert (loan.get_prefix_name(), loan.get_interface_name()) == ("joint1", "position")
    assert not hasattr(loan, "set_value")


def test_loaned_command_interface_writes_through() -> None:
    h = CommandInterface("joint1", "position")
    LoanedCommandInterface(h).set_value(0.7)
    assert h.get_value() == 0.7


def test_loan_release_runs_the_callback_once() -> None:
    released: list[str] = []
    loan = LoanedCommandInterface(CommandInterface("joint1", "position"), lambda: released.append("joint1/position"))
    loan.release()
    loan.release()
    assert released == ["joint1/position"]


def test_loan_without_callback_releases_quietly() -> None:
    loan = LoanedStateInterface(StateInterface("joint1", "position"))
    loan.release()
    assert loan.get_name() == "joint1/position"
