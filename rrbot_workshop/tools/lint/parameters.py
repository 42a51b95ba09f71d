"""The parameter checks of ``rrbot-workshop lint``: a controllers YAML's values against what Jazzy accepts.

* the ``controller_manager`` parameters of Jazzy, with their types (:data:`CONTROLLER_MANAGER_PARAMETERS`);
  unknown names get the closest valid one (:func:`manager_findings`);
* each controller's parameters against its declared schema: unknown or misspelt names, wrong types,
  missing required values, failed validations, every one of them and not only the first (:func:`check_parameters`);
* the parameters every Jazzy controller has (``update_rate``, ``is_async``, ``type``, ...) and the controller's
  ``update_rate`` against its manager's (:func:`rate_findings`);
* keys removed between Humble and Jazzy (ignored there: warnings) and keys Jazzy still declares but calls
  deprecated (notes);
* values that load but do nothing in Jazzy: a ``pid_controller`` gain ``feedforward_gain`` while feed-forward
  mode is off (:func:`behaviour_findings`).

Both checks report through ``report(level, where, message)``; :mod:`rrbot_workshop.tools.lint` turns that into
findings with file lines.
"""

from __future__ import annotations

import difflib
import fnmatch
from collections.abc import Iterable, Mapping
from typing import Any

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.params import ParameterSchema, ParamListener, flatten

__all__ = ["CONTROLLER_MANAGER_PARAMETERS", "COMMON_CONTROLLER_PARAMETERS", "DEPRECATED", "behaviour_findings",
           "check_parameters", "manager_findings", "rate_findings", "closest"]


#: controller_manager parameters of Jazzy (controller_manager_parameters.yaml, and those ros2_control_node reads)
#: -> expected Python type.
CONTROLLER_MANAGER_PARAMETERS: dict[str, type | tuple[type, ...]] = {
    "update_rate": int,
    "enforce_command_limits": bool,
    "handle_exceptions": bool,
    "thread_priority": int,
    "cpu_affinity": (int, list),
    "lock_memory": bool,
    "use_sim_time": bool,
    "robot_description": str,
    "hardware_components_initial_state.unconfigured": list,
    "hardware_components_initial_state.inactive": list,
    "hardware_components_initial_state.shutdown_on_initial_state_failure": bool,
    "defaults.switch_controller.strictness": str,
    "defaults.allow_controller_activation_with_inactive_hardware": bool,
    "defaults.deactivate_controllers_on_hardware_self_deactivate": bool,
    "overruns.print_warnings": bool,
    "overruns.manage": bool,
    "hardware_synchronization.expect_blocking_read_write": bool,
    "hardware_synchronization.minimum_cycle_time": (int, float),
    **{
        f"diagnostics.threshold.{who}.{what}.{stat}.{level}": (int, float)
        for who, whats in (("controller_manager", ("periodicity",)),
                           ("controllers", ("periodicity", "execution_time")),
                           ("hardware_components", ("periodicity", "execution_time")))
        for what in whats
        for stat in ("mean_error", "standard_deviation")
        for level in ("warn", "error")
    },
}

#: Parameters every Jazzy controller has besides its own (controller_interface_base.cpp declares the first three;
#: the spawner reads ``type`` and ``fallback_controllers`` from the controller's section; every node has
#: ``use_sim_time``) -> expected Python type. Patterns may hold ``*``.
COMMON_CONTROLLER_PARAMETERS: dict[str, type | tuple[type, ...]] = {
    "update_rate": int,
    "is_async": bool,
    "thread_priority": int,
    "async_parameters.thread_priority": int,
    "async_parameters.cpu_affinity": (int, list),
    "async_parameters.scheduling_policy": str,
    "async_parameters.clock_type": str,
    "async_parameters.wait_until_initial_trigger": bool,
    "async_parameters.trigger_predicate": str,
    "async_parameters.print_warnings": bool,
    "type": str,
    "fallback_controllers": list,
    "use_sim_time": bool,
    "qos_overrides.*": object,
}

#: Parameters that Jazzy still declares but calls deprecated: (controller type pattern, key) -> advice (a note).
DEPRECATED: dict[tuple[str, str], str] = {
    **{("diff_drive_controller/*", f"{axis}.has_{what}_limits"):
       "is deprecated in Jazzy (still declared): leave the respective limits at .NAN to switch them off"
       for axis in ("linear.x", "angular.z") for what in ("velocity", "acceleration", "jerk")},
    **{("diff_drive_controller/*", f"{axis}.min_acceleration"):
       "is deprecated in Jazzy (still declared, not used): give 'max_deceleration' instead"
       for axis in ("linear.x", "angular.z")},
    ("joint_trajectory_controller/*", "open_loop_control"):
        "is deprecated in Jazzy (still declared): use 'interpolate_from_desired_state' and zero feedback gains",
    ("joint_trajectory_controller/*", "gains.*.i_clamp"):
        "is deprecated in Jazzy (still declared): use 'i_clamp_max' / 'i_clamp_min'",
}

#: Keys that existed in Humble and are gone or renamed in Jazzy: (controller type pattern, key) -> advice.
_REMOVED: dict[tuple[str, str], str] = {
    ("controller_manager", "configure_components_on_start"):
        "was replaced by 'hardware_components_initial_state.inactive' (list of component names)",
    ("controller_manager", "activate_components_on_start"):
        "was removed; every component not listed in 'hardware_components_initial_state' is activated",
    ("joint_trajectory_controller/*", "start_with_holding"):
        "was removed in Jazzy: the controller always holds the position at activation",
    ("joint_trajectory_controller/*", "angle_wraparound"):
        "was removed in Jazzy: declare the joint as type='continuous' in the URDF instead",
    ("diff_drive_controller/*", "wheels_per_side"): "was removed in Jazzy (it was never used)",
}

def closest(name: str, valid: Iterable[str]) -> str:
    """`` (did you mean '<the closest valid name>'?)``, or ``""`` when no valid name is close."""
    matches = difflib.get_close_matches(name, list(valid), n=1, cutoff=0.6)
    return f" (did you mean '{matches[0]}'?)" if matches else ""


def _declared_patterns(schema: ParameterSchema) -> list[str]:
    """Declared names with each mapped segment (``__map_joints``) as a ``*`` wildcard."""
    return [
        ".".join("*" if part.startswith("__map_") else part for part in decl.path) for decl in schema.declarations
    ]


def _placeholder(ptype: str) -> Any:
    return {"bool": False, "int": 1, "double": 1.0, "string": "x"}.get(ptype, ["x"])


def _known(key: str, patterns: Iterable[str]) -> bool:
    return any(fnmatch.fnmatchcase(key, p) for p in patterns)


def _type_ok(value: Any, expected: type | tuple[type, ...]) -> bool:
    types = expected if isinstance(expected, tuple) else (expected,)
    if isinstance(value, bool) and bool not in types and object not in types:
        return False
    return isinstance(value, types) or (float in types and isinstance(value, int) and not isinstance(value, bool))


def check_parameters(
    name: str, ctype: str, schema: ParameterSchema, values: dict[str, Any], report: Any,
    shared: Iterable[str] = (), skip: Iterable[str] = (),
) -> None:
    """Collect every parameter error of one controller, not only the first one.

    Args:
        name: The controller's name.
        ctype: Its type string.
        schema: The parameters its type declares.
        values: Its parameters (nested), as the node would receive them.
        report: ``report(level, key, message)``.
        shared: Keys given only by sections shared with every node (``/**``): an unknown one is not this
            controller's mistake, so it is not reported.
        skip: Keys whose value is not known (an unsubstituted launch argument): nothing is said about them.
    """
    skipped = set(skip)
    given = {k: v for k, v in flatten(values).items() if k not in skipped}
    patterns = _declared_patterns(schema)
    shared_keys = set(shared)
    common = {k: v for k, v in given.items() if _known(k, COMMON_CONTROLLER_PARAMETERS)}
    for key, value in common.items():
        expected = next(t for p, t in COMMON_CONTROLLER_PARAMETERS.items() if fnmatch.fnmatchcase(key, p))
        if not _known(key, patterns) and not _type_ok(value, expected):
            report("error", key, f"'{key}' must be of type {_type_name(expected)}, got {value!r}")
    for key in given:
        deprecated = next((a for (t, k), a in DEPRECATED.items()
                           if fnmatch.fnmatchcase(key, k) and fnmatch.fnmatchcase(ctype, t)), None)
        if deprecated:  # declared (the class may declare it too) but deprecated: a note, whatever the schema says
            report("note", key, f"'{key}' {deprecated}")
            continue
        if key in common or _known(key, patterns):
            continue
        if key in shared_keys:
            continue
        advice = next((a for (t, k), a in _REMOVED.items() if k == key and fnmatch.fnmatchcase(ctype, t)), None)
        if advice:
            report("warning", key, f"'{key}' {advice}; Jazzy ignores it")
        else:
            report(
                "warning", key,
                f"'{name}' ({ctype}) declares no parameter '{key}'; it is ignored{closest(key, patterns)}",
            )
    declared_types = {".".join(d.path): d.type for d in schema.declarations}
    working = {k: v for k, v in given.items() if _known(k, patterns)}
    reported: set[str] = set()
    for _ in range(len(schema.declarations) + 1):
        try:
            ParamListener(schema, _nest(working), name)
            return
        except ParameterError as err:
            parameter = err.parameter
            if parameter in reported:  # the placeholder did not help: stop rather than loop
                return
            reported.add(parameter)
            if parameter not in skipped:
                report("error", parameter, str(err))
            pattern = next((p for p in declared_types if fnmatch.fnmatchcase(parameter, p.replace("__map_", "*"))), "")
            working[parameter] = _placeholder(declared_types.get(pattern, "string"))


def rate_findings(values: Mapping[str, Any], manager_rate: Any, report: Any) -> None:
    """A controller's ``update_rate`` against its manager's, as Jazzy's controller_interface judges it.

    Jazzy refuses a negative rate, and warns (and runs the controller at another rate) when the rate is above the
    manager's or does not divide it.
    """
    rate = values.get("update_rate")
    if not isinstance(rate, int) or isinstance(rate, bool):
        return  # absent (the manager's rate is used) or of the wrong type (reported with the types)
    if rate < 0:
        report("error", "update_rate", f"'update_rate' is {rate}: Jazzy refuses a negative update rate "
                                       "(0 runs the controller at the controller manager's rate)")
        return
    if not isinstance(manager_rate, int) or isinstance(manager_rate, bool) or manager_rate <= 0 or rate == 0:
        return
    if rate > manager_rate:
        report("warning", "update_rate",
               f"'update_rate' {rate} Hz is higher than the controller manager's {manager_rate} Hz: Jazzy runs the "
               f"controller at {manager_rate} Hz")
    elif manager_rate % rate:
        achievable = manager_rate // round(manager_rate / rate)
        report("warning", "update_rate",
               f"'update_rate' {rate} Hz is not achievable with the controller manager's {manager_rate} Hz (it is "
               f"not a divisor): Jazzy runs the controller at {achievable} Hz")


def behaviour_findings(ctype: str, values: Mapping[str, Any], report: Any, skip: Iterable[str] = ()) -> None:
    """Values Jazzy accepts that do not do what they seem to (warnings).

    ``pid_controller/PidController`` applies ``gains.<dof>.feedforward_gain`` only in feed-forward mode, which is off
    unless ``enable_feedforward`` is true or ``~/set_feedforward_control`` switches it on (pid_controller.cpp,
    test_update_chained_feedforward_off_with_gain): a non-zero gain with the mode off is said once per DOF.

    Args:
        ctype: The controller's type string.
        values: Its parameters (nested), as the node would receive them.
        report: ``report(level, key, message)``.
        skip: Keys whose value is not known (an unsubstituted launch argument): nothing is said about them.
    """
    if ctype != "pid_controller/PidController":
        return
    flat = flatten(values)
    skipped = set(skip)
    if "enable_feedforward" in skipped or flat.get("enable_feedforward") is True:
        return
    for key, gain in flat.items():
        if key in skipped or not fnmatch.fnmatchcase(key, "gains.*.feedforward_gain"):
            continue
        if isinstance(gain, (int, float)) and not isinstance(gain, bool) and gain != 0:
            report("warning", key,
                   f"'{key}' is {gain}, but feed-forward mode is off ('enable_feedforward' is false, Jazzy's "
                   "default): Jazzy leaves the gain out of the command until 'enable_feedforward: true' is set or "
                   "~/set_feedforward_control switches the mode on")


def _nest(flat: Mapping[str, Any]) -> dict[str, Any]:
    root: dict[str, Any] = {}
    for key, value in flat.items():
        node = root
        parts = key.split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        node[parts[-1]] = value
    return root


def manager_findings(parameters: Mapping[str, Any], report: Any) -> None:
    """Report the ``controller_manager`` parameters that Jazzy does not know, removed keys and wrong types.

    Args:
        parameters: The manager's own parameters (nested; the controllers' entries left out).
        report: ``report(level, key, message)``.
    """
    flat = flatten(parameters)
    if any(key.startswith("joint_limits.") for key in flat):
        _joint_limits_findings(parameters, flat, report)
    for key, value in flat.items():
        if key.startswith("joint_limits."):
            continue
        removed = _REMOVED.get(("controller_manager", key))
        if removed:
            report("warning", key, f"'{key}' {removed}; Jazzy ignores it")
            continue
        expected = CONTROLLER_MANAGER_PARAMETERS.get(key)
        if expected is None:
            report(
                "warning", key,
                f"the controller manager of Jazzy has no parameter '{key}'{closest(key, CONTROLLER_MANAGER_PARAMETERS)}",
            )
        elif not _type_ok(value, expected):
            report("error", key, f"'{key}' must be of type {_type_name(expected)}, got {value!r}")
    rate = flat.get("update_rate")
    if isinstance(rate, int) and not isinstance(rate, bool) and rate <= 0:
        report("error", "update_rate", f"'update_rate' must be a positive number of [Hz], got {rate}")
    strictness = flat.get("defaults.switch_controller.strictness")
    if strictness is not None and strictness not in ("strict", "best_effort"):
        report("error", "defaults.switch_controller.strictness",
               f"'{strictness}' is not a strictness (valid: strict, best_effort)")


def _joint_limits_findings(parameters: Mapping[str, Any], flat: Mapping[str, Any], report: Any) -> None:
    """``joint_limits.<joint>.*`` on the controller manager: checked as rrbot_workshop.joint_limits reads them."""
    from rrbot_workshop.joint_limits import joint_limits_parameters

    try:
        joint_limits_parameters(parameters, "controller_manager")
    except ParameterError as exc:
        report("error", exc.parameter, str(exc).split(": ", 1)[-1])
        return
    first = next(key for key in flat if key.startswith("joint_limits."))
    enforce = flat.get("enforce_command_limits") is True
    report("note", first, "Jazzy's controller manager does not apply 'joint_limits' parameters (its command limits "
                          "come from the URDF); rrbot_workshop applies them over the URDF's"
           + ("" if enforce else " when 'enforce_command_limits' is true"))


def _type_name(expected: type | tuple[type, ...]) -> str:
    names = {"int": "integer", "float": "double", "bool": "bool", "str": "string", "list": "list", "object": "any"}
    types = expected if isinstance(expected, tuple) else (expected,)
    return " or ".join(names.get(t.__name__, t.__name__) for t in types)
