"""Run hostile inputs against the library's public API and judge each outcome.

A :class:`Case` is one call with one bad (or odd) input and what should happen:

* ``REFUSE``: an exception of :mod:`rrbot_workshop.exceptions` whose message holds ``names`` (the argument at fault);
  a running system, if the case had one, is the same after as before (a rejected request changes nothing);
* ``ACCEPT``: the call succeeds (valid input, or an odd value that Jazzy accepts too: ``why`` says so);
* ``EITHER``: a success or a project error, both fine (the case only checks for raw exceptions and hangs).

:func:`run_case` classifies what happened: a success, a project error, a raw exception (any other type), a hang (the
call ran past :data:`HANG_SECONDS`), and a raw exception logged by the library while the call ran (a library callback
that broke on the input, as a subscriber's ``TypeError`` logged with its traceback). :func:`verdict` turns that and
the expectation into one word; :func:`tally` counts them for the report.
"""

from __future__ import annotations

import logging
import re
import signal
import tempfile
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rrbot_workshop.exceptions import RRBotWorkshopError

__all__ = ["REFUSE", "ACCEPT", "EITHER", "HANG_SECONDS", "Case", "Env", "Outcome", "run_case", "verdict", "tally",
           "system_state"]

REFUSE, ACCEPT, EITHER = "refuse", "accept", "either"

#: A call that runs longer than this is a hang [s of wall time]; every case is meant to end far sooner.
HANG_SECONDS = 30.0

#: Python's own exception names: a library log line that shows one reports a raw exception, not a rejection.
_RAW_NAMES = re.compile(r"\b(TypeError|KeyError|AttributeError|IndexError|ZeroDivisionError|RecursionError|"
                        r"ValueError|OverflowError|UnicodeError|NameError|AssertionError)\b")


@dataclass(frozen=True)
class Case:
    """One hostile call.

    Attributes:
        area: The API it exercises (``"bringup"``, ``"System.spin"``, ...).
        label: What is given, short.
        call: ``call(env)`` makes the call.
        expect: ``REFUSE``, ``ACCEPT`` or ``EITHER``.
        names: Words the error message must hold (the argument, case-insensitive).
        why: For an odd input that is accepted: why (Jazzy accepts it too, ...).
        system: The call uses ``env.system`` (a fresh running RRBot), compared before and after a refusal.
        user_error: The input is code of the user's that raises: a logged traceback of it is expected, not a fault.
        error: The project error type a refusal must be (a subclass of it).
        setup: Run before the state is recorded (a switch, parameters set): what the case's call then meets.
        by_log: A message on a topic: ROS refuses it in the subscriber with a logged error, not by raising; a
            warning or error logged while the call ran that holds every word of ``names`` is the refusal.
    """

    area: str
    label: str
    call: Callable[[Env], Any]
    expect: str = REFUSE
    names: tuple[str, ...] = ()
    why: str = ""
    system: bool = False
    user_error: bool = False
    error: type[BaseException] = RRBotWorkshopError
    by_log: bool = False
    setup: Callable[[Env], Any] | None = None

    @property
    def id(self) -> str:
        return f"{self.area}: {self.label}"


class Env:
    """What a case works on: a temporary folder and, on request, a fresh running RRBot."""

    def __init__(self, tmp: Path | None = None) -> None:
        self.tmp = tmp if tmp is not None else Path(tempfile.mkdtemp(prefix="hostile_"))
        self._system: Any = None
        self.made: list[Any] = []  # systems a case brought up, shut down afterwards

    @property
    def system(self) -> Any:
        """RRBot on mock hardware: joint_state_broadcaster and forward_position_controller active,
        joint_trajectory_controller inactive."""
        if self._system is None:
            import rrbot_workshop as rw

            self._system = rw.bringup(description="rrbot", controllers="rrbot_controllers.yaml",
                                      spawn=["joint_state_broadcaster", "forward_position_controller"],
                                      inactive=["joint_trajectory_controller"])
        return self._system

    @property
    def cm(self) -> Any:
        return self.system.controller_manager

    def file(self, name: str, content: str | bytes) -> Path:
        path = self.tmp / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
        return path

    def keep(self, thing: Any) -> Any:
        """Shut ``thing`` (a system a case brought up) down when the case ends."""
        self.made.append(thing)
        return thing

    def close(self) -> None:
        for thing in [self._system, *self.made]:
            if thing is not None:
                try:
                    thing.shutdown() if hasattr(thing, "shutdown") else thing.close()
                except Exception:  # noqa: BLE001 - cleaning up after a hostile case
                    pass
        self._system = None
        self.made.clear()


def system_state(system: Any) -> Any:
    """Everything a rejected request must leave as it was: time, controllers and their states, hardware states,
    claims and availability, interface values, the manager's parameters and remaps, topics' latest messages."""
    cm = system.controller_manager
    storage = system.resource_manager._storage
    values = {name: repr(h.get_value()) for name, h in {**storage.states, **storage.commands}.items()}
    return (
        system.clock.cycles,
        [(c.name, c.state, c.type, tuple(c.claimed_interfaces)) for c in cm.list_controllers()],
        [(h.name, h.state.label) for h in cm.list_hardware_components()],
        repr(cm.list_hardware_interfaces()),
        values,
        repr(cm.params.controller_types), repr(cm.params.param_file_parameters), repr(cm.params.param_files),
        repr(system.bus._remaps),
        sorted((t, id(m)) for t, m in system.bus._latest.items()),
        sorted(system.bus.service_names()),
        system.running,
    )


def _systems() -> list[str]:
    from rrbot_workshop.bringup import systems

    return sorted(systems())


class _Hang(BaseException):
    """Raised by the alarm in a call that ran too long (a BaseException: ``except Exception`` does not stop it)."""


@contextmanager
def _time_limit(seconds: float) -> Iterator[None]:
    def alarm(signum: int, frame: Any) -> None:
        raise _Hang()

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


class _Logged(logging.Handler):
    """Keeps the library's warnings and errors that report a raw exception (a traceback, or its type's name)."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.raw: list[str] = []
        self.texts: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        text = record.getMessage()
        self.texts.append(text)
        if record.exc_info or _RAW_NAMES.search(text):
            kind = type(record.exc_info[1]).__name__ if record.exc_info and record.exc_info[1] else ""
            self.raw.append(f"{record.name}: {text[:300]}" + (f" [{kind} with traceback]" if kind else ""))


@dataclass
class Outcome:
    """What one case did.

    Attributes:
        case: The case.
        kind: ``"ok"``, ``"refused"`` (a project error), ``"raw"`` (another exception), ``"user-raised"`` (the
            exception of the learner's own code that the case runs, reaching the caller) or ``"hang"``.
        error: The exception, if any.
        unchanged: After a refusal with a system: whether its state is as before (None: not checked).
        logged_raw: Library log lines that reported a raw exception while the call ran.
        result: What the call returned.
    """

    case: Case
    kind: str
    error: BaseException | None = None
    unchanged: bool | None = None
    logged_raw: list[str] = field(default_factory=list)
    result: Any = None
    logged: list[str] = field(default_factory=list)

    def describe(self) -> str:
        what = f"{type(self.error).__name__}: {str(self.error)[:300]}" if self.error is not None else "returned"
        return f"[{verdict(self)}] {self.case.id} -> {what}" + (f"; logged {self.logged_raw}" if self.logged_raw else "")


def run_case(case: Case, tmp: Path | None = None) -> Outcome:
    """Run one case in a fresh :class:`Env` and classify what happened."""
    env = Env(tmp)
    handler = _Logged()
    library = logging.getLogger("rrbot_workshop")
    library.addHandler(handler)
    level = library.level
    library.setLevel(logging.WARNING)
    propagate = library.propagate
    library.propagate = False  # the hostile cases' warnings are expected; keep them out of the test output
    try:
        if case.setup is not None:
            case.setup(env)
        before = system_state(env.system) if case.system else None
        before_systems = _systems()
        outcome = Outcome(case, "ok")
        try:
            with _time_limit(HANG_SECONDS):
                outcome.result = case.call(env)
        except _Hang:
            outcome.kind = "hang"
        except RRBotWorkshopError as exc:
            outcome.kind, outcome.error = "refused", exc
        except Exception as exc:  # noqa: BLE001 - what is being counted
            users = case.user_error and case.error is not RRBotWorkshopError and isinstance(exc, case.error)
            outcome.kind, outcome.error = ("user-raised" if users else "raw"), exc
        if outcome.kind == "refused":
            same = _systems() == before_systems
            if before is not None:
                same = same and system_state(env.system) == before
            outcome.unchanged = same
        outcome.logged_raw = [] if case.user_error else handler.raw
        outcome.logged = handler.texts
        return outcome
    finally:
        library.removeHandler(handler)
        library.setLevel(level)
        library.propagate = propagate
        env.close()


def verdict(outcome: Outcome) -> str:
    """One word for an outcome: ``good``, ``hang``, ``raw``, ``raw-in-callback``, ``silently-accepted``,
    ``wrongly-refused``, ``wrong-type`` (a project error of another type than the case's), ``vague`` (a refusal that does not name the argument) or ``changed-state``."""
    case = outcome.case
    if outcome.kind == "hang":
        return "hang"
    if outcome.kind == "raw":
        return "raw"
    if outcome.kind == "user-raised":  # the learner's own exception reached the learner, unchanged
        return "good"
    if outcome.logged_raw:
        return "raw-in-callback"
    if outcome.kind == "ok":
        if case.expect == REFUSE and case.by_log:
            said = any(all(n.lower() in t.lower() for n in case.names) for t in outcome.logged)
            return "good" if said else "silently-accepted"
        return "silently-accepted" if case.expect == REFUSE else "good"
    if case.expect == ACCEPT:
        return "wrongly-refused"
    if not isinstance(outcome.error, case.error):
        return "wrong-type"
    message = str(outcome.error).lower()
    if not all(n.lower() in message for n in case.names):
        return "vague"
    if outcome.unchanged is False:
        return "changed-state"
    return "good"


def tally(outcomes: list[Outcome]) -> Counter[str]:
    """Counts of verdicts, plus ``inputs``, ``refused``, ``accepted`` and ``accepted-odd`` (accepted on purpose:
    the case says why)."""
    counts: Counter[str] = Counter(verdict(o) for o in outcomes)
    counts["inputs"] = len(outcomes)
    counts["refused"] = sum(o.kind == "refused" for o in outcomes)
    counts["accepted"] = sum(o.kind == "ok" for o in outcomes)
    counts["accepted-odd"] = sum(o.kind == "ok" and bool(o.case.why) for o in outcomes)
    return counts
