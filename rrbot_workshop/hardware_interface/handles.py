"""State and command interface handles.

In ros2_control a hardware component *owns* each value it exposes; the resource manager keeps one
handle per ``"<prefix>/<interface>"`` name, and controllers *borrow* handles through loans. Here a
handle is a small object naming one slot of a flat list of values; a loan is a thin view on a handle that the
resource manager hands out and takes back.

**Flat storage.** A new handle keeps its value in a list of its own. When the resource manager takes a component's
handles (or a chainable controller's exported ones) it *adopts* them (:func:`adopt`): their values move into the
storage's one flat list and each handle keeps only its index. ``get_value``/``set_value`` work the same either way;
what changes is that code prepared once can move many values in one call: :func:`value_reader` reads all the loans
of a controller with one ``operator.itemgetter`` over the flat list.
"""

from __future__ import annotations

import functools
import math
import operator
from collections.abc import Callable, Sequence
from typing import Any

from rrbot_workshop.exceptions import DescriptionError

__all__ = [
    "SUPPORTED_DATA_TYPES",
    "Handle",
    "StateInterface",
    "CommandInterface",
    "LoanedStateInterface",
    "LoanedCommandInterface",
    "parse_value",
    "value_reader",
    "value_snapshot",
    "value_writer",
    "adopt",
    "ADOPTIONS",
]

#: Data types ros2_control handles accept, mapped to the Python type used to hold them.
SUPPORTED_DATA_TYPES: dict[str, type] = {
    "double": float,
    "float32": float,
    "bool": bool,
    "int8": int,
    "uint8": int,
    "int16": int,
    "uint16": int,
    "int32": int,
    "uint32": int,
}

_INT_MAX = {
    "int8": 2**7 - 1,
    "uint8": 2**8 - 1,
    "int16": 2**15 - 1,
    "uint16": 2**16 - 1,
    "int32": 2**31 - 1,
    "uint32": 2**32 - 1,
}


def parse_value(text: str | None, data_type: str = "double", *, where: str = "") -> Any:
    """Convert an ``initial_value`` string to the handle's type.

    An empty or missing value gives NaN for floating types, ``False`` for bool and the type's maximum
    for integers, as ros2_control does. Floats are parsed independently of the locale.

    Args:
        text: The text from the description, or None.
        data_type: One of :data:`SUPPORTED_DATA_TYPES`.
        where: Name of the interface, used in error messages.

    Raises:
        DescriptionError: If the data type is unsupported or the text cannot be converted.
    """
    if data_type not in SUPPORTED_DATA_TYPES:
        raise DescriptionError(
            f"data_type '{data_type}' of '{where}' is not supported (valid: {', '.join(SUPPORTED_DATA_TYPES)})"
        )
    text = (text or "").strip()
    try:
        if data_type in ("double", "float32"):
            return math.nan if not text else float(text)
        if data_type == "bool":
            if not text:
                return False
            if text.lower() in ("true", "1"):
                return True
            if text.lower() in ("false", "0"):
                return False
            raise ValueError(text)
        return _INT_MAX[data_type] if not text else int(text)
    except ValueError as exc:
        raise DescriptionError(f"initial value '{text}' of '{where}' is not a valid {data_type}") from exc


class _Counter:
    """A number that only goes up (see :data:`ADOPTIONS`)."""

    __slots__ = ("value",)

    def __init__(self) -> None:
        self.value = 0


#: Moved by every :func:`adopt` that moves a handle: code that prepared the stores and indices of handles (a
#: hardware component's read plan) prepares them again when it has moved.
ADOPTIONS = _Counter()


class Handle:
    """One named value: ``"<prefix_name>/<interface_name>"``, held in a slot of a flat list (see the module's notes).

    Args:
        prefix_name: Joint, sensor, GPIO or controller name (``"joint1"``).
        interface_name: Interface name (``"position"``).
        data_type: One of :data:`SUPPORTED_DATA_TYPES`.
        initial_value: Initial value; NaN by default for doubles.
    """

    __slots__ = ("_prefix_name", "_interface_name", "_data_type", "_name", "_store", "_index")

    def __init__(
        self, prefix_name: str, interface_name: str, data_type: str = "double", initial_value: Any = None
    ) -> None:
        if data_type not in SUPPORTED_DATA_TYPES:
            raise DescriptionError(
                f"interface '{prefix_name}/{interface_name}' has unsupported data_type '{data_type}' "
                f"(valid: {', '.join(SUPPORTED_DATA_TYPES)})"
            )
        self._prefix_name = prefix_name
        self._interface_name = interface_name
        self._data_type = data_type
        self._name = f"{prefix_name}/{interface_name}"
        value = parse_value(None, data_type, where=self._name) if initial_value is None else initial_value
        #: The flat list holding the value, and the value's index in it (a list of its own until adopted).
        self._store: list[Any] = [value]
        self._index = 0

    @property
    def name(self) -> str:
        """Full name, ``"<prefix_name>/<interface_name>"``."""
        return self._name

    @property
    def prefix_name(self) -> str:
        """Joint, sensor, GPIO or controller name."""
        return self._prefix_name

    @property
    def interface_name(self) -> str:
        """Interface name, e.g. ``"position"``."""
        return self._interface_name

    @property
    def data_type(self) -> str:
        """Data type name, e.g. ``"double"``."""
        return self._data_type

    def get_value(self) -> Any:
        """Current value."""
        return self._store[self._index]

    def set_value(self, value: Any) -> None:
        """Store a new value."""
        self._store[self._index] = value

    # ros2_control Jazzy method names
    def get_name(self) -> str:
        """Full name, as :attr:`name`."""
        return self._name

    def get_prefix_name(self) -> str:
        """Prefix name, as :attr:`prefix_name`."""
        return self._prefix_name

    def get_interface_name(self) -> str:
        """Interface name, as :attr:`interface_name`."""
        return self._interface_name

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._name!r}, value={self.get_value()!r})"


class StateInterface(Handle):
    """A value the hardware (or a chainable controller) reports."""

    __slots__ = ()


class CommandInterface(Handle):
    """A value a controller writes and the hardware (or a chained controller) consumes."""

    __slots__ = ()


class _Loaned:
    """A borrowed handle; the release callback runs once when the loan is returned."""

    __slots__ = ("_handle", "_release")

    def __init__(self, handle: Handle, release: Callable[[], None] | None = None) -> None:
        self._handle = handle
        self._release = release

    @property
    def name(self) -> str:
        """Full interface name."""
        return self._handle.name

    @property
    def prefix_name(self) -> str:
        """Joint, sensor, GPIO or controller name."""
        return self._handle.prefix_name

    @property
    def interface_name(self) -> str:
        """Interface name, e.g. ``"position"``."""
        return self._handle.interface_name

    @property
    def data_type(self) -> str:
        """Data type name of the borrowed handle, e.g. ``"double"``."""
        return self._handle.data_type

    def get_name(self) -> str:
        return self._handle.name

    def get_prefix_name(self) -> str:
        return self._handle.prefix_name

    def get_interface_name(self) -> str:
        return self._handle.interface_name

    def get_value(self) -> Any:
        """Current value of the borrowed handle."""
        handle = self._handle
        return handle._store[handle._index]

    def release(self) -> None:
        """Give the handle back. Safe to call more than once."""
        if self._release is not None:
            release, self._release = self._release, None
            release()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r}, value={self.get_value()!r})"


class LoanedStateInterface(_Loaned):
    """Read-only loan of a state interface."""

    __slots__ = ()


class LoanedCommandInterface(_Loaned):
    """Read-write loan of a command interface (at most one exists per interface)."""

    __slots__ = ()

    def set_value(self, value: Any) -> None:
        """Write a command."""
        handle = self._handle
        handle._store[handle._index] = value


def adopt(handles: Sequence[Handle], store: list[Any]) -> None:
    """Move the values of ``handles`` into the flat list ``store`` (the resource manager's): each value is appended
    and its handle points at it from then on. Handles already in ``store`` stay where they are."""
    moved = False
    for handle in handles:
        if handle._store is not store:
            value = handle._store[handle._index]
            handle._store, handle._index = store, len(store)
            store.append(value)
            moved = True
    if moved:
        ADOPTIONS.value += 1


def _shared_store(handles: Sequence[Handle]) -> list[Any] | None:
    """The one flat list all ``handles`` live in, or None if they live in several."""
    stores = {id(h._store): h._store for h in handles}
    return next(iter(stores.values())) if len(stores) == 1 else None


def value_reader(loans: Sequence[_Loaned]) -> Callable[[], list[Any]]:
    """A function that returns the current values of ``loans``, in order, in one call.

    It is how a controller prepared at activation reads many interfaces per cycle without a method call per value;
    it stays valid while the loans are held (a controller builds it in ``on_activate`` and drops it on deactivate).
    When the loans' handles live in one flat list (they do once the resource manager holds them), the values are
    read with one ``operator.itemgetter`` call.
    """
    handles = [loan._handle for loan in loans]
    store = _shared_store(handles)
    if store is None or not handles:  # a harness's own handles, or nothing to read
        return lambda: [h._store[h._index] for h in handles]
    indices = [h._index for h in handles]
    if len(indices) == 1:
        index = indices[0]
        return lambda: [store[index]]
    get = operator.itemgetter(*indices)
    return lambda: list(get(store))


def value_snapshot(loans: Sequence[_Loaned]) -> Callable[[], tuple[Any, ...]]:
    """Like :func:`value_reader`, with the values as a tuple: for a controller that only passes them on (a broadcaster
    hands them to its messages). With two or more loans in one flat list, the function is an ``operator.itemgetter``
    bound to that list (``functools.partial``): reading them runs no Python code at all."""
    handles = [loan._handle for loan in loans]
    store = _shared_store(handles)
    if store is None or len(handles) < 2:
        return lambda: tuple([h._store[h._index] for h in handles])
    return functools.partial(operator.itemgetter(*[h._index for h in handles]), store)


def value_writer(loans: Sequence[LoanedCommandInterface]) -> Callable[[Sequence[Any]], None]:
    """A function that writes one value to each of ``loans``, in order, in one call (see :func:`value_reader`)."""
    handles = [loan._handle for loan in loans]
    store = _shared_store(handles)
    if store is None:
        def write_each(values: Sequence[Any]) -> None:
            for handle, value in zip(handles, values):  # noqa: B905 - extra values ignored; strict= is slow
                handle._store[handle._index] = value

        return write_each
    indices = [h._index for h in handles]

    def write(values: Sequence[Any]) -> None:
        for index, value in zip(indices, values):  # noqa: B905 - extra values ignored; strict= is slow
            store[index] = value

    return write
