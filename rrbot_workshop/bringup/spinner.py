"""Spinning a system in the background of the Jupyter kernel, so panels and plots move while no cell runs.

A real robot's ``ros2_control_node`` runs its loop in a thread of its own; the learner meanwhile types
``ros2 control ...`` in another terminal. In a notebook, :meth:`System.spin_in_background
<rrbot_workshop.bringup.System.spin_in_background>` gives the same feel: the control loop runs as an asyncio task on
the kernel's event loop, a batch of cycles every ``tick`` seconds of wall time, so that the simulated clock advances
``real_time_factor`` times as fast as the wall clock.

The kernel's event loop runs one thing at a time: while a cell executes, the loop waits; between cells (and while a
cell awaits, e.g. ``await asyncio.sleep(1)``) it spins. A cell, a panel's button and the loop therefore never touch
the system at the same moment, and nothing needs a lock. The task ends with :meth:`BackgroundSpinner.stop`, with
``system.shutdown()`` and with the kernel.

Time stays simulated: a cell that calls ``system.spin(1.0)`` still advances exactly one second. What a background
run does depends on wall time, so notebooks that nbval compares do not print its results.
"""

from __future__ import annotations

import asyncio
import logging
import math
import time as _wall
from typing import Any

from rrbot_workshop.exceptions import ArgumentError, HardwareError

__all__ = ["BackgroundSpinner"]

_log = logging.getLogger(__name__)


class BackgroundSpinner:
    """Runs ``system``'s control loop on the running asyncio event loop, paced by the wall clock.

    Args:
        system: A running system with a simulated clock.
        real_time_factor: Simulated seconds per wall second (1.0: real time).
        tick: Wall time between two batches of cycles [s].
        max_cycles_per_tick: At most this many cycles per batch; when the loop cannot keep up it runs slower than
            ``real_time_factor`` instead of catching up in a burst (None: one second of simulated time).

    Raises:
        HardwareError: If there is no running event loop (outside a Jupyter kernel or ``asyncio.run``), the clock
            is a wall clock (it paces itself and would block the kernel), or a factor or tick is not positive.
    """

    def __init__(self, system: Any, real_time_factor: float = 1.0, tick: float = 0.02,
                 max_cycles_per_tick: int | None = None) -> None:
        loop = self.check_arguments(system, real_time_factor, tick)
        self.system = system
        self.real_time_factor = float(real_time_factor)
        self.tick = float(tick)
        self.max_cycles_per_tick = int(max_cycles_per_tick or system.clock.update_rate)
        #: Cycles run by this spinner.
        self.cycles = 0
        #: The exception that stopped the loop, if one did (the loop logs it and stops; the kernel lives on).
        self.error: BaseException | None = None
        self._stopped = False
        self._task = loop.create_task(self._run(), name=f"spin {system.name}")

    @staticmethod
    def check_arguments(system: Any, real_time_factor: Any, tick: Any) -> asyncio.AbstractEventLoop:
        """Refuse what :class:`BackgroundSpinner` would refuse, before anything changes; return the running loop.

        Raises:
            ArgumentError: If a factor or tick is not a number.
            HardwareError: If it is not positive and finite, the clock is a wall clock, or no event loop runs.
        """
        from rrbot_workshop.middleware.clock import WallClock

        for argument, value in (("real_time_factor", real_time_factor), ("tick", tick)):
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ArgumentError("spin_in_background", argument, value, "a positive number")
        if not real_time_factor > 0 or not tick > 0 or math.isinf(real_time_factor) or math.isinf(tick):
            raise HardwareError(f"spin_in_background: real_time_factor ({real_time_factor}) and tick ({tick}) must be "
                                "positive and finite")
        if isinstance(system.clock, WallClock):
            raise HardwareError(f"system '{system.name}' runs on a wall clock, which paces itself and would block the "
                                "kernel; bring it up with the default simulated clock to spin it in the background")
        try:
            return asyncio.get_running_loop()
        except RuntimeError:
            raise HardwareError("spin_in_background needs a running event loop (a Jupyter kernel, or asyncio.run in a "
                                "script); without one call system.spin(seconds)") from None

    @property
    def running(self) -> bool:
        """Whether the loop still spins."""
        return not self._task.done() and not self._stopped

    def stop(self) -> None:
        """Stop spinning (the system stays up; ``spin`` works as before)."""
        self._stopped = True
        self._task.cancel()

    async def _run(self) -> None:
        system = self.system
        wall_start, sim_start = _wall.monotonic(), system.time
        try:
            while not self._stopped and system.running:
                behind = sim_start + (_wall.monotonic() - wall_start) * self.real_time_factor - system.time
                cycles = int(behind / system.period)
                if cycles > self.max_cycles_per_tick:  # cannot keep up: run slower rather than in bursts
                    cycles = self.max_cycles_per_tick
                    wall_start, sim_start = _wall.monotonic(), system.time + cycles * system.period
                if cycles > 0:
                    system.spin_cycles(cycles)
                    self.cycles += cycles
                await asyncio.sleep(self.tick)
        except asyncio.CancelledError:
            pass
        except Exception as exc:  # noqa: BLE001 - the kernel must live on; the error is kept and logged
            self.error = exc
            _log.error("the background loop of system '%s' stopped", system.name, exc_info=True)

    def __repr__(self) -> str:
        state = "spinning" if self.running else "stopped"
        return (f"<BackgroundSpinner {self.system.name}: {state}, x{self.real_time_factor:g} real time, "
                f"{self.cycles} cycles>")
