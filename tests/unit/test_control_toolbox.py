"""Tests for control_toolbox.Pid; step sequences ported from control_toolbox/test/pid_tests.cpp.

Upstream's newest tests report the integral term one step later (their forward-Euler variant); the
commands are the same. The i-terms asserted here follow the Jazzy order: output first, then integrate.
"""

from __future__ import annotations

import math

import pytest

from rrbot_workshop.control_toolbox.pid import Gains, Pid
from rrbot_workshop.exceptions import ParameterError


def _run(pid: Pid, steps: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out = []
    for error, dt in steps:
        cmd = pid.compute_command(error, dt)
        out.append((cmd, pid.get_current_pid_errors()[1]))
    return out


def test_proportional_only():
    pid = Pid(p=1.0, u_clamp_max=10.0, u_clamp_min=-10.0)
    assert [pid.compute_command(e, 1.0) for e in (-0.5, -0.5, -1.0, 0.5)] == [-0.5, -0.5, -1.0, 0.5]


def test_integral_only_output_uses_previous_integral():
    """Strategy "none": the first step gives 0, the integral is added to the output before it is updated."""
    pid = Pid(i=1.0, u_clamp_max=5.0, u_clamp_min=-5.0, antiwindup_strategy="none")
    cmds = [pid.compute_command(e, 1.0) for e in (-0.5, -0.5, 0.0, 0.0, 1.0, 0.0)]
    assert cmds == [0.0, -0.5, -1.0, -1.0, -1.0, 0.0]


def test_reset_clears_integral():
    pid = Pid(i=1.0, u_clamp_max=5.0, u_clamp_min=-5.0, antiwindup_strategy="none")
    pid.compute_command(-0.5, 1.0)
    pid.reset()
    assert pid.compute_command(0.5, 1.0) == 0.0
    assert pid.compute_command(0.0, 1.0) == 0.5
    pid.reset(False)
    assert pid.compute_command(-0.5, 1.0) == 0.0
    assert pid.compute_command(0.0, 1.0) == -0.5


def test_reset_with_save_i_term_keeps_integral():
    pid = Pid(i=1.0, u_clamp_max=5.0, u_clamp_min=-5.0)
    pid.compute_command(-0.5, 1.0)
    pid.compute_command(0.0, 1.0)
    pid.reset(save_i_term=True)
    assert pid.compute_command(0.0, 1.0) == -0.5
    assert pid.get_current_cmd() == -0.5


def test_derivative_only_differentiates_errors():
    pid = Pid(d=1.0, u_clamp_max=10.0, u_clamp_min=-10.0)
    steps = [(-0.5, 1.0), (-0.5, 1.0), (-0.5, 0.1), (-1.0, 1.0), (-0.5, 1.0)]
    assert [pid.compute_command(e, dt) for e, dt in steps] == [-0.5, 0.0, 0.0, -0.5, 0.5]


def test_complete_pid_sums_the_three_terms():
    pid = Pid(1.0, 1.0, 1.0, u_clamp_max=5.0, u_clamp_min=-5.0, i_clamp_max=10.0, i_clamp_min=-10.0,
              antiwindup_strategy="none")
    assert [pid.compute_command(e, 1.0) for e in (-0.5, -0.5, 0.0)] == [-1.0, -1.0, -0.5]


def test_error_dot_overload_uses_given_derivative():
    pid = Pid(1.0, 1.0, 1.0, u_clamp_max=5.0, u_clamp_min=-5.0, antiwindup_strategy="none")
    assert pid.compute_command(-0.5, 1.0) == -1.0  # p -0.5 + d -0.5
    assert pid.compute_command(-0.5, 0.0, 1.0) == -1.0  # p -0.5 + i -0.5 + d 0
    assert pid.compute_command(-0.5, 2.0, 1.0) == 0.5  # p -0.5 + i -1.0 + d 2.0


def test_output_clamp():
    pid = Pid(p=1.0, u_clamp_max=1.0, u_clamp_min=-1.0)
    errors = [0.5, 1.0, 2.0, 10.0, 50.0, 100.0, -0.5, -1.0, -2.0, -10.0, -50.0, -100.0]
    assert [pid.compute_command(e, 1.0) for e in errors] == [0.5, 1.0, 1, 1, 1, 1, -0.5, -1.0, -1, -1, -1, -1]


def test_no_output_clamp_with_infinite_limits():
    pid = Pid(p=1.0)
    assert [pid.compute_command(e, 1.0) for e in (2.0, 100.0, -100.0)] == [2.0, 100.0, -100.0]


def test_integral_clamp_with_back_calculation():
    """integrationAntiwindupTest: i=2, i in [-1, 1], Tt=1, no output clamp."""
    pid = Pid(i=2.0, i_clamp_max=1.0, i_clamp_min=-1.0, antiwindup_strategy="back_calculation",
              tracking_time_constant=1.0)
    cmds = [pid.compute_command(e, 1.0) for e in (-1.0, -1.0, 0.5, 0.0)]
    assert cmds == pytest.approx([0.0, -1.0, -1.0, 0.0], abs=1e-9)


def test_integral_clamp_with_no_strategy():
    pid = Pid(i=1.0, i_clamp_max=1.0, i_clamp_min=-1.0, antiwindup_strategy="none")
    _run(pid, [(-10.03, 1.0)])
    assert pid.i_term == -1.0
    assert pid.compute_command(30.0, 1.0) == -1.0
    assert pid.compute_command(0.0, 1.0) == 1.0


@pytest.mark.parametrize("strategy", ["back_calculation", "conditional_integration"])
def test_zero_integral_gain_keeps_integral_zero(strategy):
    pid = Pid(u_clamp_max=20.0, u_clamp_min=-20.0, i_clamp_max=1.0, i_clamp_min=-1.0, antiwindup_strategy=strategy)
    assert _run(pid, [(-1.0, 1.0)] * 3 + [(10.0, 1.0)] * 3) == [(0.0, 0.0)] * 6


def test_back_calculation_steps():
    """backCalculationForwardPIDTest: i=1, |u|<=5, Tt=1; (command, i-term) after each step."""
    pid = Pid(i=1.0, u_clamp_max=5.0, u_clamp_min=-5.0, i_clamp_max=10.0, i_clamp_min=-10.0,
              antiwindup_strategy="back_calculation", tracking_time_constant=1.0)
    steps = [(e, 1.0) for e in (1.0, 2.0, 3.0, 1.0, 2.0, -1.0, 1.0)]
    assert _run(pid, steps) == [(0.0, 1.0), (1.0, 3.0), (3.0, 6.0), (5.0, 6.0), (5.0, 7.0), (5.0, 4.0), (4.0, 5.0)]


def test_conditional_integration_steps():
    """conditionalIntegrationForwardPIDTest: the integral holds while saturated in the error's direction."""
    pid = Pid(i=1.0, u_clamp_max=5.0, u_clamp_min=-5.0, i_clamp_max=10.0, i_clamp_min=-10.0,
              antiwindup_strategy="conditional_integration")
    steps = [(e, 1.0) for e in (1.0, 2.0, 3.0, 1.0, 2.0, -1.0, 0.0)]
    assert _run(pid, steps) == [(0.0, 1.0), (1.0, 3.0), (3.0, 6.0), (5.0, 6.0), (5.0, 6.0), (5.0, 5.0), (5.0, 5.0)]


def test_no_strategy_winds_up():
    pid = Pid(i=1.0, u_clamp_max=5.0, u_clamp_min=-5.0, antiwindup_strategy="none")
    assert _run(pid, [(3.0, 1.0)] * 3) == [(0.0, 3.0), (3.0, 6.0), (5.0, 9.0)]


def test_error_deadband_stops_integration():
    pid = Pid(i=1.0, error_deadband=0.1)
    _run(pid, [(0.05, 1.0), (-0.1, 1.0)])
    assert pid.i_term == 0.0
    pid.compute_command(0.2, 1.0)
    assert pid.i_term == pytest.approx(0.2)


def test_back_calculation_default_tracking_time_constant_sqrt_d_over_i():
    assert Pid(p=1.0, i=4.0, d=1.0, antiwindup_strategy="back_calculation").get_gains().tracking_time_constant == 0.5


def test_back_calculation_default_tracking_time_constant_p_over_i():
    assert Pid(p=1.0, i=4.0, antiwindup_strategy="back_calculation").get_gains().tracking_time_constant == 0.25


def test_back_calculation_default_undefined_is_rejected():
    with pytest.raises(ParameterError, match="tracking_time_constant"):
        Pid(p=0.0, i=4.0, antiwindup_strategy="back_calculation")


def test_dt_zero_returns_previous_command_and_keeps_state():
    pid = Pid(p=1.0, i=1.0)
    first = pid.compute_command(1.0, 0.5)
    i_before = pid.i_term
    assert pid.compute_command(7.0, 0.0) == first
    assert pid.compute_command(7.0, 3.0, 0.0) == first
    assert pid.i_term == i_before


def test_negative_dt_raises_naming_dt():
    with pytest.raises(ValueError, match="dt.*-0.1"):
        Pid(p=1.0).compute_command(1.0, -0.1)
    with pytest.raises(ValueError, match="dt"):
        Pid(p=1.0).compute_command(1.0, 0.0, -0.1)


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_non_finite_error_gives_nan_and_keeps_integral(bad):
    pid = Pid(p=1.0, i=1.0, antiwindup_strategy="none")
    pid.compute_command(1.0, 1.0)
    assert math.isnan(pid.compute_command(bad, 1.0))
    assert math.isnan(pid.compute_command(1.0, bad, 1.0))
    assert pid.i_term == 1.0
    assert pid.compute_command(1.0, 1.0) == 2.0


def test_wrong_argument_count_raises():
    with pytest.raises(TypeError, match=r"compute_command.*\(error, dt\) or \(error, error_dot, dt\)"):
        Pid().compute_command(1.0)


def test_p_i_d_terms_for_state_publishing():
    pid = Pid(2.0, 1.0, 3.0)
    pid.compute_command(1.0, 0.5)
    assert (pid.p_term, pid.d_term) == (2.0, 6.0)
    assert pid.i_term == 0.5


def test_bad_output_limits_rejected_with_values():
    with pytest.raises(ParameterError, match=r"u_clamp_min: 1.0, u_clamp_max: -1.0"):
        Pid(1.0, 1.0, 1.0, u_clamp_max=-1.0, u_clamp_min=1.0)


def test_equal_output_limits_rejected():
    with pytest.raises(ParameterError, match="u_clamp_min"):
        Pid(1.0, u_clamp_max=0.0, u_clamp_min=0.0)


def test_nan_output_limit_rejected():
    with pytest.raises(ParameterError, match="NaN"):
        Pid(1.0, u_clamp_max=math.nan)


@pytest.mark.parametrize(("i_max", "i_min"), [(-1.0, 1.0), (1.0, 0.5), (-0.5, -1.0), (0.0, 0.0)])
def test_bad_integral_limits_rejected_with_values(i_max, i_min):
    with pytest.raises(ParameterError, match=rf"i_clamp_min: {i_min}, i_clamp_max: {i_max}"):
        Pid(1.0, 1.0, i_clamp_max=i_max, i_clamp_min=i_min)


def test_unknown_strategy_rejected_listing_valid_ones():
    with pytest.raises(ParameterError, match="legacy, none, back_calculation, conditional_integration"):
        Pid(antiwindup_strategy="bogus")


def test_negative_tracking_time_constant_rejected():
    with pytest.raises(ParameterError, match="tracking_time_constant"):
        Pid(1.0, 1.0, antiwindup_strategy="back_calculation", tracking_time_constant=-1.0)


def test_negative_deadband_rejected():
    with pytest.raises(ParameterError, match="error_deadband"):
        Pid(1.0, error_deadband=-1.0)


def test_set_gains_applies_new_gains():
    pid = Pid(1.0)
    pid.set_gains(2.0, 0.0, 0.0, u_clamp_max=1.5)
    assert pid.get_gains() == Gains(p=2.0, u_clamp_max=1.5)
    assert pid.compute_command(1.0, 1.0) == 1.5


def test_set_gains_invalid_keeps_old_gains(caplog: pytest.LogCaptureFixture):
    """control_toolbox control_toolbox/test/pid_tests.cpp, UTermBadIBoundsTest (jazzy): bad bounds in set_gains do
    not raise; the error is logged and the old gains stay."""
    pid = Pid(1.0, 1.0, 1.0, u_clamp_max=1.0, u_clamp_min=-1.0, i_clamp_max=1.0, i_clamp_min=-1.0)
    assert pid.set_gains(Gains(1.0, 1.0, 1.0, i_clamp_max=-1.0, i_clamp_min=1.0)) is False
    assert pid.set_gains(1.0, 1.0, 1.0, u_clamp_max=-1.0, u_clamp_min=1.0) is False
    assert pid.get_gains().i_clamp_max == 1.0 and pid.get_gains().i_clamp_min == -1.0
    assert pid.get_gains().u_clamp_max == 1.0 and pid.get_gains().u_clamp_min == -1.0
    assert "u_clamp_min" in caplog.text and "i_clamp_min" in caplog.text


def test_bad_u_bounds_in_the_constructor_raise():
    """control_toolbox control_toolbox/test/pid_tests.cpp, UTermBadIBoundsTestConstructor (jazzy)."""
    with pytest.raises(ParameterError, match="u_clamp_min"):
        Pid(1.0, 1.0, 1.0, u_clamp_max=-1.0, u_clamp_min=1.0)


@pytest.mark.parametrize("bad", ["1.0", None, [1.0], True])
def test_a_gain_that_is_not_a_number_is_refused_clearly(bad):  # noqa: ANN001
    with pytest.raises(ParameterError, match="'p'.*must be a number"):
        Pid(bad)
    pid = Pid(1.0)
    assert pid.set_gains(bad) is False and pid.get_gains().p == 1.0


# ------------------------------------------------------------------------------------------- legacy (Jazzy's default)
# After control_toolbox's Jazzy pid_tests.cpp (integralOnlyTest, integrationClampTest, integrationAntiwindupTest):
# the legacy strategy integrates first and uses the integral, clamped to [i_clamp_min, i_clamp_max], in the same cycle.


def test_legacy_is_the_default_and_integrates_first():
    pid = Pid(i=1.0, u_clamp_max=5.0, u_clamp_min=-5.0)
    assert pid.get_gains().antiwindup_strategy == "legacy" and pid.get_gains().antiwindup is False
    cmds = [pid.compute_command(e, 1.0) for e in (-0.5, -0.5, 0.0, 0.0, 1.0, 0.0)]
    assert cmds == [-0.5, -1.0, -1.0, -1.0, 0.0, 0.0]


def test_legacy_without_antiwindup_clamps_the_output_of_the_integral_but_lets_it_wind_up():
    pid = Pid(i=1.0, i_clamp_max=1.0, i_clamp_min=-1.0)
    assert [pid.compute_command(-1.0, 1.0) for _ in range(2)] == [-1.0, -1.0]
    assert pid.compute_command(0.5, 1.0) == -1.0  # the stored integral is -1.5: still beyond the clamp


def test_legacy_with_antiwindup_keeps_the_stored_integral_within_the_clamps():
    pid = Pid(i=2.0, i_clamp_max=1.0, i_clamp_min=-1.0, antiwindup=True)
    assert [pid.compute_command(e, 1.0) for e in (-1.0, -1.0, 0.5, -1.0)] == [-1.0, -1.0, 0.0, -1.0]


def test_legacy_complete_pid():
    pid = Pid(1.0, 1.0, 1.0, u_clamp_max=5.0, u_clamp_min=-5.0, i_clamp_max=10.0, i_clamp_min=-10.0)
    # p -0.5 + i -0.5 + d -0.5;  p -0.5 + i -1.0 + d 0;  p 0 + i -1.0 + d 0.5
    assert [pid.compute_command(e, 1.0) for e in (-0.5, -0.5, 0.0)] == [-1.5, -1.5, -0.5]
