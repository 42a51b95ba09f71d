"""The manager's ``<controller>.params_file``: the files it names exist and have a section for the controller.

Jazzy's ``ControllerManager::load_controller`` hands each file to the controller's node as ``--params-file``; a file
that cannot be read stops the load, and the library also refuses a file without a section for the controller (see
:meth:`rrbot_workshop.controller_manager.manager.ControllerManager.load_controller`). Lint says so before the load,
with the same rules (:meth:`~rrbot_workshop.middleware.controllers_yaml.ControllersConfig.use_param_file`), and
gives the file's parameters to the controller's parameter checks.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rrbot_workshop.exceptions import ParameterError
from rrbot_workshop.middleware.controllers_yaml import ControllersConfig, fully_qualified

__all__ = ["params_file_parameters"]

#: report(level, message)
Report = Callable[[str, str], None]


def params_file_parameters(name: str, namespace: str, value: Any, report: Report) -> dict[str, Any]:
    """The parameters the files of ``<name>.params_file`` give controller ``name``; each problem is reported.

    Args:
        name: Controller name.
        namespace: The namespace of its manager (``/`` for the root).
        value: The manager's ``<name>.params_file`` as written (a string or a list of strings).
        report: Called with ``("error", message)`` for a value of the wrong type, a file that cannot be read or
            that has no section for the controller, and ``("note", message)`` for a path lint cannot resolve (a
            substitution such as ``$(find-pkg-share ...)``).

    Returns:
        The files' parameters for the controller, merged in order (empty when none can be used).
    """
    cfg = ControllersConfig(namespace=namespace, manager_params_files={name: value})
    try:
        files = cfg.params_files_of(name)
    except ParameterError as exc:
        report("error", str(exc).split(": ", 1)[1])
        return {}
    fqn = fully_qualified(namespace, name)
    for file in files:
        if "$(" in file:
            report("note", f"'{file}' holds a substitution lint cannot resolve; the file is not checked")
            continue
        try:
            found = cfg.use_param_file(name, file)
        except ParameterError as exc:
            why = str(exc).split(": ", 1)[1] if exc.owner == "parameter file" else str(exc)
            report("error", f"{file}, the params_file of controller '{name}', {why}")
            continue
        if not found:
            report("error", f"{file} has no section for controller '{name}'; give it one: '{name}:', '{fqn}:', "
                            f"'/**/{name}:' or '/**:', each with 'ros__parameters:'")
    params = cfg.param_file_parameters.get(name, {})
    params.pop("type", None)  # the manager's <name>.type names the plugin
    return params
