"""A learner's self-check, reported to the instructor's live view on a JupyterHub.

On a hub set up by the course (``deploy/``), every learner's server has ``RRBOT_WORKSHOP_CLASS_SERVICE`` (where the
live view, ``rrbot-workshop class-service``, takes results) and ``JUPYTERHUB_API_TOKEN`` (the learner's own hub
token) in its environment, and so do their kernels and terminals. After each recorded attempt, :func:`post_attempt`
sends the attempt (the same record as the attempt log's) with that token; the service asks the hub whose token it is,
so nobody can report for someone else. Each learner's home may be a volume of its own (zero-to-jupyterhub): results
travel, files do not have to.

Reporting never slows or breaks a self-check: the request runs in a background thread with a short timeout; a
process that ends (``rrbot-workshop grade`` in a terminal) waits for it at most that long; any failure is logged at
INFO level (``rrbot_workshop.course.grading.live_view``) and otherwise ignored. Without the two variables (a laptop),
nothing is sent.
"""

from __future__ import annotations

import atexit
import json
import logging
import os
import threading
import urllib.error
import urllib.request
from typing import Any

__all__ = ["SERVICE_ENV", "TOKEN_ENV", "TIMEOUT", "post_attempt", "wait_for_posts"]

logger = logging.getLogger(__name__)

#: Where the live view takes results (its URL, ending in ``/services/<name>/``).
SERVICE_ENV = "RRBOT_WORKSHOP_CLASS_SERVICE"
#: The learner's own hub token, set by JupyterHub in their server's environment.
TOKEN_ENV = "JUPYTERHUB_API_TOKEN"
#: Longest wait for the live view, per request and at the end of a process [s].
TIMEOUT = 2.0

_pending: list[threading.Thread] = []
_lock = threading.Lock()


def post_attempt(task: int, attempt: dict[str, Any]) -> threading.Thread | None:
    """Send one attempt of ``task`` to the live view, in the background.

    Args:
        task: Task number.
        attempt: The attempt as the log records it (``score``, ``max_score``, ``failed``, ``reasons``, ``version``,
            ``time``).

    Returns:
        The thread sending it, or None when this server reports to no live view.
    """
    url, token = os.environ.get(SERVICE_ENV, ""), os.environ.get(TOKEN_ENV, "")
    if not url or not token:
        return None
    body = json.dumps({"task": task, **attempt}).encode()
    thread = threading.Thread(target=_send, args=(url.rstrip("/") + "/api/results", token, body),
                              name=f"rrbot-workshop-live-view-task{task:02d}", daemon=True)
    with _lock:
        _pending[:] = [t for t in _pending if t.is_alive()]
        _pending.append(thread)
    thread.start()
    return thread


def _send(url: str, token: str, body: bytes) -> None:
    request = urllib.request.Request(url, data=body, method="POST", headers={
        "Authorization": f"token {token}", "Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(request, timeout=TIMEOUT) as response:
            logger.info("live view: result sent to %s (HTTP %s)", url, response.status)
    except urllib.error.HTTPError as exc:
        logger.info("live view: %s refused the result: HTTP %s", url, exc.code)
    except (OSError, ValueError) as exc:  # unreachable, timed out, a bad URL: the self-check goes on
        logger.info("live view: could not send the result to %s: %s", url, exc)


def wait_for_posts(timeout: float = TIMEOUT) -> None:
    """Wait, at most ``timeout`` seconds in all, for results still being sent (a process about to end)."""
    import time

    deadline = time.monotonic() + timeout
    with _lock:
        threads = list(_pending)
    for thread in threads:
        thread.join(max(0.0, deadline - time.monotonic()))


atexit.register(wait_for_posts)
