"""A self-check's result, sent to the instructor's live view (:mod:`rrbot_workshop.course.grading.live_view`).

A small HTTP server on 127.0.0.1 takes the place of the live view here (the room test runs the real one on a hub): it
records each request, and can hold its answer until the test lets it go, to show that sending never holds up the
learner's check.
"""

from __future__ import annotations

import json
import logging
import threading
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import pytest

from rrbot_workshop.course.grading import live_view

ATTEMPT = {"time": 1.0, "score": 3.0, "max_score": 10.0, "failed": ["reaches_goal"], "version": "abc",
           "reasons": {"reaches_goal": "joint1 stopped at 0.2 rad"}}


class _Receiver(ThreadingHTTPServer):
    def __init__(self) -> None:
        self.requests: list[dict[str, Any]] = []
        self.release = threading.Event()
        self.status = 201
        super().__init__(("127.0.0.1", 0), _Handler)

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.server_address[1]}/services/rrbot-class/"


class _Handler(BaseHTTPRequestHandler):
    server: _Receiver

    def do_POST(self) -> None:  # noqa: N802 - http.server's name
        body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
        self.server.requests.append({"path": self.path, "auth": self.headers["Authorization"], "body": body})
        self.server.release.wait(30)
        self.send_response(self.server.status)
        self.end_headers()

    def log_message(self, *args: Any) -> None:
        pass


@pytest.fixture
def receiver(monkeypatch: pytest.MonkeyPatch) -> Iterator[_Receiver]:
    server = _Receiver()
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    monkeypatch.setenv(live_view.SERVICE_ENV, server.url)
    monkeypatch.setenv(live_view.TOKEN_ENV, "learner-token")
    yield server
    server.release.set()
    server.shutdown()
    server.server_close()


def test_nothing_is_sent_without_a_live_view(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(live_view.SERVICE_ENV, raising=False)
    monkeypatch.setenv(live_view.TOKEN_ENV, "learner-token")
    assert live_view.post_attempt(2, ATTEMPT) is None
    monkeypatch.setenv(live_view.SERVICE_ENV, "http://127.0.0.1:9/services/rrbot-class/")
    monkeypatch.delenv(live_view.TOKEN_ENV)
    assert live_view.post_attempt(2, ATTEMPT) is None


def test_the_attempt_goes_with_the_learners_own_token(receiver: _Receiver) -> None:
    receiver.release.set()
    thread = live_view.post_attempt(2, ATTEMPT)
    assert thread is not None
    thread.join(30)
    (request,) = receiver.requests
    assert request["path"] == "/services/rrbot-class/api/results"
    assert request["auth"] == "token learner-token"
    assert request["body"] == {"task": 2, **ATTEMPT}


def test_sending_never_holds_up_the_check(receiver: _Receiver) -> None:
    """The live view holds its answer until after post_attempt has returned: the check went on without it."""
    thread = live_view.post_attempt(2, ATTEMPT)
    assert thread is not None and thread.is_alive()
    receiver.release.set()
    thread.join(30)
    assert not thread.is_alive() and len(receiver.requests) == 1


def test_a_process_that_ends_waits_for_the_live_view_only_so_long(receiver: _Receiver) -> None:
    thread = live_view.post_attempt(2, ATTEMPT)
    assert thread is not None
    live_view.wait_for_posts(timeout=0.05)
    assert thread.is_alive()  # given up waiting; the live view still has not answered
    receiver.release.set()
    thread.join(30)


@pytest.mark.parametrize("status", [403, 500])
def test_a_refusal_is_logged_not_raised(receiver: _Receiver, caplog: pytest.LogCaptureFixture, status: int) -> None:
    receiver.status = status
    receiver.release.set()
    with caplog.at_level(logging.INFO, logger=live_view.__name__):
        thread = live_view.post_attempt(2, ATTEMPT)
        assert thread is not None
        thread.join(30)
    assert f"HTTP {status}" in caplog.text


def test_an_unreachable_live_view_is_logged_not_raised(monkeypatch: pytest.MonkeyPatch,
                                                         caplog: pytest.LogCaptureFixture) -> None:
    from rrbot_workshop.classroom.room import free_port

    monkeypatch.setenv(live_view.SERVICE_ENV, f"http://127.0.0.1:{free_port()}/services/rrbot-class/")
    monkeypatch.setenv(live_view.TOKEN_ENV, "learner-token")
    with caplog.at_level(logging.INFO, logger=live_view.__name__):
        thread = live_view.post_attempt(2, ATTEMPT)
        assert thread is not None
        thread.join(30)
    assert "could not send the result" in caplog.text
