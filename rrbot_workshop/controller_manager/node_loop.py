"""The loop of ``ros2_control_node``: the controller manager's cycle run again and again on a clock.

In ros2_control a thread of the node calls ``read``, ``update`` and ``write`` at the manager's rate. Here
:func:`run_cycles` runs a batch of cycles for :meth:`rrbot_workshop.System.spin_cycles` (and through it ``spin``,
``spin_until`` and the background spinner). A real-time loop does not let a garbage collector stop it at random; in
Python the generational collector was a fifth of the cycle, walking the messages every topic keeps in its history. So
the collector is paused while the cycles run, and only its youngest generation is collected every :data:`GC_EVERY`
cycles of a long batch. Reference counting still frees at once everything a cycle makes, and the collector is back as
it was when the batch ends (also when a cycle raises).
"""

from __future__ import annotations

import gc
from collections.abc import Callable

__all__ = ["GC_EVERY", "run_cycles"]

#: Within one batch, the youngest generation of the garbage collector is collected every so many cycles.
GC_EVERY = 20000


def run_cycles(update: Callable[[float, float], None], tick: Callable[[], float], period: float, n: int) -> None:
    """Call ``update(tick(), period)`` ``n`` times with the garbage collector paused (see the module's notes).

    Args:
        update: One control cycle, ``ControllerManager.update``.
        tick: The clock's tick: advances the time and returns it (a wall clock sleeps there to keep pace).
        period: The manager's period in [s].
        n: Number of cycles.
    """
    collecting = gc.isenabled()
    if collecting:
        gc.disable()
    try:
        for start in range(0, n, GC_EVERY):
            for _ in range(min(GC_EVERY, n - start)):
                update(tick(), period)
            if collecting and start + GC_EVERY < n:  # between two parts of a long batch
                gc.collect(0)
    finally:
        if collecting:
            gc.enable()
