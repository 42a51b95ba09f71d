"""The parameter checks of ``rrbot-workshop lint``: a controllers YAML's values against what Jazzy accepts.

* the ``controller_manager`` parameters of Jazzy, with their types (:data:`CONTROLLER_MANAGER_PARAMETERS`);
  unknown names get the closest valid one (:func:`manager_findings`);
* each controller's parameters against its declared schema: unknown or misspelt names, wrong types,
  missing required values, failed validations, every one of them and not only the first (:func:`check_parameters`);
* keys removed or with changed defaults between Humble and Jazzy.

Both checks report through ``report(level, where, message)``; :mod:`rrbot_workshop.course.lint` turns that into
findings with file lines.
"""

from __future__ import annotations

import difflib
import fnmatch
from collections.abc import Iterable, Mapping
from typing import Any

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.controllers_yaml import ControllersConfig
from rrbot_workshop.middleware.params import ParameterSchema, ParamListener, flatten

__all__ = ["CONTROLLER_MANAGER_PARAMETERS", "check_parameters", "manager_findings", "closest"]


#: controller_manager parameters of Jazzy (controller_manager_parameters.yaml) -> expected Python type.
CONTROLLER_MANAGER_PARAMETERS: dict[str, type | tuple[type, ...]] = {
    "update_rate": int,
    "enforce_command_limits": bool,
    "handle_exceptions": bool,
    "thread_priority": int,
    "cpu_affinity": list,
    "use_sim_time": bool,
    "hardware_components_initial_state.unconfigured": list,
    "hardware_components_initial_state.inactive": list,
    "defaults.switch_controller.strictness": str,
    "defaults.allow_controller_activation_with_inactive_hardware": bool,
    "defaults.deactivate_controllers_on_hardware_self_deactivate": bool,
    "diagnostics.threshold.controller_manager.periodicity.mean_error.warn": (int, float),
    "diagnostics.threshold.controller_manager.periodicity.mean_error.error": (int, float),
    "diagnostics.threshold.controller_manager.periodicity.standard_deviation.warn": (int, float),
    "diagnostics.threshold.controller_manager.periodicity.standard_deviation.error": (int, float),
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
    ("diff_drive_controller/*", "linear.x.has_velocity_limits"):
        "was removed in Jazzy: leave 'linear.x.max_velocity' / 'min_velocity' at .NAN for no limit",
    ("diff_drive_controller/*", "linear.x.has_acceleration_limits"):
        "was removed in Jazzy: leave the acceleration limits at .NAN for no limit",
    ("diff_drive_controller/*", "linear.x.has_jerk_limits"):
        "was removed in Jazzy: leave the jerk limits at .NAN for no limit",
    ("diff_drive_controller/*", "angular.z.has_velocity_limits"):
        "was removed in Jazzy: leave 'angular.z.max_velocity' / 'min_velocity' at .NAN for no limit",
    ("diff_drive_controller/*", "angular.z.has_acceleration_limits"):
        "was removed in Jazzy: leave the acceleration limits at .NAN for no limit",
    ("diff_drive_controller/*", "angular.z.has_jerk_limits"):
        "was removed in Jazzy: leave the jerk limits at .NAN for no limit",
}

#: Defaults that changed between Humble and Jazzy and are worth a note when a file relies on them.
_CHANGED_DEFAULTS: dict[tuple[str, str], str] = {
    ("joint_trajectory_controller/*", "allow_nonzero_velocity_at_trajectory_end"):
        "defaults to false in Jazzy (true in Humble): a trajectory whose last point has a velocity is rejected",
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


def check_parameters(
    name: str, ctype: str, schema: ParameterSchema, values: dict[str, Any], report: Any
) -> None:
    """Collect every parameter error of one controller, not only the first one."""
    given = flatten(values)
    patterns = _declared_patterns(schema)
    for key in given:
        if not any(fnmatch.fnmatchcase(key, p) for p in patterns):
            advice = next((a for (t, k), a in _REMOVED.items() if k == key and fnmatch.fnmatchcase(ctype, t)), None)
            if advice:
                report("error", key, f"'{key}' {advice}")
            else:
                report(
                    "warning", key,
                    f"'{name}' ({ctype}) declares no parameter '{key}'; it is ignored{closest(key, patterns)}",
                )
    for (pattern, key), note in _CHANGED_DEFAULTS.items():
        if fnmatch.fnmatchcase(ctype, pattern) and key not in given:
            report("note", key, f"'{key}' is not set and {note}")
    declared_types = {".".join(d.path): d.type for d in schema.declarations}
    working = {k: v for k, v in given.items() if any(fnmatch.fnmatchcase(k, p) for p in patterns)}
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
            level_message = str(err)
            report("error", parameter, level_message)
            pattern = next((p for p in declared_types if fnmatch.fnmatchcase(parameter, p.replace("__map_", "*"))), "")
            working[parameter] = _placeholder(declared_types.get(pattern, "string"))


def _nest(flat: Mapping[str, Any]) -> dict[str, Any]:
    root: dict[str, Any] = {}
    for key, value in flat.items():
        node = root
        parts = key.split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        node[parts[-1]] = value
    return root


def manager_findings(cfg: ControllersConfig, report: Any) -> None:
    """Report the ``controller_manager`` parameters that Jazzy does not know, removed keys and wrong types."""
    flat = flatten(cfg.manager_parameters)
    if any(key.startswith("joint_limits.") for key in flat):
        _joint_limits_findings(cfg, flat, report)
    for key, value in flat.items():
        if key.startswith("joint_limits."):
            continue
        removed = _REMOVED.get(("controller_manager", key))
        if removed:
            report("error", key, f"'{key}' {removed}")
            continue
        expected = CONTROLLER_MANAGER_PARAMETERS.get(key)
        if expected is None:
            report(
                "warning", key,
                f"the controller manager of Jazzy has no parameter '{key}'{closest(key, CONTROLLER_MANAGER_PARAMETERS)}",
            )
        elif not isinstance(value, expected) or (expected is int and isinstance(value, bool)):
            report("error", key, f"'{key}' must be of type {_type_name(expected)}, got {value!r}")
    strictness = flat.get("defaults.switch_controller.strictness")
    if strictness is not None and strictness not in ("strict", "best_effort"):
        report("error", "defaults.switch_controller.strictness",
               f"'{strictness}' is not a strictness (valid: strict, best_effort)")


def _joint_limits_findings(cfg: ControllersConfig, flat: Mapping[str, Any], report: Any) -> None:
    """``joint_limits.<joint>.*`` on the controller manager: checked as rrbot_workshop.joint_limits reads them."""
    from rrbot_workshop.joint_limits import joint_limits_parameters

    try:
        joint_limits_parameters(cfg.manager_parameters, "controller_manager")
    except ParameterError as exc:
        report("error", exc.parameter, str(exc).split(": ", 1)[-1])
        return
    first = next(key for key in flat if key.startswith("joint_limits."))
    enforce = flat.get("enforce_command_limits") is True
    report("note", first, "Jazzy's controller manager does not apply 'joint_limits' parameters (its command limits "
                          "come from the URDF); rrbot_workshop applies them over the URDF's"
           + ("" if enforce else " when 'enforce_command_limits' is true"))


def _type_name(expected: type | tuple[type, ...]) -> str:
    names = {"int": "integer", "float": "double", "bool": "bool", "str": "string", "list": "list"}
    types = expected if isinstance(expected, tuple) else (expected,)
    return " or ".join(names.get(t.__name__, t.__name__) for t in types)
