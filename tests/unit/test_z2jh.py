"""``deploy/z2jh/config.yaml`` checked as Helm checks it, against the zero-to-jupyterhub chart 4.4.0's own files.

Helm merges the chart's ``values.yaml`` with the given values (maps key by key, anything else replaced, ``null``
removing a key), then validates the result with the chart's ``values.schema.yaml`` (JSON schema draft 7). Both files
come from ``../shared/upstream`` (see tests/unit/upstream.py). What the hub makes of ``hub.config`` and
``hub.extraConfig`` is checked with the installed JupyterHub: who is admin, with which password.
"""

from __future__ import annotations

import asyncio
import copy
import tomllib
from pathlib import Path
from typing import Any

import jsonschema
import pytest
import yaml
from upstream import Z2JH, upstream

ROOT = Path(__file__).resolve().parents[2]
CONFIG = ROOT / "deploy" / "z2jh" / "config.yaml"
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


def helm_merge(defaults: Any, values: Any) -> Any:
    """The chart's defaults with ``values`` over them, as Helm coalesces them: maps merged key by key, any other
    value replaced, a ``null`` value removing the default's key."""
    if not (isinstance(defaults, dict) and isinstance(values, dict)):
        return copy.deepcopy(values)
    merged = copy.deepcopy(defaults)
    for key, value in values.items():
        if value is None:
            merged.pop(key, None)
        elif key in merged:
            merged[key] = helm_merge(merged[key], value)
        else:
            merged[key] = copy.deepcopy(value)
    return merged


def _errors(values: dict[str, Any]) -> list[str]:
    """The schema's complaints about the chart's defaults merged with ``values``."""
    chart = upstream(Z2JH)
    defaults = yaml.safe_load((chart / "values.yaml").read_text())
    schema = yaml.safe_load((chart / "values.schema.yaml").read_text())
    validator = jsonschema.validators.validator_for(schema)(schema)
    return sorted(f"{'.'.join(map(str, e.absolute_path)) or '(top)'}: {e.message}"
                  for e in validator.iter_errors(helm_merge(defaults, values)))


@pytest.fixture(scope="module")
def values() -> dict[str, Any]:
    return yaml.safe_load(CONFIG.read_text())


def test_the_config_passes_the_charts_schema_with_the_charts_defaults(values) -> None:
    assert _errors(values) == []


@pytest.mark.parametrize(("change", "says"), [
    ({"singleuser": {"cpu": {"guarantee": "half"}}}, "singleuser.cpu.guarantee"),
    ({"cull": {"bogus": 1}}, "cull: Additional properties are not allowed ('bogus' was unexpected)"),
    ({"singleuser": {"storage": {"type": "ephemeral"}}}, "singleuser.storage.type"),
])
def test_the_schema_check_finds_wrong_keys_and_types(values, change: dict[str, Any], says: str) -> None:
    errors = _errors(helm_merge(values, change))
    assert any(says in e for e in errors), errors


def test_the_merge_is_helms() -> None:
    defaults = {"a": {"b": 1, "c": [1, 2]}, "d": 1}
    assert helm_merge(defaults, {"a": {"c": [3]}, "d": None, "e": {}}) == {"a": {"b": 1, "c": [3]}, "e": {}}
    assert defaults == {"a": {"b": 1, "c": [1, 2]}, "d": 1}


def _hub_config(values: dict[str, Any], env: dict[str, str], monkeypatch: pytest.MonkeyPatch) -> Any:
    """JupyterHub's config from ``hub.config`` (z2jh passes it to traitlets as is) and ``hub.extraConfig``."""
    from traitlets.config import Config

    c = Config(copy.deepcopy(values["hub"]["config"]))
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    for snippet in values["hub"]["extraConfig"].values():
        exec(compile(snippet, "hub.extraConfig", "exec"), {"c": c})  # noqa: S102 - the hub runs it the same way
    return c


def test_hub_config_names_real_jupyterhub_classes_and_traits(values, monkeypatch) -> None:
    from jupyterhub.app import JupyterHub
    from jupyterhub.auth import Authenticator
    from jupyterhub.authenticators.shared import SharedPasswordAuthenticator

    classes = {"JupyterHub": JupyterHub, "Authenticator": Authenticator,
               "SharedPasswordAuthenticator": SharedPasswordAuthenticator}
    for name, section in values["hub"]["config"].items():
        assert name in classes, f"hub.config.{name}: not a class this test knows ({sorted(classes)})"
        traits = classes[name].class_traits(config=True)
        assert set(section) <= set(traits), f"hub.config.{name}: {sorted(set(section) - set(traits))}"
    app = JupyterHub(config=_hub_config(values, {"RRBOT_WORKSHOP_ROOM_PASSWORD": "room-pass-1",
                                                 "RRBOT_WORKSHOP_INSTRUCTOR_PASSWORD": "i" * 32}, monkeypatch))
    assert app.authenticator_class is SharedPasswordAuthenticator


def test_only_the_instructors_password_opens_the_instructors_account(values, monkeypatch) -> None:
    from jupyterhub.authenticators.shared import SharedPasswordAuthenticator

    room, instructor = "room-password-42", "an-instructor-password-of-32-chars!"
    auth = SharedPasswordAuthenticator(config=_hub_config(
        values, {"RRBOT_WORKSHOP_ROOM_PASSWORD": room, "RRBOT_WORKSHOP_INSTRUCTOR_PASSWORD": instructor},
        monkeypatch))

    def login(name: str, password: str) -> Any:
        return asyncio.run(auth.authenticate(None, {"username": name, "password": password}))

    assert login("instructor", room) is None  # the room's password does not open the admin account
    assert login("instructor", instructor) == {"name": "instructor", "admin": True, "groups": []}
    assert login("ana", room) == {"name": "ana", "admin": False, "groups": []}
    assert login("ana", instructor) is None
    assert auth.allow_all is True


def test_no_password_is_in_the_config(values) -> None:
    text = CONFIG.read_text()
    assert "password:" not in text.replace("_password:", "")
    assert "DummyAuthenticator" not in text
    env = values["hub"]["extraEnv"]
    for name in ("RRBOT_WORKSHOP_ROOM_PASSWORD", "RRBOT_WORKSHOP_INSTRUCTOR_PASSWORD"):
        assert env[name]["valueFrom"]["secretKeyRef"]["name"] == "rrbot-workshop-passwords"


def test_the_live_view_runs_beside_the_hub_and_learners_reach_it(values) -> None:
    hub, single = values["hub"], values["singleuser"]
    (service,) = hub["services"]
    url = hub["services"][service]["url"]
    port = int(url.rsplit(":", 1)[1])
    (container,) = hub["extraContainers"]
    command = container["command"]
    assert command[:2] == ["rrbot-workshop", "class-service"] and command[command.index("--port") + 1] == str(port)
    assert container["image"] == f"{single['image']['name']}:{single['image']['tag']}"
    env = {e["name"]: e for e in container["env"]}
    # the chart keeps a generated token for each service in its secret, under this key
    assert env["JUPYTERHUB_API_TOKEN"]["valueFrom"]["secretKeyRef"]["key"] == f"hub.services.{service}.apiToken"
    assert env["JUPYTERHUB_SERVICE_NAME"]["value"] == service
    assert {"port": port, "targetPort": port, "name": service} in hub["service"]["extraPorts"]
    assert any({"port": port} in rule["ports"] for rule in hub["networkPolicy"]["ingress"])
    assert any({"port": port} in rule["ports"] for rule in single["networkPolicy"]["egress"])
    assert single["extraEnv"]["RRBOT_WORKSHOP_CLASS_SERVICE"] == f"{url}/services/{service}/"
    assert hub["loadRoles"][service]["services"] == [service]


def test_learners_servers_run_the_course(values) -> None:
    assert values["singleuser"]["cmd"] == ["rrbot-workshop", "singleuser"]
    assert PYPROJECT["project"]["scripts"]["rrbot-workshop"] == "rrbot_workshop.cli:main"
    assert values["singleuser"]["defaultUrl"].endswith("my_notebooks/00_intro.ipynb")
    assert values["cull"]["enabled"] is True and values["cull"]["timeout"] >= 3 * 3600
