"""A workshop room on this machine: JupyterHub on 127.0.0.1 and N learners at once, each running notebook 02 and
grading task 2 (half of them with a solved exercise).

Run: ``.venv/bin/python benchmarks/bench_room.py [--learners 10 30] [--arrival 0] [--warm]``. Learners log in
``--arrival`` seconds apart (0: all at the same second). With ``--warm``, the room is warmed first as an instructor
warms it before the workshop (``rrbot-workshop room warm``: every learner's server started through the hub's API, a
few at a time), and the learners arrive after. As root, every learner is a Unix account of their own (as on The
Littlest JupyterHub); ``--shared-user`` runs every server as this user instead.

Every process counts, finished ones included: a process's CPU time is its own (``utime``, ``stime`` in
``/proc/<pid>/stat``) plus that of its children that ended and were waited for (``cutime``, ``cstime``), so the
grader's pytest process, gone by the time the grade is shown, is in its kernel's count. Per learner, from login to
the graded result: their server's process tree (server, kernel, grader) between the two moments, plus an equal
share of the hub's, the proxy's and the live view's. Memory per learner: the resident size (RSS) of their server's
tree at the end, every kernel still alive, and the proportional one (PSS: shared pages divided among the processes
that share them), plus an equal share of the hub's. Printed: median and maximum over the learners, the warm-up's
cost, whether every grade was right and how many processes were left (0 expected). Nothing is asserted.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from rrbot_workshop.classroom.hub import HubAPI, warm_room
from rrbot_workshop.classroom.room import Room, portable_python

ROOT = Path(__file__).resolve().parents[1]
SOLUTION = ROOT / "solutions" / "task02_mock_hardware"
TICKS = os.sysconf("SC_CLK_TCK")


def _solve(workspace: Path) -> None:
    target = workspace / "exercises" / "task02_mock_hardware"
    shutil.rmtree(target)
    shutil.copytree(SOLUTION, target, ignore=shutil.ignore_patterns("__pycache__"))


def _table() -> dict[int, tuple[int, float, str]]:
    """Every process: pid -> (parent pid, CPU seconds with its waited-for children, command line)."""
    table = {}
    for proc in Path("/proc").glob("[0-9]*"):
        try:
            stat = (proc / "stat").read_text().rsplit(")", 1)[1].split()
            cmdline = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        table[int(proc.name)] = (int(stat[1]), sum(int(x) for x in stat[11:15]) / TICKS, cmdline)
    return table


def _tree(table: dict[int, tuple[int, float, str]], root: int) -> list[int]:
    children: dict[int, list[int]] = {}
    for pid, (ppid, _, _) in table.items():
        children.setdefault(ppid, []).append(pid)
    out, todo = [], [root]
    while todo:
        pid = todo.pop()
        out.append(pid)
        todo.extend(children.get(pid, []))
    return out


def _server_of(table: dict[int, tuple[int, float, str]], room: Room, name: str) -> int | None:
    mark = f"--ServerApp.root_dir={room.homes / name}/"
    return next((pid for pid, (_, _, cmd) in table.items() if mark in cmd), None)


def _cpu(table: dict[int, tuple[int, float, str]], pids: list[int]) -> float:
    return sum(table[p][1] for p in pids if p in table)


def _memory(pids: list[int]) -> tuple[float, float]:
    """RSS and PSS of ``pids`` [MiB]."""
    rss = pss = 0.0
    for pid in pids:
        try:
            for line in Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines():
                if line.startswith("Rss:"):
                    rss += int(line.split()[1]) / 1024
                elif line.startswith("Pss:"):
                    pss += int(line.split()[1]) / 1024
        except OSError:
            continue
    return rss, pss


def _shared(room: Room, table: dict[int, tuple[int, float, str]]) -> list[int]:
    """The hub and what it runs that belongs to no learner: the proxy, the live view, the room's service."""
    assert room.process is not None
    servers = {p for p, (_, _, cmd) in table.items() if "--ServerApp.root_dir=" in cmd}
    learners: set[int] = set()
    for server in servers:
        learners.update(_tree(table, server))
    return [p for p in _tree(table, room.process.pid) if p not in learners]


def room_of(n: int, arrival: float = 0.0, warm: bool = False, unix_users: bool = False,
            stagger: float = 1.0, at_once: int = 3) -> dict[str, object]:
    """Run a room of ``n`` learners arriving ``arrival`` seconds apart; its figures."""
    base = Path(tempfile.mkdtemp(prefix="rrbot_bench_room_", dir="/tmp"))
    base.chmod(0o755)
    try:
        python = portable_python(base / "python") if unix_users else None
        room = Room(base / "room", python=python, timeout=900.0, unix_users=unix_users)
        names = [room.name(f"learner{i:02d}") for i in range(n)]
        cpu_at: dict[tuple[str, str], float] = {}
        lock = threading.Lock()
        warm_figures: dict[str, float] = {}
        try:
            room.start()
            shared_start = _cpu(table := _table(), _shared(room, table))
            if warm:
                for name in names:
                    room.add_account(name)
                begin = time.monotonic()
                before = _cpu(table, _tree(table, room.process.pid))  # type: ignore[union-attr]
                states = warm_room(HubAPI(room.url, room.token), names, stagger=stagger, at_once=at_once,
                                   timeout=900.0, report=lambda line: None)
                table = _table()
                warm_figures = {
                    "warm_s": round(time.monotonic() - begin, 1),
                    "warm_ready": sum(s.state == "ready" for s in states.values()),
                    "warm_cpu_s_per_server": round((_cpu(table, _tree(table, room.process.pid))  # type: ignore
                                                    - before) / n, 2)}

            def observer(name: str):
                def observe(moment: str) -> None:
                    table = _table()
                    server = _server_of(table, room, name)
                    cpu = _cpu(table, _tree(table, server)) if server is not None else 0.0
                    with lock:
                        cpu_at[(name, moment)] = cpu
                return observe

            shared_before = _cpu(table := _table(), _shared(room, table))
            with ThreadPoolExecutor(max_workers=n) as pool:
                futures = []
                for i, name in enumerate(names):
                    if i and arrival:
                        time.sleep(arrival)
                    futures.append(pool.submit(room.learner_session, name, prepare=_solve if i % 2 == 0 else None,
                                               observe=observer(name)))
                runs = [f.result() for f in futures]
            table = _table()
            shared = _shared(room, table)
            shared_cpu = (_cpu(table, shared) - shared_before) / n
            shared_rss, shared_pss = _memory(shared)
            trees = {name: _tree(table, server) for name in names if (server := _server_of(table, room, name))}
            memory = {name: _memory(pids) for name, pids in trees.items()}
        finally:
            left = room.stop()
    finally:
        shutil.rmtree(base, ignore_errors=True)
    cpu = [cpu_at.get((name, "result"), 0.0) - cpu_at.get((name, "login"), 0.0) + shared_cpu for name in names]
    rss = [memory[name][0] + shared_rss / n for name in memory]
    pss = [memory[name][1] + shared_pss / n for name in memory]
    firsts = [run.first_result_s for run in runs]
    right = all(run.score == ((run.score[1], run.score[1]) if i % 2 == 0 else (0.0, run.score[1])) and run.score[1] > 0
                and not run.errors for i, run in enumerate(runs))

    def both(values: list[float], digits: int = 1) -> str:
        return f"{statistics.median(values):.{digits}f} / {max(values):.{digits}f}"

    return {"learners": n, "arrival_s": arrival, "warm": warm, "unix_users": unix_users, **warm_figures,
            "first_result_s (median / max)": both(firsts),
            "cpu_s_per_learner (median / max)": both(cpu, 2),
            "cpu_s_per_learner, above 4": sorted(round(c, 2) for c in cpu if c > 4.0),
            "of which hub, proxy, live view": round(shared_cpu, 2),
            "rss_mib_per_learner (median / max)": both(rss, 0),
            "pss_mib_per_learner (median / max)": both(pss, 0),
            "hub_start_cpu_s": round(shared_start, 1),
            "grades_right": right, "processes_left": len(left)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--learners", type=int, nargs="+", default=[10, 30], help="room sizes")
    parser.add_argument("--arrival", type=float, default=0.0, help="seconds between two learners' logins")
    parser.add_argument("--warm", action="store_true", help="start every learner's server before they arrive")
    parser.add_argument("--stagger", type=float, default=1.0, help="with --warm: seconds between two starts")
    parser.add_argument("--at-once", type=int, default=3, help="with --warm: most servers starting at once")
    parser.add_argument("--shared-user", action="store_true",
                        help="every server as this user (default as root: a Unix account per learner)")
    args = parser.parse_args()
    if not args.arrival >= 0.0:
        parser.error("--arrival must be 0 or more seconds")
    if not SOLUTION.is_dir():
        parser.error("needs solutions/ (half of the learners hand in the solved task 2)")
    unix_users = os.geteuid() == 0 and not args.shared_user
    for n in args.learners:
        if n < 1:
            parser.error("a room has at least one learner")
        print(room_of(n, args.arrival, args.warm, unix_users, args.stagger, args.at_once), flush=True)


if __name__ == "__main__":
    main()
