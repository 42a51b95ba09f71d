"""Tests of hardware.mujoco_io: the prepared state reads of MujocoSystem give what the plain formula gives.

The state reader sets ``sign * value + 0.0`` in each handle's slot; these tests compare its results bit for bit with the
Python expression, for signed zeros, infinities and NaNs, for handles in one flat list or in several.
"""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest

from rrbot_workshop.hardware.mujoco_io import StateSource, state_reader
from rrbot_workshop.hardware_interface.handles import StateInterface, adopt

# Values whose result could tell two computations apart: signed zeros, infinities, NaNs with sign and payload.
_NAN_PAYLOAD = struct.unpack("<d", struct.pack("<Q", 0x7FF8_0000_0000_1234))[0]
_NEG_NAN = struct.unpack("<d", struct.pack("<Q", 0xFFF8_0000_0000_0000))[0]
_SPECIAL = [0.0, -0.0, 1.5, -2.25, 5e-324, -5e-324, math.inf, -math.inf, math.nan, _NEG_NAN, _NAN_PAYLOAD, 1e308]


def _bits(value: float) -> int:
    return struct.unpack("<Q", struct.pack("<d", value))[0]


def _handles(count: int) -> list[StateInterface]:
    return [StateInterface(f"s{k}", "value", initial_value=math.nan) for k in range(count)]


def _sources(arrays: list[np.ndarray], handles: list[StateInterface], signs: str) -> list[StateSource]:
    """Every element of ``arrays`` read by one handle; signs alternating per element, per array, or all kept."""
    pairs = [(n, array, index) for n, array in enumerate(arrays) for index in range(array.size)]
    sign = {"per-element": lambda k, n: -1.0 if k % 2 else 1.0, "per-array": lambda k, n: -1.0 if n % 2 else 1.0,
            "all-kept": lambda k, n: 1.0}[signs]
    return [(array, index, sign(k, n), handle)
            for k, ((n, array, index), handle) in enumerate(zip(pairs, handles, strict=True))]


@pytest.mark.parametrize("signs", ["per-element", "per-array", "all-kept"])
@pytest.mark.parametrize("flat", [True, False], ids=["one-flat-list", "own-lists"])
def test_state_reader_matches_the_python_formula_bit_for_bit(flat: bool, signs: str) -> None:
    """Slots set one by one, in slices, or all in one slice (one flat list, every sign kept) give the same values."""
    buffer = np.zeros(64)
    arrays = [buffer[3:3 + 7], buffer[20:20 + 5], buffer[40:40 + 12]]
    handles = _handles(24)
    if flat:
        adopt(handles[::-1], ["x", "y"])  # one flat list, slots in reverse order after two foreign values
    sources = _sources(arrays, handles, signs)
    read = state_reader(sources)
    for shift in range(len(_SPECIAL)):  # every value under both signs
        for array in arrays:
            array[:] = np.roll(np.resize(np.array(_SPECIAL), array.size), shift)
        read()
        for array, index, sign, handle in sources:
            expected = sign * array.tolist()[index] + 0.0
            value = handle.get_value()
            assert type(value) is float and _bits(value) == _bits(expected), (handle.name, value, expected)


def test_state_reader_leaves_other_slots_alone_and_checks_its_sources() -> None:
    data = np.arange(6.0)
    handles = _handles(3)
    store: list[object] = ["keep"]
    adopt(handles, store)
    store.append("also kept")
    state_reader([(data, 5, 1.0, handles[0]), (data, 0, -1.0, handles[2])])()
    assert (store[0], store[1], store[3], store[4]) == ("keep", 5.0, 0.0, "also kept")
    assert math.isnan(store[2]) and _bits(store[3]) == 0  # type: ignore[arg-type]  # -(0.0) + 0.0 is +0.0
    with pytest.raises(IndexError, match="element 6"):
        state_reader([(data, 6, 1.0, handles[0])])
    with pytest.raises(ValueError, match="sign"):
        state_reader([(data, 0, 2.0, handles[0])])
    state_reader([])()  # nothing to read
