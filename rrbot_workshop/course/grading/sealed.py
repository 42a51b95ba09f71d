"""Predictions sealed before their outcomes are shown: a prediction changed after the reveal earns nothing.

Tasks 6 and 14 ask the learner to predict what ros2_control does, then notebook 06's prediction cell and notebook 14's
reveal cells show what really happens. Whatever is shown can be copied into the prediction file, so the moment an
outcome is about to be shown, the prediction of it is *sealed*: a copy of it, in a canonical JSON form, goes into the
task's attempt log (``exercises/.progress/taskNN.json``, under ``"sealed"``). The first seal of a prediction stays;
later reveals do not replace it.

A grader compares each prediction (or each part of one) with its seal: the same prediction is graded as usual; a
changed one earns nothing, and the reason says so and how to get the sealed one graded again (put it back). The seal
is looked up beside the graded task folder, so an instructor grading a learner's uploaded folder with its
``.progress/`` sees the learner's seals too. Only the exercises track is ever sealed, and nothing is written where the
attempt log is switched off (the course's own tests).
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

from rrbot_workshop.course import tracks
from rrbot_workshop.course.grading import attempts

__all__ = ["Seal", "canonical", "seal", "seals", "changed_since_sealed"]


@dataclass(frozen=True)
class Seal:
    """One sealed prediction.

    Attributes:
        name: What was predicted (``"nan_command"``).
        prediction: The prediction as it was, in :func:`canonical` form.
        time: When its outcome was first shown (seconds since the epoch).
    """

    name: str
    prediction: str
    time: float

    @property
    def when(self) -> str:
        """The time of the seal as the learner reads it (local time, to the minute)."""
        return datetime.fromtimestamp(self.time).strftime("%Y-%m-%d %H:%M")

    def part(self, keys: Iterable[str]) -> str:
        """The canonical form of the sealed prediction's ``keys`` only (see :func:`canonical`)."""
        try:
            whole = json.loads(self.prediction)
        except ValueError:
            return self.prediction
        if not isinstance(whole, dict):
            return self.prediction
        return json.dumps({k: whole.get(k) for k in keys}, sort_keys=True)


def _plain(value: Any) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return repr(value)


def canonical(prediction: Any, keys: Iterable[str] | None = None) -> str:
    """A prediction as canonical JSON text: mappings sorted, tuples as lists, anything else by its ``repr``.

    Args:
        prediction: One prediction (a dict, usually).
        keys: Only these keys of it (a part of the prediction); every key when None.
    """
    plain = _plain(prediction)
    if keys is not None:
        plain = {k: plain.get(k) for k in keys} if isinstance(plain, dict) else plain
    return json.dumps(plain, sort_keys=True)


def _folder(task: int, track: str | None = None) -> Path:
    """The folder of task folders whose ``.progress/`` holds the task's log (the graded one, or the track's)."""
    return tracks.task_dir(task, track).parent


def seals(task: int, folder: str | os.PathLike[str] | None = None) -> dict[str, Seal]:
    """The task's sealed predictions, by name (empty when none was sealed).

    Args:
        task: Task number.
        folder: The folder of task folders whose log to read; default the one beside the graded task folder.
    """
    data = attempts.load(task, folder if folder is not None else _folder(task))
    found = data.get("sealed")
    out: dict[str, Seal] = {}
    if isinstance(found, dict):
        for name, entry in found.items():
            if isinstance(entry, dict) and isinstance(entry.get("prediction"), str):
                out[str(name)] = Seal(str(name), entry["prediction"], float(entry.get("time") or 0.0))
    return out


def seal(task: int, predictions: Mapping[str, Any] | None, names: Iterable[str], now: float | None = None) -> list[str]:
    """Seal the predictions of ``names`` as they are now, before their outcomes are shown; never raises.

    Only the learner's own exercises are sealed (the current track is the exercises track, the attempt log switched
    on); a name already sealed keeps its first seal. A prediction that is missing is sealed as missing (``null``).

    Args:
        task: Task number.
        predictions: The learner's ``PREDICTIONS`` as read from their file now (None: the file did not load).
        names: What is about to be shown.
        now: The time of the seal (seconds since the epoch); default now.

    Returns:
        The names sealed by this call.
    """
    if tracks.current_track() != "exercises" or not attempts.recording_enabled("exercises", None):
        return []  # the predictions read were not the learner's own (the solutions track), or nothing is recorded
    try:
        folder = _folder(task, "exercises")
    except Exception:  # noqa: BLE001 - no exercises folder in this copy: nothing of the learner's to seal
        return []
    data = attempts.load(task, folder)
    found = data.get("sealed")
    kept: dict[str, Any] = found if isinstance(found, dict) else {}
    table = predictions if isinstance(predictions, Mapping) else {}
    added = [name for name in names if name not in kept]
    if not added:
        return []
    stamp = time.time() if now is None else now
    for name in added:
        kept[name] = {"time": stamp, "prediction": canonical(table.get(name))}
    data["sealed"] = kept
    return added if attempts.write(task, data, folder) else []


def changed_since_sealed(task: int, name: str, prediction: Any, keys: Iterable[str] | None = None,
                         notebook: str = "the notebook") -> str:
    """Why ``prediction`` (or its ``keys``) earns nothing, or ``""`` when it may be graded.

    Args:
        task: Task number.
        name: The prediction's name.
        prediction: The prediction as the graded file holds it now.
        keys: Compare only these keys (a part of the prediction graded on its own).
        notebook: Where the outcome was shown, for the reason (``"notebook 14"``).
    """
    found = seals(task).get(name)
    if found is None:
        return ""
    listed = list(keys) if keys is not None else None
    now = canonical(prediction, listed)
    before = found.part(listed) if listed is not None else found.prediction
    if now == before:
        return ""
    if found.prediction == "null":
        return (f"PREDICTIONS['{name}'] was written after {notebook} showed its outcome ({found.when}): a prediction "
                "made after the reveal earns nothing")
    return (f"PREDICTIONS['{name}'] was changed after {notebook} showed its outcome ({found.when}): a prediction "
            f"changed after the reveal earns nothing. The one you made before is kept under \"sealed\" in "
            f".progress/task{task:02d}.json beside your task folder; put it back to have it graded")
