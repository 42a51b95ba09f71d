"""Sample interfaces (and topics) of a running system every control cycle, for plots and checks.

A :class:`Recorder` hooks into the controller manager's loop (``add_cycle_hook``) and, after every
cycle, reads the value of each interface it watches from the resource manager. Nothing is claimed:
the recorder only looks, as ``ros2 control list_hardware_interfaces`` or a ``DynamicJointState``
echo would.

Interface names follow the resource manager: ``"joint1/position"`` is the state interface (or the
command or reference interface if no state interface has that name); ``"command:joint1/position"``
asks for the command interface explicitly, ``"state:joint1/position"`` for the state interface.
Reference interfaces of chainable controllers (``"pid_controller_joint1/joint1/position"``) are read
like command interfaces. The column of each interface is keyed by the name as given.

Example:
    >>> rec = Recorder(system, ["joint1/position", "command:joint1/position"])
    >>> system.spin(seconds=2.0)
    >>> rec.data["time"], rec.data["joint1/position"]
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from rrbot_workshop.exceptions import InterfaceNotFound

__all__ = ["Recorder", "split_kind"]

_log = logging.getLogger(__name__)

_KINDS = ("state", "command")


def split_kind(name: str) -> tuple[str | None, str]:
    """Split ``"command:joint1/position"`` into ``("command", "joint1/position")``; bare names give None."""
    head, sep, rest = name.partition(":")
    if sep and head in _KINDS:
        return head, rest
    return None, name


class Recorder:
    """Samples interface values after every control cycle of a system.

    Args:
        system: A running ``System`` (it needs ``controller_manager.add_cycle_hook`` and
            ``resource_manager.get_interface_value``; ``bus`` for ``topics``).
        interfaces: Interface names to sample (see the module docstring). None: every state interface,
            plus every command interface as ``"command:<name>"``.
        topics: Topic names whose messages are kept with their arrival time.
        max_samples: Keep at most this many cycles (oldest dropped); None keeps everything.

    Raises:
        InterfaceNotFound: If an interface does not exist when the recorder is created.
    """

    def __init__(
        self,
        system: Any,
        interfaces: Sequence[str] | None = None,
        topics: Iterable[str] = (),
        *,
        max_samples: int | None = None,
    ) -> None:
        self._system = system
        rm: Any = getattr(system, "resource_manager", None)
        self._rm: Any = rm if rm is not None else system.controller_manager.resource_manager
        if interfaces is None:
            interfaces = [*self._rm.state_interface_keys(), *(f"command:{n}" for n in self._rm.command_interface_keys())]
        self._names: list[str] = list(dict.fromkeys(interfaces))
        self._targets: list[tuple[str, str | None]] = []
        for name in self._names:
            kind, plain = split_kind(name)
            self._rm.get_interface_value(plain, kind)  # raises InterfaceNotFound for a bad name
            self._targets.append((plain, kind))
        self._max = max_samples
        self._time: list[float] = []
        self._rows: list[list[float]] = []
        self._messages: dict[str, list[tuple[float, Any]]] = {}
        self._subscriptions: list[Any] = []
        for topic in topics:
            self._messages[topic] = []
            sub = system.bus.create_subscription(
                None, topic, lambda msg, _t=topic: self._on_message(_t, msg), owner="recorder"
            )
            self._subscriptions.append(sub)
        self._active = True
        self._remove_hook: Any = system.controller_manager.add_cycle_hook(self._on_cycle)

    # ------------------------------------------------------------------------------------- sampling
    def _on_cycle(self, time: float, period: float) -> None:
        if not self._active:
            return
        row: list[float] = []
        for plain, kind in self._targets:
            try:
                value = self._rm.get_interface_value(plain, kind)
                row.append(float(value) if value is not None else math.nan)
            except (InterfaceNotFound, TypeError, ValueError):  # removed (controller unloaded) or not numeric
                row.append(math.nan)
        self._time.append(float(time))
        self._rows.append(row)
        if self._max is not None and len(self._time) > self._max:
            del self._time[0]
            del self._rows[0]

    def _on_message(self, topic: str, msg: Any) -> None:
        if not self._active:
            return
        time: Any = getattr(self._system, "time", None)
        if time is None:
            time = getattr(getattr(msg, "header", None), "stamp", math.nan)
        self._messages[topic].append((float(time), msg))

    def stop(self) -> None:
        """Stop sampling (data recorded so far stays)."""
        self._active = False
        if callable(self._remove_hook):  # the controller manager hands back a remover
            self._remove_hook()
        self._remove_hook = None
        for sub in self._subscriptions:
            sub.destroy()
        self._subscriptions.clear()

    def clear(self) -> None:
        """Forget every sample and message recorded so far."""
        self._time.clear()
        self._rows.clear()
        for messages in self._messages.values():
            messages.clear()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stop()

    # ------------------------------------------------------------------------------------- data
    @property
    def names(self) -> list[str]:
        """Recorded interface names (columns), in the order given."""
        return list(self._names)

    def __len__(self) -> int:
        return len(self._time)

    @property
    def time(self) -> np.ndarray:
        """Cycle times in [s]."""
        return np.asarray(self._time, dtype=float)

    @property
    def data(self) -> dict[str, np.ndarray]:
        """``{"time": times [s], "<interface>": values, ...}``, one entry per cycle."""
        table = np.asarray(self._rows, dtype=float).reshape(len(self._rows), len(self._names))
        out: dict[str, np.ndarray] = {"time": self.time}
        for index, name in enumerate(self._names):
            out[name] = table[:, index].copy()
        return out

    def __getitem__(self, name: str) -> np.ndarray:
        """Values of one interface (or ``"time"``).

        Raises:
            KeyError: If ``name`` is not recorded; the message lists what is.
        """
        if name == "time":
            return self.time
        if name not in self._names:
            raise KeyError(f"'{name}' is not recorded (recorded: {', '.join(['time', *self._names])})")
        index = self._names.index(name)
        return np.asarray([row[index] for row in self._rows], dtype=float)

    def messages(self, topic: str) -> list[tuple[float, Any]]:
        """``(time [s], message)`` pairs received on ``topic``.

        Raises:
            KeyError: If the topic is not recorded.
        """
        if topic not in self._messages:
            raise KeyError(f"topic '{topic}' is not recorded (recorded: {', '.join(sorted(self._messages)) or 'none'})")
        return list(self._messages[topic])

    def to_dict(self) -> dict[str, list[float]]:
        """The samples as plain lists (JSON-friendly): ``{"time": [...], "<interface>": [...]}``."""
        return {key: [float(v) for v in values] for key, values in self.data.items()}

    def __repr__(self) -> str:
        return f"<Recorder {len(self._names)} interfaces, {len(self)} samples>"
