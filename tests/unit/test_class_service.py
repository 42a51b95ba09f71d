"""The live view's parts that need no hub: what a result may hold, where results are kept, what the page shows, and
how the hub's user models read. The service on a real hub, with learners posting, is in test_room.py."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rrbot_workshop.classroom.hub import ServerState, server_state
from rrbot_workshop.classroom.service import Results, RoomView, validate_attempt
from rrbot_workshop.cli import main

GOOD = {"task": 2, "score": 3, "max_score": 10, "failed": ["b", "a"], "reasons": {"a": "why"}, "version": "v1"}


def test_a_result_is_checked_and_trimmed() -> None:
    assert validate_attempt({**GOOD, "user": "someone else", "time": 0}) == {
        "task": 2, "score": 3.0, "max_score": 10.0, "failed": ["a", "b"], "reasons": {"a": "why", "b": ""},
        "version": "v1"}
    assert len(validate_attempt({**GOOD, "reasons": {"a": "x" * 5000}})["reasons"]["a"]) == 300


@pytest.mark.parametrize(("change", "says"), [
    ({"task": "2"}, "'task'"), ({"task": 100}, "'task'"), ({"task": True}, "'task'"),
    ({"score": "all"}, "'score'"), ({"max_score": -1}, "'max_score'"), ({"score": 11}, "'score'"),
    ({"failed": "a"}, "'failed'"), ({"failed": [1]}, "'failed'"), ({"reasons": ["a"]}, "'reasons'"),
])
def test_a_malformed_result_is_refused_naming_the_field(change: dict, says: str) -> None:
    with pytest.raises(ValueError, match=says):
        validate_attempt({**GOOD, **change})
    with pytest.raises(ValueError, match="JSON object"):
        validate_attempt([GOOD])


def test_results_are_kept_and_read_back_with_the_time_they_arrived(tmp_path: Path) -> None:
    path = tmp_path / "results.jsonl"
    results = Results(path, clock=lambda: 100.0)
    results.add("ana", validate_attempt(GOOD))
    path.write_text(path.read_text() + "not json\n")  # a damaged line is skipped, not fatal
    again = Results(path)
    assert again.attempts() == {"ana": {2: [{**validate_attempt(GOOD), "time": 100.0}]}}


def test_the_page_shows_every_learner_and_task_and_when_it_was_made() -> None:
    clock = iter([1000.0, 1000.0, 1000.0, 1700.0])
    results = Results(clock=lambda: next(clock))
    results.add("ana", validate_attempt({**GOOD, "score": 10, "failed": [], "reasons": {}}))
    results.add("ben", validate_attempt(GOOD))
    results.add("dora", validate_attempt({**GOOD, "version": "as handed out"}))  # checked before changing anything
    results.add("ben", validate_attempt({**GOOD, "failed": ["a"], "version": "v2"}))  # a still fails, 700 s on
    users = [{"name": "ana", "last_activity": "2026-11-28T10:00:00Z", "servers": {"": {"ready": True}}},
             {"name": "ben", "servers": {}}, {"name": "cleo", "servers": {}}, {"name": "dora", "servers": {}},
             {"name": "teacher", "admin": True, "servers": {}}, {"name": "tess", "servers": {}}]
    view = RoomView.build(results, users, tasks=[1, 2], now=1750.0, hidden={"tess"},
                          untouched={2: {"as handed out"}}, stuck_after=600.0)
    rows = {r["name"]: r for r in view.learners}
    assert sorted(rows) == ["ana", "ben", "cleo", "dora"]  # the admin and the hidden assistant are no learners
    status = {name: row["tasks"][2]["status"] for name, row in rows.items()}
    assert status == {"ana": "passed", "ben": "stuck", "cleo": "not started", "dora": "not started"}
    assert rows["ben"]["tasks"][2]["stuck_on"] == ["a"] and rows["ana"]["server"] == "ready"
    assert view.reasons == {2: [("a", "why", 1)]}  # among those who tried: dora did not
    page = view.html(refresh_s=15)
    assert '<meta http-equiv="refresh" content="15">' in page and "made at " in page and "<b>1</b>" in page
    assert json.loads(json.dumps(view.to_dict()))["learners"][0]["name"] == "ana"


@pytest.mark.parametrize(("user", "state"), [
    ({"servers": {}}, ServerState("stopped")),
    ({"pending": "spawn", "servers": {}}, ServerState("starting")),
    ({"servers": {"": {"ready": False, "pending": "spawn"}}}, ServerState("starting")),
    ({"servers": {"": {"ready": False, "pending": "stop"}}}, ServerState("stopping")),
    ({"last_activity": "t1", "servers": {"": {"ready": True, "last_activity": "t2", "started": "t0"}}},
     ServerState("ready", "t2", "t0")),
])
def test_a_learners_server_state_from_the_hubs_user_model(user: dict, state: ServerState) -> None:
    assert server_state(user) == state


@pytest.mark.parametrize(("argv", "says"), [
    (["room", "warm", "--hub", "http://127.0.0.1:9", "--learners", "a"], "JUPYTERHUB_API_TOKEN"),
    (["room", "warm", "--hub", "http://127.0.0.1:9", "--count", "0"], "1 to 1000"),
    (["room", "warm", "--hub", "http://127.0.0.1:9", "--learners-file", "/no/such/file"], "cannot read"),
])
def test_room_warm_refuses_in_one_line(argv: list[str], says: str, monkeypatch: pytest.MonkeyPatch,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    if "JUPYTERHUB_API_TOKEN" in says:
        monkeypatch.delenv("JUPYTERHUB_API_TOKEN", raising=False)
    else:
        monkeypatch.setenv("JUPYTERHUB_API_TOKEN", "token")
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert says in err and len(err.splitlines()) == 1


def test_room_warm_says_when_the_hub_cannot_be_reached(monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    from rrbot_workshop.classroom.room import free_port

    monkeypatch.setenv("JUPYTERHUB_API_TOKEN", "token")
    assert main(["room", "warm", "--hub", f"http://127.0.0.1:{free_port()}", "--count", "2"]) == 2
    assert "cannot reach the hub" in capsys.readouterr().err


def test_the_class_service_needs_the_hubs_environment(monkeypatch: pytest.MonkeyPatch,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.delenv("JUPYTERHUB_API_URL", raising=False)
    monkeypatch.delenv("JUPYTERHUB_API_TOKEN", raising=False)
    assert main(["class-service"]) == 2
    assert "JUPYTERHUB_API_URL" in capsys.readouterr().err
