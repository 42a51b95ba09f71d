"""The class report's files: the page (the room's tasks at a glance, each learner × task, where the room is stuck,
progress), the spreadsheet and the JSON.

:func:`write_report` writes all three; :func:`render_html` turns a :class:`~rrbot_workshop.classroom.class_report.RoomReport` into one self-contained HTML
file (the plot is an inline SVG). Every text that comes from a learner (names, check names, reasons) is HTML-escaped;
the page runs no script.
"""

from __future__ import annotations

import csv
import html
import json
import math
import os
from pathlib import Path

from rrbot_workshop.classroom.class_report import RoomReport
from rrbot_workshop.classroom.task_status import NOT_STARTED, PASSED, STATUSES, STUCK, WORKING, TaskState, local_time
from rrbot_workshop.exceptions import CourseError

__all__ = ["render_html", "progress_svg", "duration", "write_report", "csv_cell"]

_CSS = """body{font-family:sans-serif;margin:1.5em;color:#222} table{border-collapse:collapse;margin-bottom:1.5em}
td,th{border:1px solid #ccc;padding:.3em .6em;text-align:center;vertical-align:top} th.who{text-align:left}
.passed{background:#d9f2d9} .working{background:#e3ecfa} .stuck{background:#f9d0cc;font-weight:bold}
.not-started{color:#777;background:#f6f6f6} small{font-weight:normal} .meta{color:#555}
td.reason{text-align:left;max-width:40em} td.when{white-space:nowrap}"""
_CLASS = {NOT_STARTED: "not-started", WORKING: "working", STUCK: "stuck", PASSED: "passed"}


def duration(seconds: float) -> str:
    """A duration for a reader: ``45 s``, ``12 min``, ``2 h 05 min``."""
    seconds = max(0.0, seconds)
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 90 * 60:
        return f"{seconds / 60:.0f} min"
    hours, minutes = divmod(round(seconds / 60), 60)
    return f"{hours} h {minutes:02d} min"


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def _cell(state: TaskState, now: float) -> str:
    esc = html.escape
    checks = _plural(state.attempts, "check")
    if state.status == PASSED:
        when = "first try" if state.first_try or state.time_to_pass_s is None else \
            f"in {duration(state.time_to_pass_s)}"
        detail = f"{when} · {checks}"
    elif state.status == STUCK:
        since = state.failing_since[state.stuck_on[0]]
        detail = (f"{duration(now - since)} on {esc(state.stuck_on[0])}<br>{state.points:g}/{state.max_points:g} "
                  f"points · {checks}")
    elif state.status == WORKING:
        detail = f"{state.points:g}/{state.max_points:g} points · {checks}"
    else:
        detail = f"checked as handed out ×{state.attempts}" if state.attempts else ""
    return f'<td class="{_CLASS[state.status]}">{state.status}<br><small>{detail}</small></td>'


def _ago(when: float | None, now: float) -> str:
    if when is None:
        return "no self-check yet"
    return f"{html.escape(local_time(when)[11:16])} ({duration(now - when)} ago)"


def _ticks(top: float, count: int = 6) -> list[float]:
    """Round tick values from 0 to at least ``top`` (1, 2 or 5 times a power of ten apart)."""
    raw = max(top, 1e-9) / count
    power = 10 ** math.floor(math.log10(raw))
    step = next(m * power for m in (1, 2, 5, 10) if m * power >= raw)
    return [step * i for i in range(int(math.ceil(top / step - 1e-9)) + 1)] or [0.0]


def progress_svg(report: RoomReport, width: int = 640, height: int = 240) -> str:
    """Tasks passed in the room over the workshop's time (minutes since the room's first self-check), as an inline
    SVG step chart: one step up at each learner's first full score of a task, flat until the report's time."""
    states = [s for lr in report.learners for s in lr.tasks.values()]
    starts = [s.first_check for s in states if s.first_check is not None]
    start = min(starts, default=report.made_at)
    passes = sorted((s.passed_at - start) / 60.0 for s in states if s.passed_at is not None)
    end = max([*passes, (report.made_at - start) / 60.0, 1.0])
    xs, ys = _ticks(end), _ticks(max(len(passes), 1))
    left, right, top, bottom = 48, 12, 10, 36
    plot_w, plot_h = width - left - right, height - top - bottom

    def at(x: float, y: float) -> str:
        return f"{left + plot_w * x / xs[-1]:.1f},{top + plot_h * (1 - y / ys[-1]):.1f}"

    points = [at(0, 0)]
    for count, minute in enumerate(passes, start=1):
        points += [at(minute, count - 1), at(minute, count)]
    points.append(at(end, len(passes)))
    grid = "".join(f'<line x1="{left}" x2="{left + plot_w}" y1="{at(0, y).split(",")[1]}" '
                   f'y2="{at(0, y).split(",")[1]}" class="grid"/><text x="{left - 6}" y="{at(0, y).split(",")[1]}" '
                   f'text-anchor="end" dy="4">{y:g}</text>' for y in ys)
    grid += "".join(f'<text x="{at(x, 0).split(",")[0]}" y="{top + plot_h + 16}" text-anchor="middle">{x:g}</text>'
                    for x in xs)
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" role="img" '
            f'aria-label="tasks passed over time"><style>text{{font:11px sans-serif;fill:#444}} '
            f'.grid{{stroke:#ddd}} .line{{fill:none;stroke:#1f77b4;stroke-width:2}}</style>{grid}'
            f'<polyline class="line" points="{" ".join(points)}"/>'
            f'<text x="{left + plot_w / 2}" y="{height - 4}" text-anchor="middle">minutes since the room\'s first '
            f'self-check</text><text transform="translate(12,{top + plot_h / 2}) rotate(-90)" text-anchor="middle">'
            f'tasks passed (all learners)</text></svg>')


def render_html(report: RoomReport) -> str:
    """The report as one HTML page (see the module's documentation)."""
    esc = html.escape
    now = report.made_at
    tasks = report.tasks()
    counts = report.counts()
    summary = "".join(f"<tr><th>task {t}</th>" + "".join(f'<td class="{_CLASS[s]}">{counts[t][s]}</td>'
                                                         for s in STATUSES) + "</tr>" for t in tasks)
    head = "".join(f"<th>task {t}</th>" for t in tasks)
    rows = "".join(f'<tr><th class="who">{esc(lr.name)}</th><td class="when">{_ago(lr.last_activity, now)}</td>'
                   + "".join(_cell(lr.state(t), now) for t in tasks) + "</tr>" for lr in report.learners)
    nobody = '<tr><td colspan="5">no learner who started a task fails a check</td></tr>'
    stuck = "".join(f"<tr><td>{r['task']}</td><td>{esc(r['check'])}</td><td>{r['learners_stuck']}</td>"
                    f"<td>{r['learners_failing']}</td><td class=\"reason\">{esc(r['most_common_reason'])}</td></tr>"
                    for r in report.stuck()) or nobody
    notes = "".join(f"<li>{esc(n)}</li>" for n in report.notes) or "<li>none</li>"
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>rrbot_workshop: the room</title>
<style>{_CSS}</style></head><body>
<h1>The room: {_plural(len(report.learners), "learner")}</h1>
<p class="meta">Made {esc(local_time(now))}. A learner is <b>stuck</b> on a task when the same check has failed in
every self-check of their own work for {duration(report.stuck_after)} or more (<code>--stuck-after</code>);
<b>not started</b> means no self-check of files they changed. Make the report again to refresh it.</p>
<h2>Tasks</h2>
<table><tr><th>task</th>{"".join(f'<th class="{_CLASS[s]}">{s}</th>' for s in STATUSES)}</tr>{summary}</table>
<h2>Learners × tasks</h2>
<table><tr><th class="who">learner</th><th>last self-check</th>{head}</tr>{rows}</table>
<h2>Where the room is stuck (checks failing now, among learners who started the task)</h2>
<table><tr><th>task</th><th>check</th><th>stuck</th><th>failing</th><th>most common reason</th></tr>{stuck}</table>
<h2>Progress over the workshop</h2>{progress_svg(report)}
<h2>Notes</h2><ul>{notes}</ul></body></html>
"""


#: First characters that make a spreadsheet read a cell as a formula (OWASP's CSV injection list, with NUL and the
#: full-width forms some spreadsheets also take).
_FORMULA_START = ("=", "+", "-", "@", "\t", "\r", "\n", "\0", "\uff1d", "\uff0b", "\uff0d", "\uff20")


def csv_cell(value: object) -> str:
    """A CSV cell a spreadsheet shows as text: a text starting with ``=``, ``+``, ``-``, ``@``, a tab, a carriage
    return (OWASP's list, with a line feed, NUL and their full-width forms) gets a leading ``'``; None is empty."""
    text = "" if value is None else str(value)
    return f"'{text}" if text.startswith(_FORMULA_START) else text


_CSV_COLUMNS = ["learner", "task", "status", "points", "max_points", "attempts", "time_to_pass_s", "first_try",
                "stuck_on", "failing_checks", "failing_since", "last_check", "learner_last_activity"]


def _csv_rows(report: RoomReport) -> list[list[object]]:
    rows: list[list[object]] = []
    for learner in report.learners:
        for task in report.tasks():
            s = learner.state(task)
            since = min(s.failing_since.values(), default=None)
            rows.append([learner.name, task, s.status, s.points, s.max_points, s.attempts, s.time_to_pass_s,
                         s.first_try, " ".join(s.stuck_on), " ".join(sorted(s.failing)), local_time(since),
                         local_time(s.last_check), local_time(learner.last_activity)])
    return rows


def write_report(report: RoomReport, out: Path) -> list[Path]:
    """Write ``report.json``, ``report.csv`` (one row per learner and task, every cell quoted and formula-safe, see
    :func:`csv_cell`) and ``report.html`` into ``out``.

    Raises:
        CourseError: If ``out`` is a file or cannot be written.
    """
    if os.path.lexists(out) and not out.is_dir():
        raise CourseError("--out", str(out), "is a file; give a folder for report.json, report.csv and report.html")
    paths = [out / "report.json", out / "report.csv", out / "report.html"]
    try:
        out.mkdir(parents=True, exist_ok=True)
        paths[0].write_text(json.dumps(report.to_dict(), indent=1) + "\n", encoding="utf-8")
        with paths[1].open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle, quoting=csv.QUOTE_ALL)
            writer.writerow(_CSV_COLUMNS)
            writer.writerows([csv_cell(v) for v in row] for row in _csv_rows(report))
        paths[2].write_text(render_html(report), encoding="utf-8")
    except OSError as exc:
        raise CourseError("--out", str(out), f"cannot be written ({exc.strerror or exc})") from None
    return paths
