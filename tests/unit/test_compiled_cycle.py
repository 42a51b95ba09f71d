"""The compiled control cycle: the plans of the resource manager and of the controller loop follow every state change,
whoever makes it, and a stale plan never runs work that a state forbids. The lazily built messages are the ones the
cycle's numbers give, whenever they are read."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import pytest

import rrbot_workshop as rw
from rrbot_workshop.middleware.lifecycle import TRANSITIONS, ReturnType, State
from rrbot_workshop.msgs import Float64MultiArray

JSB, FWD = "joint_state_broadcaster", "forward_position_controller"


@pytest.fixture
def system() -> Iterator[rw.System]:
    with rw.bringup("rrbot", "rrbot_controllers.yaml", spawn=[JSB, FWD], name="compiled_cycle_test") as s:
        s.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.3, -0.2]))
        s.spin_cycles(2)
        yield s


def test_every_state_change_moves_the_transition_counter(system: rw.System) -> None:
    cm = system.controller_manager
    before = TRANSITIONS.value
    cm.switch_controllers(deactivate=[FWD], strictness="strict")
    assert TRANSITIONS.value > before
    before = TRANSITIONS.value
    cm.set_hardware_component_state("rrbot", "inactive")
    assert TRANSITIONS.value > before


def test_a_controller_deactivated_behind_the_managers_back_is_not_updated(system: rw.System) -> None:
    cm = system.controller_manager
    fwd = cm.get_controller(FWD)
    calls: list[float] = []
    original = fwd.update

    def counting(time: float, period: float) -> ReturnType:
        calls.append(time)
        return original(time, period)

    fwd.update = counting  # type: ignore[method-assign] - replaced at run time: the cycle calls it as it is now
    system.spin_cycles(3)
    assert len(calls) == 3
    fwd.deactivate()  # not through the manager: the plan still lists it until it is rebuilt
    system.spin_cycles(3)
    assert len(calls) == 3


def test_a_switch_between_cycles_changes_who_updates(system: rw.System) -> None:
    cm = system.controller_manager
    stats = cm.controller_statistics()
    updates = stats[FWD].execution_time.count
    cm.switch_controllers(deactivate=[FWD], strictness="strict")
    system.spin_cycles(5)
    assert cm.controller_statistics()[FWD].execution_time.count == updates
    cm.switch_controllers(activate=[FWD], strictness="strict")
    system.spin_cycles(5)
    assert cm.controller_statistics()[FWD].execution_time.count == 5  # statistics restart at activation
    assert cm.controller_statistics()[FWD].periodicity.count == 4  # the first update is not a period (Jazzy)


def test_hardware_taken_down_between_cycles_is_no_longer_read_or_written(system: rw.System) -> None:
    rm = system.resource_manager
    impl = rm.get_component("rrbot")._impl  # noqa: SLF001 - the implementation behind the wrapper
    calls = {"read": 0, "write": 0}
    read, write = impl.read, impl.write

    def counted_read(time: float, period: float) -> ReturnType:
        calls["read"] += 1
        return read(time, period)

    def counted_write(time: float, period: float) -> ReturnType:
        calls["write"] += 1
        return write(time, period)

    impl.read, impl.write = counted_read, counted_write
    system.spin_cycles(2)
    assert calls == {"read": 2, "write": 2}
    system.controller_manager.set_hardware_component_state("rrbot", "inactive")  # reads on, writes stop
    system.spin_cycles(2)
    assert calls == {"read": 4, "write": 2}
    system.controller_manager.set_hardware_component_state("rrbot", "unconfigured")
    system.spin_cycles(2)
    assert calls == {"read": 4, "write": 2}
    assert rm.get_component("rrbot").get_lifecycle_state() is State.UNCONFIGURED


def test_a_failing_read_still_takes_the_slow_path(system: rw.System, caplog: pytest.LogCaptureFixture) -> None:
    impl = system.resource_manager.get_component("rrbot")._impl  # noqa: SLF001

    def broken(time: float, period: float) -> ReturnType:
        raise RuntimeError("sensor cable unplugged")

    impl.read = broken
    with caplog.at_level(logging.ERROR):
        system.spin_cycles(1)
    assert "sensor cable unplugged" in caplog.text
    assert system.resource_manager.get_component("rrbot").get_lifecycle_state() is State.UNCONFIGURED
    assert {c.name: c.state for c in system.controller_manager.list_controllers()} == {JSB: "inactive",
                                                                                        FWD: "inactive"}


def test_lazily_built_messages_keep_the_numbers_of_their_cycle(system: rw.System) -> None:
    system.spin_cycles(1)
    system.publish("/forward_position_controller/commands", Float64MultiArray(data=[0.5, 0.1]))
    system.spin_cycles(3)
    history = system.history("/joint_states")
    positions = [m.position for m in history[-4:]]  # built now, long after their cycles
    assert positions == [[0.3, -0.2], [0.3, -0.2], [0.5, 0.1], [0.5, 0.1]]
    stamps = [m.header.stamp for m in history[-4:]]
    assert stamps == sorted(stamps) and len(set(stamps)) == 4


def _linear_blend(t0: float, p0: object, t1: float, p1: object, t: float) -> tuple[list[float], ...]:
    """The linear blend written out in plain Python floats, one joint at a time: the reference."""
    dim, big_t = len(p0.positions), t1 - t0  # type: ignore[attr-defined]
    tau = min(max(t - t0, 0.0), big_t)
    x0, x1 = p0.positions, p1.positions  # type: ignore[attr-defined]
    slopes = [(x1[i] - x0[i]) / big_t if big_t != 0.0 else 0.0 for i in range(dim)]
    positions = [x0[i] + slopes[i] * tau for i in range(dim)]
    e0, e1 = p0.effort, p1.effort  # type: ignore[attr-defined]
    if not (e0 and e1):
        effort = [0.0] * dim
    elif big_t != 0.0:
        effort = [e0[i] + (e1[i] - e0[i]) / big_t * tau for i in range(dim)]
    else:
        effort = [e0[i] + 0.0 for i in range(dim)]
    return positions, slopes, [0.0] * dim, effort


@pytest.mark.parametrize("dim", [2, 40])  # the list path and the numpy path
@pytest.mark.parametrize("with_effort", [False, True])
def test_a_kept_linear_segment_samples_exactly_the_linear_blend(dim: int, with_effort: bool) -> None:
    import random

    from rrbot_workshop.controllers.trajectory import LinearSegment, interpolate_between_points
    from rrbot_workshop.msgs import JointTrajectoryPoint

    rng = random.Random(7)
    for t0, t1 in ((0.25, 1.75), (1.0, 1.0)):  # a segment, and one of zero length
        p0 = JointTrajectoryPoint(positions=[rng.uniform(-3, 3) for _ in range(dim)],
                                  effort=[rng.uniform(-5, 5) for _ in range(dim)] if with_effort else [])
        p1 = JointTrajectoryPoint(positions=[rng.uniform(-3, 3) for _ in range(dim)],
                                  effort=[rng.uniform(-5, 5) for _ in range(dim)] if with_effort else [])
        segment = LinearSegment(t0, p0, t1, p1)
        assert segment.matches(t0, p0, t1, p1) and not segment.matches(t0, p1, t1, p0)
        for t in (t0 - 0.3, t0, t0 + 0.013, (t0 + t1) / 2, t1 - 1e-9, t1, t1 + 2.0):
            sample = segment.at(t)
            positions, velocities, accelerations, effort = _linear_blend(t0, p0, t1, p1, t)
            assert (sample.positions, sample.velocities, sample.accelerations, sample.effort) == \
                (positions, velocities, accelerations, effort), f"differs at t = {t}"
            assert sample.time_from_start == t - t0
            assert interpolate_between_points(t0, p0, t1, p1, t) == sample, f"the general interpolation differs at {t}"


# ----------------------------------------------------------------- flat interface storage
def test_the_resource_manager_holds_every_value_in_one_flat_list(system: rw.System) -> None:
    rm = system.controller_manager.resource_manager
    storage = rm._storage  # noqa: SLF001 - the storage is what this test is about
    handles = [*storage.states.values(), *storage.commands.values()]
    assert handles and all(h._store is storage.values for h in handles)  # noqa: SLF001
    assert sorted(h._index for h in handles) == sorted({h._index for h in handles})  # noqa: SLF001 - one slot each
    state = storage.states["joint1/position"]
    assert storage.values[state._index] == state.get_value() == pytest.approx(0.3)  # noqa: SLF001
    state.set_value(1.25)  # the handle API writes the slot
    assert storage.values[state._index] == 1.25  # noqa: SLF001


def test_a_reader_over_adopted_handles_reads_the_flat_list_and_one_over_own_handles_still_works() -> None:
    from rrbot_workshop.hardware_interface.handles import (
        ADOPTIONS,
        LoanedCommandInterface,
        LoanedStateInterface,
        StateInterface,
        adopt,
        value_reader,
        value_writer,
    )

    a, b, c = StateInterface("j", "a", initial_value=1.0), StateInterface("j", "b", initial_value=2.0), \
        StateInterface("j", "c", initial_value=3.0)
    own = value_reader([LoanedStateInterface(h) for h in (a, b, c)])
    assert own() == [1.0, 2.0, 3.0]  # three lists of their own: read one by one
    store: list[float] = [9.0]
    before = ADOPTIONS.value
    adopt([c, a], store)
    assert ADOPTIONS.value == before + 1 and store == [9.0, 3.0, 1.0]
    adopt([c, a], store)  # already there: nothing moves
    assert ADOPTIONS.value == before + 1 and store == [9.0, 3.0, 1.0]
    a.set_value(5.0)
    assert store[2] == 5.0 and own() == [5.0, 2.0, 3.0]  # the old reader follows each handle to its slot
    shared = value_reader([LoanedStateInterface(h) for h in (a, c)])
    assert shared() == [5.0, 3.0]
    assert value_reader([LoanedStateInterface(c)])() == [3.0]
    write = value_writer([LoanedCommandInterface(h) for h in (a, c)])
    write([7.0, 8.0, 99.0])  # extra values are ignored
    assert (a.get_value(), c.get_value(), store) == (7.0, 8.0, [9.0, 8.0, 7.0])


def test_the_mock_read_plan_follows_its_handles_when_they_move() -> None:
    from rrbot_workshop.hardware_interface.handles import adopt

    info = rw.description.parse_ros2_control(
        rw.description.process_xacro(rw.description.descriptions_root() / "rrbot/urdf/rrbot.urdf.xacro"))[0]
    from rrbot_workshop.hardware.mock import GenericSystem

    component = GenericSystem()
    assert component.on_init(info).name == "SUCCESS"
    states, commands = component.export_state_interfaces(), component.export_command_interfaces()
    component._register_handles(states, commands)  # noqa: SLF001 - what the resource manager does with them
    command = next(h for h in commands if h.name == "joint1/position")
    state = next(h for h in states if h.name == "joint1/position")
    command.set_value(0.5)
    assert component.read(0.0, 0.01) is ReturnType.OK and state.get_value() == 0.5  # plan over the own lists
    store: list[float] = []
    adopt([*states, *commands], store)  # now the handles live in one flat list: the plan is made again
    command.set_value(-0.25)
    assert component.read(0.01, 0.01) is ReturnType.OK
    assert state.get_value() == -0.25 and store[state._index] == -0.25  # noqa: SLF001


def test_the_loop_is_compiled_into_one_block_per_active_controller_and_again_after_a_switch(system: rw.System) -> None:
    cm = system.controller_manager
    source = cm._loop.source  # noqa: SLF001 - the compiled loop is the subject here
    assert source.index(f"# '{JSB}'") < source.index(f"# '{FWD}'")  # chain order
    assert source.count("result = ctrl.update(time, ctrl_period)") == 2
    cm.switch_controllers(deactivate=[FWD], strictness="strict")
    system.spin_cycles(1)
    assert f"# '{FWD}'" not in cm._loop.source  # noqa: SLF001
    assert cm._loop.source.count("result = ctrl.update(time, ctrl_period)") == 1  # noqa: SLF001


def test_a_slower_controller_gets_the_rate_rule_in_the_compiled_loop(system: rw.System) -> None:
    cm = system.controller_manager
    cm.switch_controllers(deactivate=[JSB], strictness="strict")
    cm.get_controller(JSB)._update_rate = 20  # noqa: SLF001 - as if configured with update_rate: 20 (manager: 100 Hz)
    cm.switch_controllers(activate=[JSB], strictness="strict")
    system.spin_cycles(50)
    assert f"# '{JSB}' at 20 Hz" in cm._loop.source  # noqa: SLF001
    stats = cm.controller_statistics()
    assert stats[JSB].execution_time.count == 10 and stats[FWD].execution_time.count == 52  # FWD: + the fixture's 2
    assert stats[JSB].periodicity.count == 9 and stats[JSB].periodicity.maximum == pytest.approx(20.0)


def test_a_traceback_through_the_compiled_loop_shows_its_line(system: rw.System, caplog: pytest.LogCaptureFixture) -> None:
    def broken(time: float, period: float) -> ReturnType:
        raise ZeroDivisionError("learner's bug")

    system.controller_manager.get_controller(FWD).update = broken  # type: ignore[method-assign]
    with caplog.at_level(logging.ERROR):
        system.spin_cycles(1)
    logged = caplog.text
    assert "File \"<rrbot_workshop controller loop" in logged and "result = ctrl.update(time, ctrl_period)" in logged
    assert "ZeroDivisionError: learner's bug" in logged
    from rrbot_workshop.course.tracebacks import is_learner_frame

    loop_file = logged.split('File "')[1].split('"')[0]
    assert loop_file.startswith("<rrbot_workshop controller loop") and not is_learner_frame(loop_file)  # library's
    assert [c.state for c in system.controller_manager.list_controllers()] == ["active", "inactive"]


def test_a_snapshot_reader_gives_the_values_of_the_moment_as_a_tuple() -> None:
    from rrbot_workshop.hardware_interface.handles import LoanedStateInterface, StateInterface, adopt, value_snapshot

    a, b = StateInterface("j", "a", initial_value=1.0), StateInterface("j", "b", initial_value=2.0)
    loans = [LoanedStateInterface(h) for h in (b, a)]
    own = value_snapshot(loans)
    assert own() == (2.0, 1.0)
    adopt([a, b], [])
    shared = value_snapshot(loans)  # now one itemgetter over the flat list
    first = shared()
    a.set_value(5.0)
    assert first == (2.0, 1.0) and shared() == (2.0, 5.0) and own() == (2.0, 5.0)
    assert value_snapshot(loans[:1])() == (2.0,) and value_snapshot([])() == ()


def test_the_hardware_cycle_is_compiled_per_component_and_a_traceback_shows_its_line(
    system: rw.System, caplog: pytest.LogCaptureFixture
) -> None:
    rm = system.resource_manager
    source = rm.cycle.source
    assert "def read(time, period):" in source and "def write(time, period):" in source
    assert source.count("# 'rrbot'\n") == 2  # one block in read, one in write
    impl = rm.get_component("rrbot")._impl  # noqa: SLF001

    def broken(time: float, period: float) -> ReturnType:
        raise OSError("device gone")

    impl.write = broken
    with caplog.at_level(logging.ERROR):
        system.spin_cycles(1)
    assert "File \"<rrbot_workshop hardware write" in caplog.text and "result = component._impl.write(time, period)" in caplog.text
    system.spin_cycles(1)  # the component is out: the plan made again has no block for it
    assert "# 'rrbot'" not in rm.cycle.source


def test_a_plan_compiled_after_the_line_cache_was_cleared_still_shows_its_lines(system: rw.System) -> None:
    import linecache

    cm = system.controller_manager
    cm.switch_controllers(deactivate=[FWD], strictness="strict")
    system.spin_cycles(1)
    linecache.clearcache()  # as a tool or a notebook extension may do
    cm.switch_controllers(activate=[FWD], strictness="strict")  # back to a plan whose code was compiled before
    system.spin_cycles(1)
    filename = cm._loop.update.__code__.co_filename  # noqa: SLF001
    assert linecache.getline(filename, 1) == "def update(time, period):\n"


def test_a_controller_name_is_never_code_in_the_compiled_loop(system: rw.System) -> None:
    """A name that would be code is refused at load (not a ROS node name); a valid one is a repr in the source."""
    from rrbot_workshop.exceptions import ControllerError

    cm = system.controller_manager
    before = list(cm.controllers)
    name = "odd\nraise SystemExit('a name became code')"
    with pytest.raises(ControllerError, match="not a valid ROS node name"):
        cm.load_controller(name, "joint_state_broadcaster/JointStateBroadcaster")
    assert list(cm.controllers) == before
    system.spin_cycles(3)
    assert repr(FWD) in cm._loop.source  # noqa: SLF001 - names enter the compiled loop as literals only


def test_the_statistics_of_a_long_run_are_folded_as_they_pile_up(system: rw.System) -> None:
    from rrbot_workshop.controller_manager.statistics import ControllerStatistics

    stats = system.controller_manager._controllers[FWD].statistics  # noqa: SLF001 - the record behind the figures
    system.spin_cycles(ControllerStatistics.FOLD_EVERY + 10)
    assert len(stats.pending) < ControllerStatistics.FOLD_AT  # folded once during the run, not only when read
    assert stats.periodicity.count == ControllerStatistics.FOLD_EVERY + 11 and not stats.pending  # + the fixture's 2
    assert stats.periodicity.minimum == stats.periodicity.maximum == pytest.approx(100.0)
