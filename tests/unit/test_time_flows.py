"""Simulated time always flows: ``spin(seconds)`` advances the clock by ``seconds`` for any value, and a run split
into many spins runs the same cycles as one spin of their sum (the manager's and each controller's own rate).

ros2_control_demos' example 11 runs its controller manager at 10 Hz; six ``spin(1/30)`` calls used to leave the
clock at 0.0 s because each one was rounded to whole cycles on its own.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rrbot_workshop as rw
from rrbot_workshop.middleware.clock import SimClock

YAML = """\
controller_manager:
  ros__parameters:
    update_rate: {rate}
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    forward_position_controller:
      type: forward_command_controller/ForwardCommandController

joint_state_broadcaster:
  ros__parameters:
    update_rate: {jsb_rate}

forward_position_controller:
  ros__parameters:
    joints: [joint1, joint2]
    interface_name: position
"""


def _system(tmp_path: Path, rate: int, jsb_rate: int) -> Any:
    config = tmp_path / f"controllers_{rate}_{jsb_rate}.yaml"
    config.write_text(YAML.format(rate=rate, jsb_rate=jsb_rate))
    return rw.bringup(description="rrbot", controllers=config,
                      spawn=["joint_state_broadcaster", "forward_position_controller"])


def _recorded(system: Any) -> list[float]:
    """The times of the manager's cycles from now on (its ``update`` wrapped)."""
    cycles: list[float] = []
    update = system.controller_manager.update

    def recording(time: float, period: float) -> None:
        cycles.append(time)
        update(time, period)

    system.controller_manager.update = recording
    return cycles


def _broadcasts(system: Any) -> list[float]:
    return [m.header.stamp for m in system.history("/joint_states")]


def test_six_spins_of_a_third_of_a_period_on_a_10_hz_manager_run_two_cycles(tmp_path: Path) -> None:
    """Example 11's case: a 10 Hz manager spun 1/30 s at a time."""
    system = _system(tmp_path, 10, 10)
    try:
        start = system.time
        cycles = _recorded(system)
        for _ in range(6):
            system.spin(1 / 30)
        assert system.time == pytest.approx(start + 0.2, abs=1e-9)
        assert cycles == pytest.approx([start + 0.1, start + 0.2])
    finally:
        system.shutdown()


def test_a_spin_shorter_than_the_period_moves_the_clock_and_runs_no_cycle(tmp_path: Path) -> None:
    system = _system(tmp_path, 100, 100)
    try:
        start = system.time
        cycles = _recorded(system)
        assert system.spin(0.004) == pytest.approx(start + 0.004, abs=1e-12)
        assert cycles == []
        system.spin(0.006)
        assert cycles == pytest.approx([start + 0.01]) and system.time == pytest.approx(start + 0.01, abs=1e-12)
    finally:
        system.shutdown()


def test_clock_plan_reads_durations_as_fractions_and_carries_the_rest() -> None:
    clock = SimClock(30)
    cycles, since = clock.plan(0.05)  # one and a half periods of 1/30 s
    assert cycles == 1 and since == Fraction(1, 60)
    for _ in range(cycles):
        clock.tick()
    clock.advance(since)
    assert clock.now() == pytest.approx(0.05, abs=1e-12)
    assert clock.plan(1 / 60) == (1, 0)  # the other half period completes the next cycle exactly
    assert SimClock(10).plan(1 / 30) == (0, Fraction(1, 30))


@pytest.mark.parametrize("seconds", [-0.001, float("nan"), float("inf"), "0.1", None])
def test_a_negative_or_not_finite_duration_is_refused(seconds: float) -> None:
    with pytest.raises(ValueError, match="finite duration of 0 s or more"):
        SimClock(100).plan(seconds)


def test_advance_refuses_a_time_beyond_one_period() -> None:
    with pytest.raises(ValueError, match="within one period"):
        SimClock(100).advance(Fraction(1, 100))


@settings(derandomize=True, database=None, deadline=None, max_examples=40,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rate=st.sampled_from([10, 30, 100]), jsb_divisor=st.sampled_from([1, 2, 3]),
       spins_us=st.lists(st.integers(min_value=0, max_value=250_000), min_size=1, max_size=8))
def test_many_spins_run_the_same_cycles_as_one_spin_of_their_sum(tmp_path: Path, rate: int, jsb_divisor: int,
                                                                  spins_us: list[int]) -> None:
    """Spin sizes in whole microseconds (so their sum is exact): the manager's cycle times, the broadcaster's
    updates at its own rate (a divisor of the manager's), and the final clock are the same either way."""
    jsb_rate = max(1, rate // jsb_divisor)
    split, whole = _system(tmp_path, rate, jsb_rate), _system(tmp_path, rate, jsb_rate)
    try:
        split_cycles, whole_cycles = _recorded(split), _recorded(whole)
        split_seen, whole_seen = len(split.history("/joint_states")), len(whole.history("/joint_states"))
        for us in spins_us:
            split.spin(us / 1e6)
        whole.spin(sum(spins_us) / 1e6)
        assert split_cycles == whole_cycles
        assert _broadcasts(split)[split_seen:] == _broadcasts(whole)[whole_seen:]
        assert split.time == pytest.approx(whole.time, abs=1e-12)
        assert split.time == pytest.approx(sum(spins_us) / 1e6, abs=1e-9)
    finally:
        split.shutdown()
        whole.shutdown()
