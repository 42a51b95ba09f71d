"""``%control`` and ``%topic``: IPython magics that print like ``ros2 control`` and ``ros2 topic``.

``%load_ext rrbot_workshop`` registers them. They act on the current system (the last one brought up)
or on ``--system <name>``::

    %control list_controllers
    %control switch_controllers --activate joint_trajectory_controller --deactivate forward_position_controller
    %topic echo /joint_states --once
    %topic info /joint_states -v
    %topic hz /joint_states
    %topic pub /forward_position_controller/commands std_msgs/msg/Float64MultiArray "{data: [0.7, 0.7]}"
    %topic pub /diffbot_base_controller/cmd_vel geometry_msgs/msg/TwistStamped "{header: auto, twist: {linear: {x: 0.1}}}"
    %control load_controller my_controller my_params.yaml --set-state active
    %control -c /rrbot_1/controller_manager list_controllers

The cell magic ``%%pytest --against SPEC [SPEC ...]`` runs the cell's pytest tests once per controller named (see
:func:`rrbot_workshop.course.controller_tests.pytest_cell`).

Output is printed (this is the one module whose job is printing); bad input prints an error line
naming what was wrong and what is valid, and never raises into the notebook.
"""

from __future__ import annotations

import argparse
import shlex
import typing
from pathlib import Path
from typing import Any

import yaml

from rrbot_workshop.bringup import System, current_system, get_system, systems
from rrbot_workshop.exceptions import MessageError, RRBotWorkshopError
from rrbot_workshop.tools.message_yaml import message_from_dict, message_to_yaml, message_type, ros_time

__all__ = ["control", "topic", "load_ipython_extension", "message_from_dict", "message_to_yaml", "ros_time"]


class _UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> typing.NoReturn:
        raise _UsageError(f"{self.prog}: {message}")

    def exit(self, status: int = 0, message: str | None = None) -> typing.NoReturn:
        raise _UsageError(message or "")


def _control_parser() -> _Parser:
    p = _Parser(prog="%control", add_help=False)
    p.add_argument("--system", default=None, help="name of the system (default: the last one brought up)")
    p.add_argument("-c", "--controller-manager", default=None, help="the controller manager by name, e.g. "
                   "/rrbot_1/controller_manager (instead of --system)")
    sub = p.add_subparsers(dest="verb", parser_class=_Parser)
    lc = sub.add_parser("list_controllers", add_help=False)
    lc.add_argument("-v", "--verbose", action="store_true")
    lh = sub.add_parser("list_hardware_components", add_help=False)
    lh.add_argument("-v", "--verbose", action="store_true")
    li = sub.add_parser("list_hardware_interfaces", add_help=False)
    li.add_argument("-v", "--verbose", action="store_true")
    sub.add_parser("list_controller_types", add_help=False)
    load = sub.add_parser("load_controller", add_help=False)
    load.add_argument("name")
    load.add_argument("param_file", nargs="?", default=None)
    load.add_argument("--set-state", choices=["inactive", "active"], default=None)
    scs = sub.add_parser("set_controller_state", add_help=False)
    scs.add_argument("name")
    scs.add_argument("state", choices=["unconfigured", "inactive", "active"])
    sw = sub.add_parser("switch_controllers", add_help=False)
    sw.add_argument("--activate", nargs="*", default=[])
    sw.add_argument("--deactivate", nargs="*", default=[])
    sw.add_argument("--strict", action="store_true")
    sw.add_argument("--activate-asap", action="store_true")
    un = sub.add_parser("unload_controller", add_help=False)
    un.add_argument("name")
    hw = sub.add_parser("set_hardware_component_state", add_help=False)
    hw.add_argument("name")
    hw.add_argument("state", choices=["unconfigured", "inactive", "active", "finalized"])
    sub.add_parser("view_controller_chains", add_help=False)
    st = sub.add_parser("statistics", add_help=False)
    st.add_argument("--no-execution-time", action="store_true")
    why = sub.add_parser("why", add_help=False)
    why.add_argument("name", nargs="?", default=None)
    why.add_argument("--activate", nargs="*", default=None)
    why.add_argument("--deactivate", nargs="*", default=None)
    return p


_VERBS = (
    "list_controllers [-v], list_hardware_components [-v], list_hardware_interfaces [-v], list_controller_types, "
    "load_controller <name> [<param_file>] [--set-state inactive|active], set_controller_state <name> <state>, "
    "switch_controllers [--activate ...] [--deactivate ...] [--strict], unload_controller <name>, "
    "set_hardware_component_state <name> <state>, view_controller_chains, statistics [--no-execution-time], "
    "why <name> [--activate|--deactivate] (or why --activate ... --deactivate ...)"
)


def _why_lists(cm: Any, args: Any) -> tuple[list[str], list[str]]:
    """``why NAME`` activates NAME unless it is active (then deactivates it); the flags say which, or list more."""
    activate, deactivate = list(args.activate or []), list(args.deactivate or [])
    if args.name is not None:
        if args.deactivate is not None and args.activate is None:
            deactivate.insert(0, args.name)
        elif args.activate is not None and args.deactivate is None:
            activate.insert(0, args.name)
        elif args.activate is None and args.deactivate is None:
            spec = cm.controllers.get(args.name)
            (deactivate if spec is not None and spec.state.label == "active" else activate).append(args.name)
        else:
            raise _UsageError("why NAME takes --activate or --deactivate, not both (or list names after each flag)")
    if not activate and not deactivate:
        raise _UsageError("%control why needs a controller: why <name> [--activate|--deactivate]")
    return activate, deactivate


def _system(name: str | None, manager: str | None = None) -> System:
    if manager is not None:  # ros2 control's -c: the controller manager by its (fully qualified) name
        wanted = "/" + manager.strip("/")
        for candidate in systems().values():
            if candidate.controller_manager.name == wanted:
                return candidate
        names = sorted(s.controller_manager.name for s in systems().values())
        raise _UsageError(f"no controller manager {wanted} (running: {', '.join(names) or 'none'})")
    if name is not None:
        return get_system(name)
    system = current_system()
    if system is None:
        raise _UsageError("no running system: call rrbot_workshop.bringup(...) first")
    return system


def _print_controllers(system: System, verbose: bool) -> None:
    states = system.controller_manager.list_controllers()
    if not states:
        print("No controllers are currently loaded!")
        return
    wn = max(len(c.name) for c in states)
    wt = max(len(c.type) for c in states)
    ws = max(len(c.state) for c in states)
    for c in states:
        print(f"{c.name:<{wn}} {c.type:<{wt}}  {c.state:<{ws}}".rstrip())
        if verbose:
            sections = [
                ("claimed interfaces", c.claimed_interfaces),
                ("required command interfaces", c.required_command_interfaces),
                ("required state interfaces", c.required_state_interfaces),
                ("chained to interfaces", [r for conn in c.chain_connections for r in conn.reference_interfaces]),
                ("exported reference interfaces", c.reference_interfaces),
            ]
            for title, items in sections:
                print(f"\t{title}:")
                for item in items:
                    print(f"\t\t{item}")


def _print_statistics(system: System, execution_time: bool) -> None:
    """Per controller: updates, periodicity mean/min/max [Hz] (manager's clock), execution time mean/max [µs]."""
    stats = system.controller_manager.controller_statistics()
    if not stats:
        print("No controllers are currently loaded!")
        return
    wn = max(len(n) for n in stats)
    head = f"{'controller':<{wn}}  updates  periodicity mean/min/max [Hz]"
    print(head + ("   execution mean/max [us]" if execution_time else ""))
    for name, s in stats.items():
        p, updates = s.periodicity, s.execution_time.count
        if not p.count:
            print(f"{name:<{wn}}  {updates:>7}")
            continue
        line = f"{name:<{wn}}  {updates:>7}  {p.mean:7.2f} {p.minimum:7.2f} {p.maximum:7.2f}"
        if execution_time:
            e = s.execution_time
            line += f"   {e.mean:9.1f} {e.maximum:9.1f}"
        print(line)


def _print_hardware_components(system: System, verbose: bool) -> None:
    for idx, comp in enumerate(system.controller_manager.list_hardware_components(), start=1):
        print(f"Hardware Component {idx}")
        print(f"\tname: {comp.name}")
        print(f"\ttype: {comp.type}")
        print(f"\tplugin name: {comp.plugin_name}")
        print(f"\tstate: id={comp.state.id} label={comp.state.label}")
        print("\tcommand interfaces")
        for itf in comp.command_interfaces:
            avail = "[available]" if itf.is_available else "[unavailable]"
            claimed = "[claimed]" if itf.is_claimed else "[unclaimed]"
            print(f"\t\t{itf.name} {avail} {claimed}")
        if verbose:
            print("\tstate interfaces")
            for itf in comp.state_interfaces:
                print(f"\t\t{itf.name} {'[available]' if itf.is_available else '[unavailable]'}")


def _print_hardware_interfaces(system: System, verbose: bool) -> None:
    itfs = system.controller_manager.list_hardware_interfaces()
    print("command interfaces")
    for c in itfs.command_interfaces:
        dtype = f" [{c.data_type}]" if verbose else ""
        if c.is_available:
            print(f"\t{c.name}{dtype} [available] {'[claimed]' if c.is_claimed else '[unclaimed]'}")
        else:
            print(f"\t{c.name}{dtype} [unavailable] [unclaimed]")
    print("state interfaces")
    for s in itfs.state_interfaces:
        print(f"\t{s.name}{f' [{s.data_type}]' if verbose else ''}")


def control(line: str) -> None:
    """Run one ``%control`` command line (also callable from plain Python)."""
    try:
        args = _control_parser().parse_args(shlex.split(line))
        if args.verb is None:
            raise _UsageError(f"%control needs a verb: {_VERBS}")
        system = _system(args.system, args.controller_manager)
        cm = system.controller_manager
        verb = args.verb
        if verb == "list_controllers":
            _print_controllers(system, args.verbose)
        elif verb == "list_hardware_components":
            _print_hardware_components(system, args.verbose)
        elif verb == "list_hardware_interfaces":
            _print_hardware_interfaces(system, args.verbose)
        elif verb == "list_controller_types":
            for type_name, base in cm.list_controller_types():
                print(f"{type_name:70s} {base}")
        elif verb == "load_controller":
            if args.name in cm.controllers:
                print(f"Controller : {args.name} already loaded, skipping load_controller!")
            else:
                if args.param_file is not None and not Path(args.param_file).is_file():
                    raise _UsageError(f"Controller parameter file : {args.param_file} does not exist, Aborting!")
                cm.load_controller(args.name, param_file=args.param_file)
                print(f"Successfully loaded controller {args.name}")
            if args.set_state:
                cm.configure_controller(args.name)
                if args.set_state == "active":
                    cm.switch_controllers(activate=[args.name], strictness="strict")
                print(f"Successfully set controller {args.name} to {args.set_state}")
        elif verb == "set_controller_state":
            cm.set_controller_state(args.name, args.state)
            print(f"Successfully set controller {args.name} to {args.state}")
        elif verb == "switch_controllers":
            result = cm.switch_controllers(
                activate=args.activate, deactivate=args.deactivate,
                strictness="strict" if args.strict else "best_effort", activate_asap=args.activate_asap,
            )
            for line_ in result.skipped:
                print(f"Skipped: {line_}")
            print("Successfully switched controllers")
        elif verb == "unload_controller":
            cm.unload_controller(args.name)
            print(f"Successfully unloaded controller {args.name}")
        elif verb == "set_hardware_component_state":
            if cm.set_hardware_component_state(args.name, args.state):
                print(f"Successfully set hardware component {args.name} to {args.state}")
            else:
                state = system.resource_manager.get_component(args.name).get_lifecycle_state().label
                print(f"Error: hardware component {args.name} did not reach {args.state}; it is {state}")
        elif verb == "view_controller_chains":
            print(cm.view_controller_chains(), end="")
        elif verb == "statistics":
            _print_statistics(system, not args.no_execution_time)
        elif verb == "why":
            activate, deactivate = _why_lists(cm, args)
            print(cm.explain_switch(activate=activate, deactivate=deactivate))
    except (_UsageError, RRBotWorkshopError, KeyError, ValueError) as exc:
        text = exc.args[0] if isinstance(exc, KeyError) and exc.args else str(exc)
        print(f"Error: {text}".rstrip())


# ===================================================================== %topic
def _topic_parser() -> _Parser:
    p = _Parser(prog="%topic", add_help=False)
    p.add_argument("--system", default=None)
    sub = p.add_subparsers(dest="verb", parser_class=_Parser)
    lst = sub.add_parser("list", add_help=False)
    lst.add_argument("-t", "--show-types", action="store_true")
    echo = sub.add_parser("echo", add_help=False)
    echo.add_argument("topic")
    echo.add_argument("--once", action="store_true")
    echo.add_argument("-n", type=int, default=10, help="how many of the latest messages (default 10)")
    info = sub.add_parser("info", add_help=False)
    info.add_argument("topic")
    info.add_argument("-v", "--verbose", action="store_true")
    hz = sub.add_parser("hz", add_help=False)
    hz.add_argument("topic")
    hz.add_argument("-w", "--window", type=int, default=10000, help="messages the statistics use (default 10000)")
    hz.add_argument("--duration", type=float, default=1.0, help="simulated seconds to listen for (default 1.0)")
    pub = sub.add_parser("pub", add_help=False)
    pub.add_argument("topic")
    pub.add_argument("type")
    pub.add_argument("values", nargs="?", default="{}")
    pub.add_argument("--once", "-1", action="store_true")
    return p


_TOPIC_VERBS = (
    "list [-t], echo <topic> [--once] [-n N], info <topic> [-v], hz <topic> [--duration S] [-w N], "
    "pub <topic> <type> '<yaml>'"
)


def _unknown_topic(system: System, name: str) -> str:
    close = system.bus.similar_topics(name)
    return f"Unknown topic '{name}'" + (f"; did you mean '{close[0]}'?" if close else "")


def _print_topic_info(system: System, name: str, verbose: bool) -> None:
    """``ros2 topic info [-v]``: the type, then the count (and with -v the node) of publishers and subscriptions."""
    bus = system.bus
    type_name = bus.topic_type_name(name)
    if type_name is None:
        print(_unknown_topic(system, name))
        return
    endpoints = [("Publisher", "PUBLISHER", bus.publisher_owners(name)),
                 ("Subscription", "SUBSCRIPTION", bus.subscription_owners(name))]
    print(f"Type: {type_name}")
    for title, kind, owners in endpoints:
        if not verbose:
            print(f"{title} count: {len(owners)}")
            continue
        print(f"\n{title} count: {len(owners)}\n")
        for owner in owners:
            print(f"Node name: {owner or '_anonymous'}")
            print("Node namespace: /")
            print(f"Topic type: {type_name}")
            print(f"Endpoint type: {kind}\n")


def _print_topic_hz(system: System, name: str, duration: float, window: int) -> None:
    """``ros2 topic hz``, on simulated time: listen for ``duration`` [s] of spinning, print the rate."""
    if not duration > 0:
        raise _UsageError(f"--duration must be > 0 simulated seconds, got {duration}")
    if system.bus.topic_type_name(name) is None:
        print(_unknown_topic(system, name))
        return
    times: list[float] = []
    subscription = system.bus.create_subscription(None, name, lambda _msg: times.append(system.time), owner="_ros2cli_hz")
    try:
        system.spin(duration)
    finally:
        subscription.destroy()
    times = times[-(max(window, 2)):]
    if len(times) < 2:
        print(f"WARNING: {len(times)} message(s) on '{name}' in {duration:g} s of simulated time: no rate to measure")
        return
    gaps = [b - a for a, b in zip(times, times[1:], strict=False)]
    mean = sum(gaps) / len(gaps)
    std = (sum((g - mean) ** 2 for g in gaps) / len(gaps)) ** 0.5
    rate = 1.0 / mean if mean > 0 else float("inf")
    print(f"average rate: {rate:.3f}")
    print(f"\tmin: {min(gaps):.3f}s max: {max(gaps):.3f}s std dev: {std:.5f}s window: {len(times)}")
    print(f"(measured on simulated time: the system spun {duration:g} s, until t = {system.time:.2f} s)")


def topic(line: str) -> None:
    """Run one ``%topic`` command line: ``list``, ``echo``, ``info``, ``hz`` or ``pub``, as ``ros2 topic`` does.

    ``hz`` spins the system for ``--duration`` seconds of simulated time (default 1 s) and reports the
    rate of the messages received meanwhile: simulated time moves only while the system spins.
    """
    try:
        args = _topic_parser().parse_args(shlex.split(line))
        if args.verb is None:
            raise _UsageError(f"%topic needs a verb: {_TOPIC_VERBS}")
        system = _system(args.system)
        if args.verb == "list":
            for name, type_name in system.bus.topic_names_and_types():
                print(f"{name} [{type_name}]" if args.show_types else name)
        elif args.verb == "info":
            _print_topic_info(system, args.topic, args.verbose)
        elif args.verb == "hz":
            _print_topic_hz(system, args.topic, args.duration, args.window)
        elif args.verb == "echo":
            history = system.history(args.topic)
            if not history:
                print(f"WARNING: no message has been published on '{args.topic}' yet")
                return
            for msg in history[-1:] if args.once else history[-max(args.n, 1):]:
                print(message_to_yaml(msg))
                print("---")
        elif args.verb == "pub":
            cls = message_type(args.type)
            try:
                data = yaml.safe_load(args.values)
            except yaml.YAMLError as exc:
                raise MessageError(f"values are not valid YAML: {exc}") from None
            msg = message_from_dict(cls, data, now=system.time)  # header: auto, stamp: now -> the system's clock
            system.publish(args.topic, msg)
            print("publisher: beginning loop")
            print(f"publishing #1: {msg!r}")
    except (_UsageError, RRBotWorkshopError, KeyError, ValueError) as exc:
        text = exc.args[0] if isinstance(exc, KeyError) and exc.args else str(exc)
        print(f"Error: {text}".rstrip())


def load_ipython_extension(ipython: Any) -> None:
    """Register ``%control``, ``%topic`` and ``%%pytest`` (see :func:`rrbot_workshop.course.controller_tests.pytest_cell`),
    and short tracebacks for library errors, in an IPython shell; on Linux, fork the shell's clean copy that self-checks
    grade in (see :mod:`rrbot_workshop.course.grading.kernel_fork`), before any of the learner's code runs."""
    from rrbot_workshop.course.controller_tests import pytest_cell
    from rrbot_workshop.course.grading import kernel_fork
    from rrbot_workshop.course.tracebacks import register

    hidden = getattr(ipython, "user_ns_hidden", {})
    mine = [name for name in getattr(ipython, "user_ns", {}) if name not in hidden and not name.startswith("_")]
    if getattr(ipython, "kernel", None) is not None and not mine:
        kernel_fork.start()  # a notebook's kernel, and nothing of the learner's defined in it yet

    ipython.register_magic_function(control, "line", "control")
    ipython.register_magic_function(topic, "line", "topic")
    ipython.register_magic_function(pytest_cell, "cell", "pytest")
    register(ipython)
