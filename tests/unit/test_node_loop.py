"""The node's loop runs a batch of cycles with the garbage collector paused, and always gives it back as it was."""

from __future__ import annotations

import gc
from collections.abc import Iterator

import pytest

from rrbot_workshop.controller_manager import node_loop
from rrbot_workshop.controller_manager.node_loop import run_cycles


@pytest.fixture(autouse=True)
def _collector_restored() -> Iterator[None]:
    was = gc.isenabled()
    yield
    gc.enable() if was else gc.disable()


def test_cycles_run_in_order_with_the_collector_paused_and_it_comes_back() -> None:
    gc.enable()
    seen: list[tuple[float, float, bool]] = []
    times = iter([0.01, 0.02, 0.03])
    run_cycles(lambda t, p: seen.append((t, p, gc.isenabled())), lambda: next(times), 0.01, 3)
    assert seen == [(0.01, 0.01, False), (0.02, 0.01, False), (0.03, 0.01, False)]
    assert gc.isenabled()


def test_a_cycle_that_raises_still_gives_the_collector_back() -> None:
    gc.enable()

    def broken(time: float, period: float) -> None:
        raise RuntimeError("boom")

    with pytest.raises(RuntimeError, match="boom"):
        run_cycles(broken, lambda: 0.0, 0.01, 5)
    assert gc.isenabled()


def test_a_disabled_collector_stays_disabled_and_is_never_run(monkeypatch: pytest.MonkeyPatch) -> None:
    gc.disable()
    collected: list[int] = []
    monkeypatch.setattr(node_loop.gc, "collect", lambda generation=2: collected.append(generation) or 0)
    monkeypatch.setattr(node_loop, "GC_EVERY", 2)
    count = [0]
    run_cycles(lambda t, p: count.__setitem__(0, count[0] + 1), lambda: 0.0, 0.01, 5)
    assert count[0] == 5 and collected == [] and not gc.isenabled()


def test_a_long_batch_collects_the_youngest_generation_between_its_parts(monkeypatch: pytest.MonkeyPatch) -> None:
    gc.enable()
    events: list[str] = []
    monkeypatch.setattr(node_loop.gc, "collect", lambda generation=2: events.append(f"gc{generation}") or 0)
    monkeypatch.setattr(node_loop, "GC_EVERY", 2)
    run_cycles(lambda t, p: events.append("cycle"), lambda: 0.0, 0.01, 5)
    assert events == ["cycle", "cycle", "gc0", "cycle", "cycle", "gc0", "cycle"]
