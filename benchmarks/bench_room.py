"""A workshop room on this machine: JupyterHub on 127.0.0.1 and N learners at once, each running notebook 02 and
grading task 2 (half of them with a solved exercise).

Run: ``.venv/bin/python benchmarks/bench_room.py [--learners 10 30] [--arrival 0]``. Learners log in ``--arrival``
seconds apart (0: all at the same second; a real room arrives over a minute or two). For each room size it prints, per
learner: the
memory of the room's processes (hub, proxy, servers, kernels; RSS at the end, when every kernel is still alive)
divided by N, the CPU seconds they used divided by N, the time from login to the graded result (median and
maximum), and the 95th percentile of cell execution time while the room works; and whether every grade was right.
Nothing is asserted. Everything is stopped at the end and the count of processes left is printed (0 expected).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from rrbot_workshop.classroom.room import Room

ROOT = Path(__file__).resolve().parents[1]
SOLUTION = ROOT / "solutions" / "task02_mock_hardware"
TICKS = os.sysconf("SC_CLK_TCK")


def _solve(workspace: Path) -> None:
    target = workspace / "exercises" / "task02_mock_hardware"
    shutil.rmtree(target)
    shutil.copytree(SOLUTION, target, ignore=shutil.ignore_patterns("__pycache__"))


def _rss_and_cpu(pids: list[int]) -> tuple[float, float]:
    """Total resident memory [MiB] and CPU time [s] (user + system, the process's own) of ``pids``."""
    rss = cpu = 0.0
    for pid in pids:
        try:
            status = Path(f"/proc/{pid}/status").read_text()
            stat = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        rss += next(int(line.split()[1]) for line in status.splitlines() if line.startswith("VmRSS:")) / 1024
        cpu += (int(stat[11]) + int(stat[12])) / TICKS
    return rss, cpu


def room_of(n: int, arrival: float = 0.0) -> dict[str, float | int | bool]:
    """Run a room of ``n`` learners arriving ``arrival`` seconds apart; its figures."""
    with tempfile.TemporaryDirectory(prefix="rrbot_room_") as folder:
        room = Room(Path(folder), timeout=600.0)
        start = time.monotonic()
        try:
            room.start()
            hub_up = time.monotonic() - start
            names = [f"learner{i:02d}" for i in range(n)]
            with ThreadPoolExecutor(max_workers=n) as pool:
                futures = []
                for i, name in enumerate(names):
                    if i and arrival:
                        time.sleep(arrival)
                    futures.append(pool.submit(room.learner_session, name, prepare=_solve if i % 2 == 0 else None))
                runs = [f.result() for f in futures]
            rss, cpu = _rss_and_cpu(list(room.processes()))
        finally:
            left = room.stop()
    cells = sorted(t for run in runs for t in run.cell_s)
    firsts = [run.first_result_s for run in runs]
    right = all(run.score == ((run.score[1], run.score[1]) if i % 2 == 0 else (0.0, run.score[1])) and run.score[1] > 0
                and not run.errors for i, run in enumerate(runs))
    return {"learners": n, "arrival_s": arrival, "hub_start_s": round(hub_up, 1), "rss_mib_per_learner": round(rss / n, 1),
            "cpu_s_per_learner": round(cpu / n, 1), "first_result_median_s": round(statistics.median(firsts), 1),
            "first_result_max_s": round(max(firsts), 1),
            "cell_p95_s": round(cells[min(len(cells) - 1, int(0.95 * len(cells)))], 2),
            "grades_right": right, "processes_left": len(left)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--learners", type=int, nargs="+", default=[10, 30], help="room sizes")
    parser.add_argument("--arrival", type=float, default=0.0, help="seconds between two learners' logins")
    args = parser.parse_args()
    if not args.arrival >= 0.0:
        parser.error("--arrival must be 0 or more seconds")
    if not SOLUTION.is_dir():
        parser.error("needs solutions/ (half of the learners hand in the solved task 2)")
    for n in args.learners:
        if n < 1:
            parser.error("a room has at least one learner")
        print(room_of(n, args.arrival), flush=True)


if __name__ == "__main__":
    main()
