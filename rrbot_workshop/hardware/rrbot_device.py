"""A simulated RRBot device with the contract of the ROSCon 2022 workshop's comms library.

The original workshop's task 7 talks to the robot through a small header-only library (``DrDenisRRBotComms``). This
is that device, in Python, with the same calls and numbers, so a driver written against it reads like the original:

* ``RRBotDevice(number_of_dofs)``: every joint at position **0.1** rad, at rest, in POSITION mode, movement
  disabled; digital outputs all off;
* ``init()`` enables movement, ``stop()`` disables it (states then freeze);
* ``set_control_mode(ControlMode.POSITION | ControlMode.VELOCITY)`` (always accepted) and ``get_control_mode()``;
* ``write_joint_commands(positions, velocities, dt)``: moves the joints for ``dt`` seconds, never faster than
  ``MAX_VELOCITY`` = **0.5** rad/s. In POSITION mode each joint heads for its position command; in VELOCITY mode it
  moves at its velocity command, clamped to [-0.5, 0.5];
* ``read_joint_states()`` → positions [rad], velocities [rad/s], accelerations [rad/s²];
* ``write_gpios(outputs)`` and ``read_gpio()`` → (inputs, outputs): the outputs read back as written, the inputs
  are random bits;
* ``read_sensor_values(n)``: ``n`` force-torque values in [0, ``SENSOR_MAX`` = **23.28**].

Differences from the original, on purpose:

* **time**: the original measures ``dt`` on the wall clock between two writes, so the robot's motion depended on how
  fast the computer ran; here ``dt`` is passed in (the controller manager's period), so a run is reproducible;
* **randomness**: the original seeds with the wall clock (``time(NULL)``); here a ``seed`` makes sensor and input
  values reproducible. Like the original's, a sensor value stays the same within one second (of simulated time);
* **the velocity clamp**: the original's VELOCITY mode clamps with ``v < MAX_VELOCITY ? -MAX_VELOCITY : v`` for the
  lower bound, so every command below +0.5 rad/s (0.2 included) became -0.5 rad/s; here it is ``max(v, -0.5)``;
* a NaN command (a controller that wrote nothing yet) holds the joint instead of spreading NaN into the states.
"""

from __future__ import annotations

import enum
import math
import random
from collections.abc import Sequence

__all__ = ["ControlMode", "RRBotDevice", "MAX_VELOCITY", "SENSOR_MAX", "INITIAL_POSITION"]

#: Highest joint speed of the device in [rad/s].
MAX_VELOCITY = 0.5
#: Highest force-torque sensor value (N or N m; the original gives no unit).
SENSOR_MAX = 23.28
#: Where every joint starts, in [rad].
INITIAL_POSITION = 0.1


class ControlMode(enum.IntEnum):
    """The device's control modes (``control_mode_type`` of the original)."""

    POSITION = 0
    VELOCITY = 1


def _clamp(value: float, limit: float) -> float:
    return min(max(value, -limit), limit)


class RRBotDevice:
    """The simulated RRBot behind a driver.

    Args:
        number_of_dofs: Number of joints.
        seed: Seed of the random sensor and input values.
    """

    def __init__(self, number_of_dofs: int, seed: int = 0) -> None:
        if number_of_dofs < 1:
            raise ValueError(f"an RRBot device needs at least one joint, got number_of_dofs={number_of_dofs}")
        self.number_of_dofs = number_of_dofs
        self.seed = seed
        self._positions = [INITIAL_POSITION] * number_of_dofs
        self._velocities = [0.0] * number_of_dofs
        self._accelerations = [0.0] * number_of_dofs
        self._digital_outs = [False] * number_of_dofs
        self._mode = ControlMode.POSITION
        self._enabled = False
        self._time = 0.0  # simulated time since construction [s], the sum of the dt passed in
        self._rng = random.Random(seed)

    # ----------------------------------------------------------------- lifecycle and mode
    def init(self) -> None:
        """Enable movement (the original also starts its wall-clock timer here)."""
        self._enabled = True

    def stop(self) -> None:
        """Disable movement: the joints stop where they are."""
        self._enabled = False
        self._velocities = [0.0] * self.number_of_dofs
        self._accelerations = [0.0] * self.number_of_dofs

    @property
    def movement_enabled(self) -> bool:
        """True between :meth:`init` and :meth:`stop`."""
        return self._enabled

    def set_control_mode(self, mode: ControlMode) -> bool:
        """Switch between POSITION and VELOCITY; always accepted (returns True), as the original."""
        self._mode = ControlMode(mode)
        return True

    def get_control_mode(self) -> ControlMode:
        """The current control mode."""
        return self._mode

    # ----------------------------------------------------------------- joints
    def write_joint_commands(self, positions: Sequence[float], velocities: Sequence[float], dt: float) -> None:
        """Move the joints for ``dt`` [s] under the commands of the current mode (both lists have one value per joint).

        Raises:
            ValueError: If a list does not have one value per joint, or ``dt`` is negative.
        """
        for name, values in (("positions", positions), ("velocities", velocities)):
            if len(values) != self.number_of_dofs:
                raise ValueError(f"write_joint_commands: {len(values)} {name} for {self.number_of_dofs} joints")
        if dt < 0.0:
            raise ValueError(f"write_joint_commands: dt must not be negative, got {dt}")
        self._time += dt
        if not self._enabled or dt == 0.0:
            return  # frozen: time passes, nothing moves
        for i in range(self.number_of_dofs):
            if self._mode is ControlMode.POSITION:
                target = positions[i]
                v = 0.0 if math.isnan(target) else _clamp((target - self._positions[i]) / dt, MAX_VELOCITY)
            else:
                command = velocities[i]
                v = 0.0 if math.isnan(command) else _clamp(command, MAX_VELOCITY)
            self._accelerations[i] = (v - self._velocities[i]) / dt
            self._velocities[i] = v
            self._positions[i] += v * dt

    def read_joint_states(self) -> tuple[list[float], list[float], list[float]]:
        """Positions [rad], velocities [rad/s] and accelerations [rad/s²], as new lists."""
        return list(self._positions), list(self._velocities), list(self._accelerations)

    # ----------------------------------------------------------------- I/O
    def write_gpios(self, outputs: Sequence[bool]) -> None:
        """Set the digital outputs (one per joint, as the original sizes them).

        Raises:
            ValueError: If there is not one output per joint.
        """
        if len(outputs) != self.number_of_dofs:
            raise ValueError(f"write_gpios: {len(outputs)} outputs for a device with {self.number_of_dofs}")
        self._digital_outs = [bool(v) for v in outputs]

    def read_gpio(self) -> tuple[list[bool], list[bool]]:
        """(inputs, outputs): random input bits (nothing is wired to them) and the outputs as written."""
        return [self._rng.random() < 0.5 for _ in range(self.number_of_dofs)], list(self._digital_outs)

    def read_sensor_values(self, count: int) -> list[float]:
        """``count`` force-torque values in [0, SENSOR_MAX]; each stays the same within one second of device time."""
        second = int(self._time)
        return [random.Random(f"{self.seed}/{second}/{i}").random() * SENSOR_MAX for i in range(count)]
