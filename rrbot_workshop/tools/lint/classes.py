"""The controller classes behind ``rrbot-workshop lint``: configure one as Jazzy would and read what it uses.

:func:`controller_interfaces` configures a controller with its parameters and a description, and reads the
interfaces it claims and reads, and, for a chainable controller, the reference and state interfaces it exports.
A class may be a learner's file loaded by a course track (:func:`learner_file`); what it raises or logs while
it is configured is caught (:func:`captured`) so that lint reports it instead of a traceback.
"""

from __future__ import annotations

import contextlib
import inspect
import logging
import sys
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

__all__ = ["Interfaces", "hardware_interfaces", "controller_interfaces", "quiet", "captured", "learner_file",
           "reason", "unfinished_exercise", "LEARNER_MODULE_PREFIX"]

#: Module names the course tracks give a learner's file when they load it (rrbot_workshop.course.tracks).
LEARNER_MODULE_PREFIX = "rrbot_workshop_track_"


class Interfaces:
    """What one controller asks for and exports once configured (names ``<prefix>/<interface>``)."""

    def __init__(self) -> None:
        self.commands: list[str] = []
        self.states: list[str] = []
        self.references: list[str] = []
        self.exported_states: list[str] = []


def hardware_interfaces(infos: Sequence[Any]) -> tuple[set[str], set[str]]:
    commands: set[str] = set()
    states: set[str] = set()
    for info in infos:
        for component in [*info.joints, *info.sensors, *info.gpios]:
            commands.update(f"{component.name}/{i.name}" for i in component.command_interfaces)
            states.update(f"{component.name}/{i.name}" for i in component.state_interfaces)
    return commands, states


def controller_interfaces(cls: Any, name: str, values: Mapping[str, Any], urdf: str, rate: int) -> Interfaces:
    """Configure a controller of ``cls`` as Jazzy would, and read its interface configuration and exports."""
    from rrbot_workshop.controller_interface.base import ChainableControllerInterface, InterfaceConfigurationType
    from rrbot_workshop.testing import ControllerHarness

    controller = cls()
    harness = ControllerHarness(controller, name, values, state_values={}, command_values={},
                                update_rate=rate, robot_description=urdf)
    harness.configure()

    def names(config: Any) -> list[str]:
        if config is None or config.type is not InterfaceConfigurationType.INDIVIDUAL:
            return []
        return list(config.names)

    out = Interfaces()
    out.commands = names(controller.command_interface_configuration())
    out.states = names(controller.state_interface_configuration())
    if isinstance(controller, ChainableControllerInterface):
        out.references = [handle.name for handle in controller.export_reference_interfaces()]
        out.exported_states = [handle.name for handle in controller.export_state_interfaces()]
    return out


@contextlib.contextmanager
def quiet() -> Iterator[None]:
    """The library logs what it ignores while the checks run; the findings say it instead."""
    logger = logging.getLogger("rrbot_workshop")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        logger.setLevel(level)


class _Collect(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


@contextlib.contextmanager
def captured(name: str) -> Iterator[_Collect]:
    """The warnings and errors logger ``name`` logs meanwhile (not printed)."""
    logger = logging.getLogger(name)
    handler = _Collect()
    level, propagate = logger.level, logger.propagate
    logger.setLevel(logging.WARNING)
    logger.propagate = False
    logger.addHandler(handler)
    try:
        yield handler
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)
        logger.propagate = propagate


def learner_file(cls: Any) -> str | None:
    """The learner's file ``cls`` was loaded from by a course track, or None for the library's own classes."""
    module = getattr(cls, "__module__", "") or ""
    if not module.startswith(LEARNER_MODULE_PREFIX):
        return None
    try:
        path = Path(inspect.getfile(sys.modules[module]))
    except (KeyError, TypeError):
        return module
    with contextlib.suppress(ValueError):
        return str(path.relative_to(Path.cwd()))
    return str(path)


def reason(exc: BaseException) -> str:
    text = str(exc)
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _shown(path: Any) -> str:
    with contextlib.suppress(TypeError, ValueError):
        return str(Path(path).resolve().relative_to(Path.cwd().resolve()))
    return str(path)


def unfinished_exercise(exc: BaseException) -> str | None:
    """``<file>: <what is unfinished>[; to run anyway: ...]`` when resolving a plugin failed on a learner's
    unfinished class (the library's ``UnfinishedExercise``); None for any other failure."""
    problem = getattr(exc, "problem", None)
    task = getattr(exc, "task", None)
    if not isinstance(problem, str) or task is None:
        return None
    path = getattr(exc, "path", None)
    where = _shown(path) if path is not None else f"task {task}'s folder"
    _, _, instead = str(exc).partition("To run anyway: ")
    return f"{where}: {problem}" + (f"; to run anyway: {instead.rstrip('.')}" if instead else "")
