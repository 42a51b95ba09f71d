"""Hostile inputs to the library's public API, as a learner meets it: :data:`CASES` (see :mod:`hostile_api`).

Each case is one call with one bad input and what Jazzy (or Python's own rules, where ROS has no say) does with it.
Run ``python tests/unit/hostile_api_cases.py`` to print every outcome that is not good and the tally.
"""

from __future__ import annotations

import math
from typing import Any

from hostile_api import ACCEPT, EITHER, REFUSE, Case, Env

import rrbot_workshop as rw
from rrbot_workshop.exceptions import (
    ControllerError,
    ControllerNotFound,
    DescriptionError,
    HardwareError,
    MessageError,
    ParameterError,
    RRBotWorkshopError,
    SwitchError,
)
from rrbot_workshop.msgs import (
    Float64MultiArray,
    JointState,
    JointTrajectory,
    JointTrajectoryPoint,
)

__all__ = ["CASES"]

NAN, INF = math.nan, math.inf
FWD = "/forward_position_controller/commands"
JTC = "/joint_trajectory_controller/joint_trajectory"
JOINTS = ["joint1", "joint2"]

CASES: list[Case] = []


def case(area: str, label: str, call: Any, expect: str = REFUSE, names: tuple[str, ...] = (), **kw: Any) -> None:
    CASES.append(Case(area, label, call, expect, names, **kw))


# ---------------------------------------------------------------- bringup
def _bringup(**kw: Any) -> Any:
    def call(env: Env) -> Any:
        args: dict[str, Any] = {"description": "rrbot", "controllers": "rrbot_controllers.yaml"}
        args.update(kw)
        return env.keep(rw.bringup(**args))
    return call


for label, value in [("None", None), ("an int", 3), ("an empty string", ""), ("a list", ["rrbot"]),
                     ("a dict", {"a": 1}), ("an unknown package", "no_such_robot_pkg"),
                     ("URDF text without <ros2_control>", "<robot name='r'><link name='a'/></robot>"),
                     ("unclosed XML", "<robot name='r'><link name='a'>"), ("bytes", b"<robot/>")]:
    dnames = {"URDF text without <ros2_control>": ("ros2_control",), "unclosed XML": ("XML",),
              "an unknown package": ("no_such_robot_pkg",)}.get(label, ("description",))
    case("bringup", f"description={label}", _bringup(description=value, controllers=None), names=dnames,
         error=DescriptionError if label not in ("an int", "a list", "a dict", "None", "bytes") else RRBotWorkshopError)
for label, value in [("an int", 3), ("a list", ["a"]), ("an empty string", ""), ("a missing file", "nope.yaml"),
                     ("YAML of a list", "- 1\n- 2\n"), ("controller_manager not a mapping", {"controller_manager": 3}),
                     ("update_rate a string", {"controller_manager": {"ros__parameters": {"update_rate": "fast"}}}),
                     ("update_rate 0", {"controller_manager": {"ros__parameters": {"update_rate": 0}}}),
                     ("update_rate negative", {"controller_manager": {"ros__parameters": {"update_rate": -100}}}),
                     ("update_rate NaN", {"controller_manager": {"ros__parameters": {"update_rate": NAN}}}),
                     ("update_rate huge", {"controller_manager": {"ros__parameters": {"update_rate": 10**12}}}),
                     ("a controller type not a string",
                      {"controller_manager": {"ros__parameters": {"update_rate": 100, "fwd": {"type": 3}}}}),
                     ("an unknown controller type",
                      {"controller_manager": {"ros__parameters": {"update_rate": 100, "fwd": {"type": "x/Y"}}}})]:
    names = ("update_rate",) if "update_rate" in label else ("type",) if "type" in label else ("controllers",)
    if label in ("a missing file",):
        names = ("nope.yaml",)
    odd = {"update_rate huge": "Jazzy takes any positive update_rate; a spin is bounded by MAX_SPIN_CYCLES",
           "an unknown controller type": "Jazzy reads the type only when the controller is loaded"}
    case("bringup", f"controllers={label}", _bringup(controllers=value), names=names,
         expect=EITHER if label in odd else REFUSE, why=odd.get(label, ""))
for label, value, names, err in [
        ("a string", "no_such_controller", ("no_such_controller",), ControllerError),
        ("[None]", [None], ("spawn",), RRBotWorkshopError),
        ("an unknown controller", ["no_such_controller"], ("no_such_controller",), ControllerError),
        ("a duplicate", ["joint_state_broadcaster", "joint_state_broadcaster"], ("joint_state_broadcaster",),
         RRBotWorkshopError),
        ("an int", 3, ("spawn",), RRBotWorkshopError)]:
    case("bringup", f"spawn={label}", _bringup(spawn=value), names=names, error=err)
case("bringup", "spawn and inactive name one controller",
     _bringup(spawn=["forward_position_controller"], inactive=["forward_position_controller"]),
     names=("forward_position_controller",))
case("bringup", "inactive=[3]", _bringup(inactive=[3]), names=("inactive",))
case("bringup", "clock='bogus'", _bringup(clock="bogus"), names=("clock",))
case("bringup", "clock=3", _bringup(clock=3), names=("clock",))
case("bringup", "hardware_initial_state of an unknown component", _bringup(hardware_initial_state={"nope": "active"}),
     names=("nope",))
case("bringup", "hardware_initial_state 'bogus'", _bringup(hardware_initial_state={"rrbot": "bogus"}),
     names=("bogus",))
case("bringup", "hardware_initial_state a list", _bringup(hardware_initial_state=["rrbot"]),
     names=("hardware_initial_state",))
case("bringup", "hardware_initial_state None value", _bringup(hardware_initial_state={"rrbot": None}),
     names=("rrbot",))
case("bringup", "name=3", _bringup(name=3), names=("name",))
case("bringup", "name=''", _bringup(name=""), names=("name",))
case("bringup", "namespace 'a b'", _bringup(namespace="a b"), names=("namespace",))
case("bringup", "namespace=3", _bringup(namespace=3), names=("namespace",))
case("bringup", "mock_hardware='bogus'", _bringup(mock_hardware="bogus"), names=("mock_hardware",))
case("bringup", "xacro_args=3", _bringup(xacro_args=3), names=("xacro_args",))
case("bringup", "xacro_args an unknown arg", _bringup(xacro_args={"no_such_arg": "1"}), names=("no_such_arg",),
     expect=EITHER, why="xacro accepts an argument the file does not declare")
case("bringup", "xacro_args a non-string key", _bringup(xacro_args={3: "1"}), names=("xacro_args",))
case("bringup", "launch_args=[]", _bringup(launch_args=["a"]), names=("launch_args",))
case("bringup", "controller_types value 3", _bringup(controller_types={"fwd": 3}), names=("fwd",))
case("bringup", "package_path=3", _bringup(package_path=3), names=("package_path",))
case("bringup", "package_path a missing folder", _bringup(package_path=["/no/such/folder"]), names=("/no/such/folder",),
     expect=EITHER, why="ROS ignores a missing folder on the package path")


# ---------------------------------------------------------------- System: time
def _sys(fn: Any) -> Any:
    return lambda env: fn(env.system)


for label, value in [("None", None), ("a string", "1"), ("NaN", NAN), ("inf", INF), ("-1", -1.0), ("a list", [1]),
                     ("huge", 1e12), ("True", True)]:
    case("System.spin", f"seconds={label}", _sys(lambda s, v=value: s.spin(v)), names=("seconds",), system=True)
case("System.spin", "seconds=0", _sys(lambda s: s.spin(0.0)), expect=ACCEPT, why="spinning no time does nothing")
for label, value in [("-1", -1), ("1.5", 1.5), ("'3'", "3"), ("None", None), ("huge", 10**12), ("NaN", NAN)]:
    case("System.spin_cycles", f"n={label}", _sys(lambda s, v=value: s.spin_cycles(v)), names=("n",), system=True)
case("System.spin_until", "predicate None", _sys(lambda s: s.spin_until(None, 1.0)), names=("predicate",),
     system=True)
case("System.spin_until", "predicate 3", _sys(lambda s: s.spin_until(3, 1.0)), names=("predicate",), system=True)
for label, value in [("NaN", NAN), ("inf", INF), ("-1", -1.0), ("None", None), ("a string", "1"), ("huge", 1e12)]:
    case("System.spin_until", f"timeout={label}", _sys(lambda s, v=value: s.spin_until(lambda: False, v)),
         names=("timeout",), system=True)
case("System.spin_until", "a predicate that raises", _sys(lambda s: s.spin_until(lambda: 1 / 0, 0.1)),
     expect=EITHER, user_error=True, error=ZeroDivisionError, why="the learner's predicate's own error reaches them")
for label, kw in [("real_time_factor=0", {"real_time_factor": 0}), ("real_time_factor=-1", {"real_time_factor": -1}),
                  ("real_time_factor=NaN", {"real_time_factor": NAN}), ("tick=0", {"tick": 0}),
                  ("tick=NaN", {"tick": NAN}), ("real_time_factor='fast'", {"real_time_factor": "fast"})]:
    name = next(iter(kw))

    def _bg(s: Any, kw: dict[str, Any] = kw) -> Any:
        try:
            return s.spin_in_background(**kw)
        finally:
            s.stop_background()
    case("System.spin_in_background", label, _sys(_bg), names=(name,), system=True)
case("System.add_spin_listener", "None", _sys(lambda s: s.add_spin_listener(None)), names=("listener",), system=True)
case("System.add_spin_listener", "3", _sys(lambda s: s.add_spin_listener(3)), names=("listener",), system=True)


def _raising_listener(s: Any) -> Any:
    s.add_spin_listener(lambda *a: 1 / 0)
    s.spin(0.05)
    return s.controller_manager.list_controllers()


case("System.add_spin_listener", "a listener that raises, then spin", _sys(_raising_listener), expect=ACCEPT,
     user_error=True, why="the learner's listener is logged; the system keeps running")


# ---------------------------------------------------------------- topics
def _pub(topic: str, msg: Any, spin: float = 0.05) -> Any:
    def call(env: Env) -> Any:
        env.system.publish(topic, msg)
        env.system.spin(spin)
    return call


case("System.publish", "topic None", _sys(lambda s: s.publish(None, Float64MultiArray(data=[0.0, 0.0]))),
     names=("topic",), error=MessageError, system=True)
case("System.publish", "msg None", _sys(lambda s: s.publish(FWD, None)), names=("None",), error=MessageError,
     system=True)
case("System.publish", "a JointState on the forward commands",
     _sys(lambda s: s.publish(FWD, JointState(name=JOINTS))), names=("Float64MultiArray",), error=MessageError,
     system=True)
case("System.publish", "a dict as message", _sys(lambda s: s.publish(FWD, {"data": [0.1, 0.1]})),
     names=("Float64MultiArray",), error=MessageError, system=True)
case("System.publish", "a list as message", _sys(lambda s: s.publish(FWD, [0.1, 0.1])),
     names=("Float64MultiArray",), error=MessageError, system=True)
for label, data, names in [("data None", None, ("data",)), ("data strings", ["a", "b"], ("data",)),
                           ("data a string", "0.1", ("data",)), ("data nested lists", [[0.1], [0.2]], ("data",)),
                           ("data of dicts", [{}, {}], ("data",))]:
    case("System.publish", f"forward command {label}", _pub(FWD, Float64MultiArray(data=data)), names=names,
         error=MessageError, system=True)
case("forward command", "one value for two joints", _pub(FWD, Float64MultiArray(data=[0.1])), by_log=True,
     names=("data",))
case("forward command", "three values for two joints", _pub(FWD, Float64MultiArray(data=[0.1, 0.2, 0.3])),
     by_log=True, names=("data",))
case("forward command", "no values", _pub(FWD, Float64MultiArray(data=[])), by_log=True, names=("data",))
case("forward command", "NaN", _pub(FWD, Float64MultiArray(data=[NAN, 0.0])), expect=EITHER,
     why="Jazzy's forward_command_controller writes NaN through; mock hardware keeps the last valid value")
case("forward command", "inf", _pub(FWD, Float64MultiArray(data=[INF, 0.0])), expect=EITHER,
     why="Jazzy writes it through; the URDF limits clamp it when enforced")
case("forward command", "huge length", _pub(FWD, Float64MultiArray(data=[0.0] * 100_000)), by_log=True,
     names=("data",))


def _traj(joint_names: Any = None, points: Any = None) -> JointTrajectory:
    return JointTrajectory(joint_names=list(JOINTS) if joint_names is None else joint_names,
                           points=[JointTrajectoryPoint(positions=[0.5, 0.5], time_from_start=1.0)]
                           if points is None else points)


def _to_jtc(env: Env) -> None:
    env.cm.switch_controllers(activate=["joint_trajectory_controller"], deactivate=["forward_position_controller"])


def _jtc(msg: Any) -> Any:
    def call(env: Env) -> Any:
        env.system.publish(JTC, msg)
        env.system.spin(0.05)
    return call


P = JointTrajectoryPoint
for label, msg, names in [
        ("no joint names", _traj(joint_names=[]), ("joint",)),
        ("an unknown joint", _traj(joint_names=["joint1", "elbow"]), ("elbow",)),
        ("a duplicate joint", _traj(joint_names=["joint1", "joint1"]), ("joint1",)),
        ("positions one short", _traj(points=[P(positions=[0.5], time_from_start=1.0)]), ("positions",)),
        ("positions one too many", _traj(points=[P(positions=[0.5, 0.5, 0.5], time_from_start=1.0)]),
         ("positions",)),
        ("velocities of the wrong length", _traj(points=[P(positions=[0.5, 0.5], velocities=[0.1],
                                                           time_from_start=1.0)]), ("velocit",)),
        ("accelerations of the wrong length", _traj(points=[P(positions=[0.5, 0.5], accelerations=[0.1],
                                                              time_from_start=1.0)]), ("accelerations",)),
        ("effort given", _traj(points=[P(positions=[0.5, 0.5], effort=[1.0, 1.0], time_from_start=1.0)]),
         ("effort",)),
        ("times not increasing", _traj(points=[P(positions=[0.1, 0.1], time_from_start=2.0),
                                               P(positions=[0.2, 0.2], time_from_start=1.0)]), ("time_from_start",)),
        ("two points at one time", _traj(points=[P(positions=[0.1, 0.1], time_from_start=1.0),
                                                 P(positions=[0.2, 0.2], time_from_start=1.0)]),
         ("time_from_start",)),
        ("NaN position", _traj(points=[P(positions=[NAN, 0.5], time_from_start=1.0)]), ("positions",)),
        ("inf position", _traj(points=[P(positions=[INF, 0.5], time_from_start=1.0)]), ("positions",)),
        ("NaN time_from_start", _traj(points=[P(positions=[0.5, 0.5], time_from_start=NAN)]), ("time_from_start",)),
        ("negative time_from_start", _traj(points=[P(positions=[0.5, 0.5], time_from_start=-1.0)]),
         ("time_from_start",)),
]:
    case("joint trajectory", label, _jtc(msg), by_log=True, names=names, setup=_to_jtc)
case("joint trajectory", "no points", _jtc(_traj(points=[])), expect=ACCEPT, setup=_to_jtc,
     why="Jazzy takes an empty trajectory as a cancel: the controller holds position")
for label, msg, names in [
        ("joint_names None", _traj(joint_names=None), ("joint_names",)),
        ("joint_names a string", JointTrajectory(joint_names="joint1", points=[]), ("joint_names",)),
        ("joint_names of ints", _traj(joint_names=[1, 2]), ("joint_names",)),
        ("points None", JointTrajectory(joint_names=list(JOINTS), points=None), ("points",)),
        ("points [None]", _traj(points=[None]), ("points",)),
        ("a point's positions None", _traj(points=[P(positions=None, time_from_start=1.0)]), ("positions",)),
        ("a point's positions strings", _traj(points=[P(positions=["a", "b"], time_from_start=1.0)]),
         ("positions",)),
        ("a point's time_from_start a string", _traj(points=[P(positions=[0.5, 0.5], time_from_start="1")]),
         ("time_from_start",)),
        ("a point's time_from_start None", _traj(points=[P(positions=[0.5, 0.5], time_from_start=None)]),
         ("time_from_start",)),
        ("header None", JointTrajectory(header=None, joint_names=list(JOINTS),
                                        points=[P(positions=[0.5, 0.5], time_from_start=1.0)]), ("header",)),
]:
    if label == "joint_names None":
        msg = JointTrajectory(joint_names=None, points=[P(positions=[0.5, 0.5], time_from_start=1.0)])
    case("joint trajectory", label, _jtc(msg), names=names, error=MessageError, setup=_to_jtc, system=True)
case("joint trajectory", "10000 points", _jtc(_traj(points=[P(positions=[0.0, 0.0], time_from_start=0.01 * (k + 1))
                                                              for k in range(10_000)])), setup=_to_jtc,
     expect=EITHER, why="a long trajectory is valid")


# ---------------------------------------------------------------- controller manager
def _cm(fn: Any) -> Any:
    return lambda env: fn(env.cm)


for method in ("load_controller", "configure_controller", "unload_controller", "cleanup_controller"):
    for label, value, err, names in [("None", None, ControllerError, ("name",)), ("3", 3, ControllerError, ("name",)),
                                     ("''", "", ControllerError, ("name",)),
                                     ("an unknown name", "no_such_controller", ControllerError,
                                      ("no_such_controller",)),
                                     ("a name with a space", "my controller", ControllerError, ("my controller",))]:
        case(f"cm.{method}", label, _cm(lambda cm, m=method, v=value: getattr(cm, m)(v)), names=names, error=err,
             system=True)
case("cm.load_controller", "twice", _cm(lambda cm: cm.load_controller("forward_position_controller")),
     names=("forward_position_controller",), error=ControllerError, system=True)
case("cm.unload_controller", "an active one", _cm(lambda cm: cm.unload_controller("forward_position_controller")),
     names=("forward_position_controller",), error=ControllerError, system=True)
case("cm.configure_controller", "an active one",
     _cm(lambda cm: cm.configure_controller("forward_position_controller")),
     names=("forward_position_controller",), error=ControllerError, system=True)
for label, kw, names, err in [
        ("activate a string", {"activate": "joint_trajectory_controller"}, ("activate",), ControllerError),
        ("activate [None]", {"activate": [None]}, ("activate",), ControllerError),
        ("activate 3", {"activate": 3}, ("activate",), ControllerError),
        ("deactivate a dict", {"deactivate": {"a": 1}}, ("deactivate",), ControllerError),
        ("activate an unknown", {"activate": ["nope"]}, ("nope",), ControllerError),
        ("activate a duplicate", {"activate": ["joint_trajectory_controller", "joint_trajectory_controller"],
                                  "deactivate": ["forward_position_controller"]},
         ("joint_trajectory_controller",), SwitchError),
        ("activate and deactivate one controller", {"activate": ["joint_trajectory_controller"],
                                                    "deactivate": ["joint_trajectory_controller"]},
         ("joint_trajectory_controller",), SwitchError),
        ("strictness 'bogus'", {"activate": [], "strictness": "bogus"}, ("strictness",), ControllerError),
        ("strictness 7", {"activate": [], "strictness": 7}, ("strictness",), ControllerError),
        ("timeout NaN", {"activate": [], "timeout": NAN}, ("timeout",), RRBotWorkshopError),
        ("timeout 'x'", {"activate": [], "timeout": "x"}, ("timeout",), RRBotWorkshopError),
        ("activate_asap 'yes'", {"activate": [], "activate_asap": "yes"}, ("activate_asap",), RRBotWorkshopError),
        ("a claimed interface", {"activate": ["joint_trajectory_controller"]}, ("joint_trajectory_controller",),
         SwitchError),
]:
    odd = label in ("activate a duplicate", "activate and deactivate one controller")
    case("cm.switch_controllers", label, _cm(lambda cm, kw=kw: cm.switch_controllers(**kw)), names=names,
         error=err if label not in ("activate an unknown",) else ControllerError, system=True,
         expect=EITHER if odd else REFUSE,
         why="Jazzy's best-effort switch drops what cannot be done (a repeat, deactivating an inactive one)"
         if odd else "")
case("cm.set_controller_state", "'bogus'",
     _cm(lambda cm: cm.set_controller_state("joint_trajectory_controller", "bogus")), names=("bogus",),
     system=True)
case("cm.set_controller_state", "None", _cm(lambda cm: cm.set_controller_state("joint_trajectory_controller", None)),
     names=("state",), system=True)
case("cm.set_controller_state", "unknown name", _cm(lambda cm: cm.set_controller_state("nope", "active")),
     names=("nope",), error=ControllerNotFound, system=True)
case("cm.set_hardware_component_state", "'bogus'", _cm(lambda cm: cm.set_hardware_component_state("rrbot", "bogus")),
     names=("bogus",), system=True)
case("cm.set_hardware_component_state", "an unknown component",
     _cm(lambda cm: cm.set_hardware_component_state("nope", "active")), names=("nope",), system=True)
case("cm.set_hardware_component_state", "None name",
     _cm(lambda cm: cm.set_hardware_component_state(None, "active")), names=("name",), system=True)
case("cm.set_hardware_component_state", "state 3", _cm(lambda cm: cm.set_hardware_component_state("rrbot", 3)),
     names=("state",), system=True)
case("cm.default_strictness", "= 'bogus'", _cm(lambda cm: setattr(cm, "default_strictness", "bogus")),
     names=("strictness",), system=True)
case("cm.handle_exceptions", "= 'yes'", _cm(lambda cm: setattr(cm, "handle_exceptions", "yes")),
     names=("handle_exceptions",), system=True)
case("cm.get_controller", "an unknown name", _cm(lambda cm: cm.get_controller("nope")), names=("nope",),
     error=ControllerNotFound, system=True)
case("cm.add_cycle_hook", "None", _cm(lambda cm: cm.add_cycle_hook(None)), names=("hook",), system=True)
case("System.call_service", "an unknown service", _sys(lambda s: s.call_service("/controller_manager/nope")),
     names=("nope",), system=True)
case("System.call_service", "name None", _sys(lambda s: s.call_service(None)), names=("service",), system=True)
case("System.call_service", "list_controllers with a wrong request",
     _sys(lambda s: s.call_service("/controller_manager/switch_controller", {"activate_controllers": 3})),
     names=("activate_controllers",), system=True)
case("System.spawn", "a string", _sys(lambda s: s.spawn("joint_trajectory_controller", load_only=True)), expect=ACCEPT,
     why="spawn takes one name or several, as the spawner does")
case("System.spawn", "[None]", _sys(lambda s: s.spawn([None])), names=("controllers",), system=True)
case("System.spawn", "an unknown", _sys(lambda s: s.spawn(["nope"])), names=("nope",), system=True)
case("System.unspawn", "an unknown", _sys(lambda s: s.unspawn(["nope"])), names=("nope",), system=True)
case("System.unspawn", "None", _sys(lambda s: s.unspawn(None)), names=("controllers",), system=True)


# ---------------------------------------------------------------- parameters
def _set(values: Any) -> Any:
    def call(env: Env) -> Any:
        env.cm.get_controller("joint_trajectory_controller").get_node().set_parameters(values)
    return call


def _params(values: Any) -> Any:
    """A case: ``values`` set and the controller cleaned up (the setup); the call configures it."""
    def setup(env: Env) -> None:
        _set(values)(env)
        env.cm.cleanup_controller("joint_trajectory_controller")
    return {"call": lambda env: env.cm.configure_controller("joint_trajectory_controller"), "setup": setup,
            "system": True}


def _pcase(label: str, values: Any, names: tuple[str, ...]) -> None:
    spec = _params(values)
    case("set_parameters", label, spec.pop("call"), names=names, error=ParameterError, **spec)


case("set_parameters", "None", _set(None), names=("values",), error=ParameterError, system=True)
case("set_parameters", "a list", _set(["joints"]), names=("values",), error=ParameterError, system=True)
case("set_parameters", "a key 3", _set({3: 1.0}), names=("3",), error=ParameterError, system=True)
case("set_parameters", "a key ''", _set({"": 1.0}), names=("parameter",), error=ParameterError, system=True)
case("set_parameters", "a key 'a..b'", _set({"a..b": 1.0}), names=("a..b",), error=ParameterError, system=True)
case("set_parameters", "through a value", _set({"joints.x": 1.0}), names=("joints",), error=ParameterError,
     system=True)
_pcase("joints a string, then configure", {"joints": "joint1"}, ("joints",))
_pcase("joints empty, then configure", {"joints": []}, ("joints",))
_pcase("joints duplicate, then configure", {"joints": ["joint1", "joint1"]}, ("joints",))
_pcase("an unknown command interface, then configure", {"command_interfaces": ["torque"]}, ("command_interfaces",))
_pcase("goal_time NaN, then configure", {"constraints.goal_time": NAN}, ("goal_time",))
_pcase("goal_time 'x', then configure", {"constraints.goal_time": "x"}, ("goal_time",))
_pcase("joints of ints, then configure", {"joints": [1, 2]}, ("joints",))


# ---------------------------------------------------------------- description
def _desc(text: Any) -> Any:
    return lambda env: rw.description.parse_ros2_control(text)


def _urdf(ros2_control: str, joints: str = "") -> str:
    joints = joints or ("<joint name='joint1' type='revolute'><parent link='a'/><child link='b'/>"
                        "<limit lower='-1' upper='1' velocity='1' effort='1'/></joint>")
    return (f"<robot name='r'><link name='a'/><link name='b'/>{joints}"
            f"<ros2_control name='hw' type='system'><hardware><plugin>mock_components/GenericSystem</plugin>"
            f"</hardware>{ros2_control}</ros2_control></robot>")


_AT_LOAD = ("an initial_value 'abc'", "no <hardware>", "a hardware <plugin> empty")
_YAML = {"controller_manager": {"ros__parameters": {"update_rate": 100}}}
_J = "<joint name='joint1'><command_interface name='position'/><state_interface name='position'/></joint>"
for label, text, names in [
        ("None", None, ("urdf",)), ("an int", 3, ("urdf",)), ("empty", "", ("urdf",)),
        ("not XML", "hello", ("urdf",)), ("unclosed", "<robot name='r'>", ("XML",)),
        ("a list", ["<robot/>"], ("urdf",)),
        ("deeply nested", "<robot name='r'>" + "<a>" * 100_000 + "</a>" * 100_000 + "</robot>", ("ros2_control",)),
        ("an entity expansion", "<?xml version='1.0'?><!DOCTYPE r [<!ENTITY a 'aaaaaaaaaa'>"
                                "<!ENTITY b '&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;'><!ENTITY c '&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;'>"
                                "<!ENTITY d '&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;'><!ENTITY e '&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;'>"
                                "<!ENTITY f '&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;'><!ENTITY g '&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;'>"
                                "]><robot name='r'>&g;</robot>", ("entit",)),
        ("a joint of no URDF joint", _urdf(_J.replace("joint1", "elbow")), ("elbow",)),
        ("a duplicate joint", _urdf(_J + _J), ("joint1",)),
        ("a duplicate interface", _urdf("<joint name='joint1'><command_interface name='position'/>"
                                        "<command_interface name='position'/></joint>"), ("position",)),
        ("an initial_value 'abc'", _urdf("<joint name='joint1'><state_interface name='position'>"
                                         "<param name='initial_value'>abc</param></state_interface></joint>"),
         ("'abc'",)),
        ("an interface without a name", _urdf("<joint name='joint1'><command_interface/></joint>"), ("name",)),
        ("a joint without a name", _urdf("<joint><command_interface name='position'/></joint>"), ("name",)),
        ("no <hardware>", _urdf(_J).replace("<hardware><plugin>mock_components/GenericSystem</plugin></hardware>",
                                            ""), ("hardware",)),
        ("an unknown type", _urdf(_J).replace("type='system'", "type='robot'"), ("type",)),
        ("min above max", _urdf("<joint name='joint1'><command_interface name='position'><param name='min'>1"
                                "</param><param name='max'>-1</param></command_interface></joint>"), ("min",)),
        ("min 'abc'", _urdf("<joint name='joint1'><command_interface name='position'><param name='min'>abc"
                            "</param></command_interface></joint>"), ("min",)),
        ("a limit velocity 'fast'", _urdf(_J, "<joint name='joint1' type='revolute'><parent link='a'/><child link='b'/>"
                                              "<limit lower='-1' upper='1' velocity='fast' effort='1'/></joint>"),
         ("velocity",)),
        ("a limit lower above upper", _urdf(_J, "<joint name='joint1' type='revolute'><parent link='a'/>"
                                                "<child link='b'/><limit lower='1' upper='-1' velocity='1' "
                                                "effort='1'/></joint>"), ("lower",)),
        ("a limit velocity NaN", _urdf(_J, "<joint name='joint1' type='revolute'><parent link='a'/><child link='b'/>"
                                           "<limit lower='-1' upper='1' velocity='nan' effort='1'/></joint>"),
         ("velocity",)),
        ("a limit velocity negative", _urdf(_J, "<joint name='joint1' type='revolute'><parent link='a'/>"
                                                "<child link='b'/><limit lower='-1' upper='1' velocity='-1' "
                                                "effort='1'/></joint>"), ("velocity",)),
        ("rw_rate 'fast'", _urdf(_J).replace("type='system'", "type='system' rw_rate='fast'"), ("rw_rate",)),
        ("a hardware <plugin> empty", _urdf(_J).replace("mock_components/GenericSystem", ""), ("plugin",)),
        ("a 10 MB comment", _urdf(_J).replace("</robot>", "<!--" + "x" * 10_000_000 + "--></robot>"), ()),
]:
    expect = ACCEPT if label == "a 10 MB comment" else REFUSE
    if label in _AT_LOAD:  # Jazzy's parser takes it as text too; loading the hardware refuses it
        case("bringup", f"a description with {label}", _bringup(description=text, controllers=_YAML), names=names,
             error=HardwareError)
    elif label == "min 'abc'":  # Jazzy's joint limits reader skips it with a warning, as here
        case("bringup", f"a description with {label}", _bringup(description=text, controllers=_YAML), by_log=True,
             names=("min 'abc'",))
    else:
        case("parse_ros2_control", label, _desc(text), expect=expect, names=names, error=DescriptionError,
             why="a large comment is valid XML" if expect == ACCEPT else "")


def _xacro(text: Any, **mappings: Any) -> Any:
    def call(env: Env) -> Any:
        path = env.file("robot.urdf.xacro", text) if isinstance(text, str) else text
        return rw.description.process_xacro(path, **mappings)
    return call


def _xacro_path(path: str) -> Any:
    return lambda env: rw.description.process_xacro(path)


_X = "<robot name='r' xmlns:xacro='http://www.ros.org/wiki/xacro'>{}</robot>"
for label, source, mappings, names in [
        ("path None", None, {}, ("path",)), ("path 3", 3, {}, ("path",)),
        ("a missing file", "/no/such/file.xacro", {}, ("/no/such/file.xacro",)),
        ("a macro that calls itself", _X.format("<xacro:macro name='m'><xacro:m/></xacro:macro><xacro:m/>"), {},
         ("m",)),
        ("a file that includes itself", _X.format("<xacro:include filename='robot.urdf.xacro'/>"), {},
         ("robot.urdf.xacro",)),
        ("an unknown macro", _X.format("<xacro:nope/>"), {}, ("nope",)),
        ("an undefined property", _X.format("<link name='${nope}'/>"), {}, ("nope",)),
        ("a division by zero", _X.format("<link name='${1/0}'/>"), {}, ("1/0",)),
        ("a huge exponent", _X.format("<link name='${10**10**10}'/>"), {}, ("10**10**10",)),
        ("an import in an expression", _X.format("<link name='${__import__(\"os\").getcwd()}'/>"), {}, ("import",)),
        ("an unknown $(find)", _X.format("<xacro:include filename='$(find no_such_pkg)/a.xacro'/>"), {},
         ("no_such_pkg",)),
        ("an unknown $(arg)", _X.format("<link name='$(arg nope)'/>"), {}, ("nope",)),
        ("a mapping of a dict", _X.format("<xacro:arg name='a' default='1'/><link name='$(arg a)'/>"), {"a": {"x": 1}},
         ("a",)),
]:
    fn: Any = _xacro_path(source) if isinstance(source, str) and source.startswith("/") else _xacro(source, **mappings)
    odd = label == "a mapping of a dict"
    case("process_xacro", label, fn, names=names, error=DescriptionError, expect=EITHER if odd else REFUSE,
         why="a mapping's value is given to xacro as its text, as a launch file's str() would" if odd else "")


# ---------------------------------------------------------------- hardware parameters
def _hw(params: str, plugin: str = "mock_components/GenericSystem", joint: str = _J) -> Any:
    def call(env: Env) -> Any:
        text = _urdf(joint).replace("mock_components/GenericSystem", plugin).replace("</plugin>", "</plugin>" + params)
        yaml = {"controller_manager": {"ros__parameters": {"update_rate": 100}}}
        system = env.keep(rw.bringup(description=text, controllers=yaml))
        system.spin(0.02)
        return [h.state.label for h in system.controller_manager.list_hardware_components()]
    return call


for label, params, names in [
        ("calculate_dynamics 'maybe'", "<param name='calculate_dynamics'>maybe</param>", ("calculate_dynamics",)),
        ("mock_sensor_commands '2'", "<param name='mock_sensor_commands'>2</param>", ("mock_sensor_commands",)),
        ("position_state_following_offset 'abc'", "<param name='position_state_following_offset'>abc</param>",
         ("position_state_following_offset",)),
        ("position_state_following_offset NaN", "<param name='position_state_following_offset'>nan</param>",
         ("position_state_following_offset",)),
        ("disable_commands ''", "<param name='disable_commands'></param>", ("disable_commands",)),

]:
    case("GenericSystem parameters", label, _hw(params), names=names, error=HardwareError)
case("GenericSystem parameters", "custom_interface_with_following_offset unknown",
     _hw("<param name='position_state_following_offset'>0.1</param>"
         "<param name='custom_interface_with_following_offset'>nope</param>"), by_log=True, names=("'nope'",))


# ---------------------------------------------------------------- joint limits
def _limits(fn: Any) -> Any:
    return lambda env: fn(rw.joint_limits)


for label, params, names in [
        ("max_velocity NaN", {"joint_limits": {"joint1": {"has_velocity_limits": True, "max_velocity": NAN}}},
         ("max_velocity",)),
        ("max_velocity negative", {"joint_limits": {"joint1": {"has_velocity_limits": True, "max_velocity": -1.0}}},
         ("max_velocity",)),
        ("max_velocity a string", {"joint_limits": {"joint1": {"has_velocity_limits": True, "max_velocity": "x"}}},
         ("max_velocity",)),
        ("has_velocity_limits 'yes'", {"joint_limits": {"joint1": {"has_velocity_limits": "yes"}}},
         ("has_velocity_limits",)),
        ("min_position above max_position", {"joint_limits": {"joint1": {"has_position_limits": True,
                                                                         "min_position": 1.0,
                                                                         "max_position": -1.0}}},
         ("min_position",)),
        ("joint_limits a list", {"joint_limits": [1, 2]}, ("joint_limits",)),
        ("a joint's limits a number", {"joint_limits": {"joint1": 3}}, ("joint1",)),
]:
    case("joint_limits.get_joint_limits", label,
         _limits(lambda jl, p=params: jl.get_joint_limits("joint1", p, rw.joint_limits.JointLimits())),
         names=names, error=RRBotWorkshopError)
case("joint_limits.get_joint_limits", "joint name None",
     _limits(lambda jl: jl.get_joint_limits(None, {}, jl.JointLimits())), names=("joint",), error=RRBotWorkshopError)
case("joint_limits.load_joint_limits_yaml", "a missing file",
     _limits(lambda jl: jl.load_joint_limits_yaml("/no/such/limits.yaml")), names=("limits.yaml",),
     error=RRBotWorkshopError)
case("joint_limits.load_joint_limits_yaml", "path None",
     _limits(lambda jl: jl.load_joint_limits_yaml(None)), names=("path",), error=RRBotWorkshopError)


def _limiter(fn: Any) -> Any:
    def call(env: Env) -> Any:
        jl = rw.joint_limits
        limits = jl.JointLimits(has_velocity_limits=True, max_velocity=1.0)
        lim = jl.JointSaturationLimiter()
        lim.init(["joint1"], [limits])
        return fn(jl, lim)
    return call


case("JointSaturationLimiter.enforce", "dt NaN",
     _limiter(lambda jl, lim: lim.enforce(jl.JointControlInterfacesData("joint1", position=0.0),
                                          jl.JointControlInterfacesData("joint1", velocity=5.0), NAN)),
     names=("dt",), expect=EITHER, why="Jazzy's limiter refuses a non-positive dt by returning false")
case("JointSaturationLimiter.enforce", "desired None",
     _limiter(lambda jl, lim: lim.enforce(jl.JointControlInterfacesData("joint1", position=0.0), None, 0.01)),
     names=("desired",), error=RRBotWorkshopError)
case("JointSaturationLimiter.init", "two names, one limit",
     lambda env: rw.joint_limits.JointSaturationLimiter().init(["joint1", "joint2"], [rw.joint_limits.JointLimits()]),
     names=("joint",), expect=EITHER, why="Jazzy's init returns false for mismatched sizes")


# ---------------------------------------------------------------- control_toolbox.Pid
def _pid(fn: Any) -> Any:
    return lambda env: fn(rw.control_toolbox.Pid)


for label, args, kw, names in [
        ("p None", (None, 0.0, 0.0), {}, ("p",)), ("p 'a'", ("a", 0.0, 0.0), {}, ("p",)),
        ("p NaN", (NAN, 0.0, 0.0), {}, ("p",)),
        ("u_clamp_max below u_clamp_min", (1.0, 0.0, 0.0), {"u_clamp_max": -1.0, "u_clamp_min": 1.0}, ("u_clamp",)),
        ("antiwindup_strategy 'bogus'", (1.0, 0.0, 0.0), {"antiwindup_strategy": "bogus"}, ("antiwindup_strategy",)),
        ("tracking_time_constant -1", (1.0, 0.0, 0.0), {"antiwindup_strategy": "back_calculation",
                                                          "tracking_time_constant": -1.0},
         ("tracking_time_constant",)),
        ("i_clamp_max NaN", (1.0, 1.0, 0.0), {"i_clamp_max": NAN}, ("i_clamp",)),
]:
    case("Pid", label, _pid(lambda P, a=args, k=kw: P(*a, **k)), names=names, error=RRBotWorkshopError,
         expect=EITHER if "NaN" in label else REFUSE,
         why="Jazzy's Pid does not check its gains for NaN" if "NaN" in label else "")
for label, args, names in [("dt 0", (1.0, 0.0), ("dt",)), ("dt -1", (1.0, -1.0), ("dt",)),
                           ("dt NaN", (1.0, NAN), ("dt",)), ("dt None", (1.0, None), ("dt",)),
                           ("error None", (None, 0.01), ("error",)), ("error 'a'", ("a", 0.01), ("error",)),
                           ("four arguments", (1.0, 2.0, 3.0, 4.0), ("compute_command",))]:
    case("Pid.compute_command", label, _pid(lambda P, a=args: P(1.0, 0.0, 0.0).compute_command(*a)), names=names,
         error=RRBotWorkshopError,
         expect=EITHER if label in ("dt 0", "dt -1", "dt NaN", "error NaN") else REFUSE,
         why="Jazzy's compute_command returns 0 for dt <= 0 (and throws for a negative dt in newer releases)"
         if label.startswith("dt ") and label != "dt None" else "")
case("Pid.compute_command", "error NaN", _pid(lambda P: P(1.0, 0.0, 0.0).compute_command(NAN, 0.01)),
     expect=EITHER, why="Jazzy's Pid returns NaN on NaN input")


# ---------------------------------------------------------------- interpolation
def _interp(*args: Any) -> Any:
    def call(env: Env) -> Any:
        from rrbot_workshop.controllers.joint_trajectory import interpolate_between_points
        return interpolate_between_points(*args)
    return call


case("interpolate_between_points", "p0 None", _interp(0.0, None, 1.0, P(positions=[1.0]), 0.5), names=("p0",),
     error=RRBotWorkshopError)
case("interpolate_between_points", "lengths differ", _interp(0.0, P(positions=[0.0]), 1.0, P(positions=[1.0, 2.0]),
                                                            0.5), names=("positions",), error=RRBotWorkshopError)
case("interpolate_between_points", "t1 before t0", _interp(1.0, P(positions=[0.0]), 0.0, P(positions=[1.0]), 0.5),
     names=("t1",), expect=EITHER, error=RRBotWorkshopError, why="ros2_controllers clamps to the segment's ends")
case("interpolate_between_points", "t NaN", _interp(0.0, P(positions=[0.0]), 1.0, P(positions=[1.0]), NAN),
     names=("t",), error=RRBotWorkshopError)


# ---------------------------------------------------------------- ControllerHarness
def _harness(**kw: Any) -> Any:
    def call(env: Env) -> Any:
        from rrbot_workshop.controllers.forward_command import ForwardCommandController
        from rrbot_workshop.testing import ControllerHarness

        args: dict[str, Any] = {"controller": ForwardCommandController(), "name": "fwd",
                                "parameters": {"joints": ["j1"], "interface_name": "position"},
                                "state_values": {}, "command_values": {"j1/position": 0.0}}
        steps = kw.pop("steps", None)
        args.update(kw)
        h = ControllerHarness(**args)
        if steps:
            return steps(h)
        return h
    return call


for label, kw, names in [
        ("controller None", {"controller": None}, ("controller",)),
        ("controller a class", {"controller": "ForwardCommandController"}, ("controller",)),
        ("name None", {"name": None}, ("name",)), ("name ''", {"name": ""}, ("name",)),
        ("parameters a list", {"parameters": ["joints"]}, ("parameters",)),
        ("update_rate 0", {"update_rate": 0}, ("update_rate",)),
        ("update_rate -1", {"update_rate": -1}, ("update_rate",)),
        ("update_rate NaN", {"update_rate": NAN}, ("update_rate",)),
        ("update_rate '100'", {"update_rate": "100"}, ("update_rate",)),
        ("command_values a list", {"command_values": ["j1/position"]}, ("command_values",)),
        ("a command name without '/'", {"command_values": {"position": 0.0}}, ("position",)),
        ("a state value 'abc'", {"state_values": {"j1/position": "abc"}}, ("j1/position",)),
        ("robot_description 3", {"robot_description": 3}, ("robot_description",)),
]:
    case("ControllerHarness", label, _harness(**kw), names=names, error=RRBotWorkshopError)
for label, steps, names, err in [
        ("update(cycles=-1)", lambda h: (h.configure(), h.activate(), h.update(-1)), ("cycles",), RRBotWorkshopError),
        ("update(cycles='3')", lambda h: (h.configure(), h.activate(), h.update("3")), ("cycles",),
         RRBotWorkshopError),
        ("value of an unknown interface", lambda h: h.value("nope/position"), ("nope/position",), RRBotWorkshopError),
        ("set an unknown interface", lambda h: h.set("nope/position", 1.0), ("nope/position",), RRBotWorkshopError),
        ("activate before configure", lambda h: h.activate(), ("configure",), RRBotWorkshopError),
        ("publish None", lambda h: h.publish("/fwd/commands", None), ("None",), MessageError),
        ("publish on a bad topic", lambda h: h.publish("a b", Float64MultiArray()), ("topic",), MessageError),
        ("values(None)", lambda h: h.values(None), ("names",), RRBotWorkshopError),
]:
    case("ControllerHarness", label, _harness(steps=steps), names=names, error=err)


class _Raising:
    """A controller of the learner's whose update raises."""


def _raising_controller(where: str) -> Any:
    def call(env: Env) -> Any:
        from rrbot_workshop.controllers.forward_command import ForwardCommandController
        from rrbot_workshop.testing import ControllerHarness

        class Broken(ForwardCommandController):
            def update(self, time: float, period: float) -> Any:
                if where == "update":
                    raise RuntimeError("learner's bug")
                return super().update(time, period)

            def on_configure(self, previous_state: Any) -> Any:
                if where == "on_configure":
                    raise RuntimeError("learner's bug")
                return super().on_configure(previous_state)

        h = ControllerHarness(Broken(), "fwd", {"joints": ["j1"], "interface_name": "position"},
                              state_values={}, command_values={"j1/position": 0.0})
        h.configure()
        h.activate()
        return h.update()
    return call


case("ControllerHarness", "a learner's update that raises", _raising_controller("update"), expect=EITHER,
     user_error=True, why="the harness reports the learner's error (raised or as ERROR)", error=Exception)
case("ControllerHarness", "a learner's on_configure that raises", _raising_controller("on_configure"),
     expect=EITHER, user_error=True, why="the harness reports the learner's error", error=Exception)


def _raising_hardware(where: str) -> Any:
    def call(env: Env) -> Any:
        from rrbot_workshop.hardware.mock import GenericSystem
        from rrbot_workshop.middleware.plugins import register as register_plugin

        class Broken(GenericSystem):
            def read(self, time: float, period: float) -> Any:
                if where == "read":
                    raise RuntimeError("learner's bug")
                return super().read(time, period)

            def write(self, time: float, period: float) -> Any:
                if where == "write":
                    raise RuntimeError("learner's bug")
                return super().write(time, period)

        register_plugin("hardware", f"hostile/Broken_{where}", Broken)
        text = _urdf(_J).replace("mock_components/GenericSystem", f"hostile/Broken_{where}")
        system = env.keep(rw.bringup(description=text,
                                     controllers={"controller_manager": {"ros__parameters": {"update_rate": 100}}}))
        system.spin(0.05)
        return system.controller_manager.list_hardware_components()[0].state.label
    return call


for where in ("read", "write"):
    case("hardware component", f"a learner's {where} that raises", _raising_hardware(where), expect=ACCEPT,
         user_error=True, why="the manager deactivates the component and logs the learner's error")


def _raising_subscriber(env: Env) -> Any:
    bus = env.system.bus
    bus.create_subscription(Float64MultiArray, FWD, lambda msg: 1 / 0, owner="learner")
    env.system.publish(FWD, Float64MultiArray(data=[0.1, 0.1]))
    env.system.spin(0.05)
    return env.system.latest("/joint_states")


case("topic bus", "a learner's subscriber that raises", _raising_subscriber, expect=ACCEPT, user_error=True,
     why="the bus logs the subscriber's error and delivers to the others")


if __name__ == "__main__":  # pragma: no cover - the probe's report
    import sys

    from hostile_api import run_case, tally, verdict

    only = sys.argv[1] if len(sys.argv) > 1 else ""
    outcomes = []
    for c in CASES:
        if only and only not in c.id:
            continue
        o = run_case(c)
        outcomes.append(o)
        if verdict(o) != "good":
            print(o.describe())
    print(dict(tally(outcomes)))
