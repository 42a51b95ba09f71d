"""More of the random sequences of tests/unit/test_invariants_random_sequences.py than CI runs.

Run: ``.venv/bin/python benchmarks/fuzz_switches.py [sequences] [steps]`` (default 200 x 1000 = 200,000 operations).
Prints the number of operations and sequences per second; a violated invariant stops it with the seed to replay.
"""

from __future__ import annotations

import logging
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "unit"))

import test_invariants_random_sequences as invariants  # noqa: E402


def main(argv: list[str]) -> None:
    sequences = int(argv[1]) if len(argv) > 1 else 200
    steps = int(argv[2]) if len(argv) > 2 else 1000
    logging.disable(logging.CRITICAL)
    start = time.perf_counter()
    for seed in range(sequences):
        rng = random.Random(10_000 + seed)
        system = invariants._start()
        try:
            for _ in range(steps):
                invariants._step(system, rng)
        except AssertionError as exc:
            print(f"seed {10_000 + seed}: {exc}")
            raise SystemExit(1) from exc
        finally:
            system.shutdown()
    elapsed = time.perf_counter() - start
    print(f"{sequences * steps} operations in {sequences} sequences without a violation "
          f"({sequences * steps / elapsed:.0f} operations/s)")


if __name__ == "__main__":
    main(sys.argv)
