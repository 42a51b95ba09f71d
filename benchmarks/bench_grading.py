"""Seconds to grade each task, as a learner's self-check runs it (a fresh process per grading).

Run: ``.venv/bin/python benchmarks/bench_grading.py [--runs 3] [--track solutions] [--tasks 1 2 ...]``. Each task is
graded ``--runs`` times on the chosen track, one after the other, and the minimum, median and maximum wall time are
printed with the score, and the median CPU time the grader process used (user + system): on a busy machine the wall
time grows with the load, the CPU time does not, and on an idle one the two are close (a grader runs in one thread).
Nothing is asserted; the course's target is at most 5 s per task on an idle 2-core machine.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import time

from rrbot_workshop.course.grading import grade, graded_tasks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="gradings per task")
    parser.add_argument("--track", default="solutions", choices=["solutions", "exercises"])
    parser.add_argument("--tasks", type=int, nargs="*", default=None, help="task numbers (default: all graded)")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error("--runs must be at least 1")
    print(f"{'task':>4}  {'min s':>6}  {'median s':>8}  {'max s':>6}  {'cpu s':>6}  score")
    for task in args.tasks or graded_tasks():
        times, cpu = [], []
        for _ in range(args.runs):
            used = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            rubric = grade(task, track=args.track, record=False)
            times.append(time.perf_counter() - start)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu.append(after.ru_utime - used.ru_utime + after.ru_stime - used.ru_stime)
        print(f"{task:>4}  {min(times):6.2f}  {statistics.median(times):8.2f}  {max(times):6.2f}  "
              f"{statistics.median(cpu):6.2f}  {rubric.score:g}/{rubric.max_score:g}")


if __name__ == "__main__":
    main()
