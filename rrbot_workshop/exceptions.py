"""One exception hierarchy for the whole library.

Every exception names the thing at fault (file, element, parameter, controller, interface) and, where
there is a finite set of valid choices, lists them. Exceptions carry their data as attributes so tools
(graders, notebooks) can react without parsing messages.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = [
    "RRBotWorkshopError",
    "DescriptionError",
    "HardwareError",
    "LifecycleError",
    "InterfaceNotFound",
    "InterfaceAlreadyClaimed",
    "ModeSwitchRejected",
    "ParameterError",
    "ControllerError",
    "ControllerNotFound",
    "SwitchError",
    "PluginNotFound",
    "UnfinishedExercise",
    "MessageError",
    "CourseError",
    "GradingError",
    "JointLimitsError",
    "ArgumentError",
]


def _valid(choices: Iterable[str] | None) -> str:
    if choices is None:
        return ""
    items = sorted(set(choices))
    if not items:
        return " (there are none)"
    return " (valid: " + ", ".join(repr(c) for c in items) + ")"


class RRBotWorkshopError(Exception):
    """Base class of every error raised on purpose by rrbot_workshop."""


class DescriptionError(RRBotWorkshopError, ValueError):
    """A robot description (xacro, URDF or its ``<ros2_control>`` tag) is invalid.

    Attributes:
        source: File or description name the error comes from, if known.
        element: XML element at fault, if known (e.g. ``"<joint name='joint1'>"``).
        attribute: Attribute or child at fault, if known.
    """

    def __init__(
        self,
        message: str,
        *,
        source: str | None = None,
        element: str | None = None,
        attribute: str | None = None,
    ) -> None:
        self.source = source
        self.element = element
        self.attribute = attribute
        prefix = f"{source}: " if source else ""
        super().__init__(prefix + message)


class HardwareError(RRBotWorkshopError):
    """A hardware component could not be loaded, or failed in a way the caller must see."""


class LifecycleError(RRBotWorkshopError):
    """A lifecycle transition was requested from a state that does not allow it.

    Attributes:
        name: Controller or hardware component name.
        state: Current state label.
        transition: Requested transition.
    """

    def __init__(self, name: str, state: str, transition: str, allowed_from: Iterable[str] = ()) -> None:
        self.name = name
        self.state = state
        self.transition = transition
        allowed = list(allowed_from)
        hint = f"; '{transition}' is allowed from: {', '.join(allowed)}" if allowed else ""
        super().__init__(f"cannot '{transition}' '{name}': it is '{state}'{hint}")


class InterfaceNotFound(RRBotWorkshopError, KeyError):
    """An interface name does not exist or is not available.

    Attributes:
        interface: The requested full interface name (``"joint1/position"``).
        available: The names that would have been valid.
    """

    def __init__(self, interface: str, available: Iterable[str] | None = None, reason: str = "does not exist") -> None:
        self.interface = interface
        self.available = sorted(available) if available is not None else None
        super().__init__(f"interface '{interface}' {reason}{_valid(self.available)}")

    def __str__(self) -> str:  # KeyError would otherwise quote the message
        return str(self.args[0])


class InterfaceAlreadyClaimed(RRBotWorkshopError):
    """A command interface is already claimed by someone else.

    Attributes:
        interface: Full interface name.
        holder: Name of the controller that holds the claim, if known.
        requester: Name of the controller that asked, if known.
    """

    def __init__(self, interface: str, holder: str | None = None, requester: str | None = None) -> None:
        self.interface = interface
        self.holder = holder
        self.requester = requester
        who = f" by '{holder}'" if holder else ""
        asker = f"'{requester}' cannot claim it" if requester else "it cannot be claimed twice"
        super().__init__(f"command interface '{interface}' is already claimed{who}; {asker}")


class ModeSwitchRejected(RRBotWorkshopError):
    """A hardware component refused a command mode switch.

    Attributes:
        component: Hardware component name.
        start: Interfaces that were to be started.
        stop: Interfaces that were to be stopped.
    """

    def __init__(self, component: str, reason: str, start: Iterable[str] = (), stop: Iterable[str] = ()) -> None:
        self.component = component
        self.start = list(start)
        self.stop = list(stop)
        super().__init__(f"hardware '{component}' rejected the command mode switch: {reason}")


class ParameterError(RRBotWorkshopError, ValueError):
    """A parameter is missing, of the wrong type, or fails validation.

    Attributes:
        owner: Controller (or node) name the parameter belongs to.
        parameter: Dotted parameter name (``"gains.joint1.p"``).
    """

    def __init__(self, owner: str, parameter: str, message: str) -> None:
        self.owner = owner
        self.parameter = parameter
        super().__init__(f"parameter '{parameter}' of '{owner}': {message}")


class ControllerError(RRBotWorkshopError):
    """A controller could not be loaded, configured or switched."""


class ControllerNotFound(ControllerError, KeyError):
    """No controller of that name is loaded (or declared).

    Attributes:
        name: The requested controller name.
        available: Names that exist.
    """

    def __init__(self, name: str, available: Iterable[str], what: str = "loaded") -> None:
        self.name = name
        self.available = sorted(available)
        super().__init__(f"no controller named '{name}' is {what}{_valid(self.available)}")

    def __str__(self) -> str:
        return str(self.args[0])


class SwitchError(ControllerError):
    """``switch_controllers`` was rejected; nothing changed.

    Attributes:
        reasons: One line per problem found.
        partial: True if some controllers did change state (a best-effort switch in which an
            activation failed while the switch ran); False if the request was rejected as a whole.
        controllers: The controllers the problems involve (requested ones, holders of a claimed interface,
            preceding or following controllers of a chain), each once, in the order first met.
        interfaces: The interfaces the problems involve (claimed twice, missing, unavailable), each once.
    """

    def __init__(
        self,
        reasons: Iterable[str],
        partial: bool = False,
        controllers: Iterable[str] = (),
        interfaces: Iterable[str] = (),
    ) -> None:
        self.reasons = list(reasons)
        self.partial = partial
        self.controllers = list(dict.fromkeys(controllers))
        self.interfaces = list(dict.fromkeys(interfaces))
        head = "switch partly failed:" if partial else "switch rejected, no controller changed state:"
        super().__init__(head + "\n  - " + "\n  - ".join(self.reasons))


class PluginNotFound(RRBotWorkshopError, KeyError):
    """A plugin type string is unknown.

    Attributes:
        plugin: The requested type string.
        available: Registered type strings of the same kind.
    """

    def __init__(self, plugin: str, kind: str, available: Iterable[str]) -> None:
        self.plugin = plugin
        self.available = sorted(available)
        super().__init__(f"unknown {kind} plugin '{plugin}'{_valid(self.available)}")

    def __str__(self) -> str:
        return str(self.args[0])


class UnfinishedExercise(PluginNotFound):
    """A plugin name of the original workshop resolves to a learner's class that is not finished yet.

    The workshop's names (``controlko_hardware_interface/RRBotHardwareInterface``, ...) mean "your task N class";
    while that class does not import, is missing, or still has stubs (``raise NotImplementedError``), the plugin
    cannot be loaded, as a C++ plugin whose library was not built yet. It is a :class:`PluginNotFound`, so every
    caller that handles an unknown plugin handles it too.

    Attributes:
        plugin: The requested type string.
        kind: ``"hardware"`` or ``"controller"``.
        task: The task whose exercise the name resolves to.
        path: The learner's file (``None`` if it is missing).
        line: Line of the problem in that file (``None`` if there is none to point at).
        problem: What is unfinished, in one sentence (the learner's error, with file and line).
        available: Registered type strings of the same kind.
    """

    def __init__(self, plugin: str, kind: str, task: int, path: object, line: int | None, problem: str,
                 message: str, available: Iterable[str] = ()) -> None:
        self.plugin = plugin
        self.kind = kind
        self.task = task
        self.path = path
        self.line = line
        self.problem = problem
        self.available = sorted(available)
        RRBotWorkshopError.__init__(self, message)


class MessageError(RRBotWorkshopError, ValueError):
    """A message was rejected; the text says which field and why."""


class CourseError(RRBotWorkshopError, ValueError):
    """A course request names a track, task or folder that does not exist.

    Attributes:
        what: The kind of thing at fault (``"track"``, ``"task"``, ``"folder"``).
        value: The requested value.
        available: The values that would have been valid.
    """

    def __init__(self, what: str, value: object, message: str, available: Iterable[object] | None = None) -> None:
        self.what = what
        self.value = value
        self.available = sorted(str(a) for a in available) if available is not None else None
        super().__init__(message + _valid(self.available))


class GradingError(RRBotWorkshopError):
    """A grader could not run to the end (it crashed or could not be collected); the text says why."""


class JointLimitsError(HardwareError):
    """A joint's measured position is beyond its position limits by more than the tolerance while a position is
    commanded (Jazzy's joint limiters throw then: a hardware failure, or a description whose limits are narrower
    than the joint's).

    Attributes:
        joint: Joint name.
        position: The measured position [rad] or [m].
        limits: ``(min_position, max_position)``.
    """

    def __init__(self, joint: str, position: float, limits: tuple[float, float]) -> None:
        self.joint = joint
        self.position = position
        self.limits = limits
        super().__init__(
            f"joint '{joint}': its position {position:.6g} is out of its limits [{limits[0]:.6g}, {limits[1]:.6g}]; "
            "a hardware failure, or joint limits in the description narrower than the joint's real ones"
        )


class ArgumentError(RRBotWorkshopError, ValueError, TypeError):
    """An argument of a library call is of the wrong type or out of range (Python code, not a ROS file, is at fault).

    It is a :class:`ValueError` and a :class:`TypeError` too, so code that catches Python's own errors for a bad
    argument still catches it.

    Attributes:
        function: The call (``"System.spin"``).
        argument: The argument's name (``"seconds"``).
        value: What was given.
        valid: What would be valid, in words (``"a finite number of seconds >= 0"``).
    """

    def __init__(self, function: str, argument: str, value: object, valid: str) -> None:
        self.function = function
        self.argument = argument
        self.value = value
        self.valid = valid
        shown = repr(value)
        if len(shown) > 80:
            shown = shown[:77] + "..."
        super().__init__(f"{function}: argument '{argument}' must be {valid}, got {shown}")
