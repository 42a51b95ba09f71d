"""The deployment files follow their tools' conventions and install what the laptop installs.

* ``binder/`` (repo2docker): the same pinned dependencies as ``pyproject.toml``, a supported Python, scripts that run;
* ``.devcontainer/devcontainer.json``: sets the course up with its own command, forwards JupyterLab's port;
* ``deploy/z2jh/config.yaml``: every key is one of the zero-to-jupyterhub chart's, with the chart's type. The table
  below is written down from the chart's configuration reference, version 4.4.0 (its ``values.schema.yaml``), for
  the keys this file uses;
* ``deploy/tljh/``: the plugin's hooks set what its README says.
"""

from __future__ import annotations

import importlib.util
import json
import re
import subprocess
import tomllib
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())

#: zero-to-jupyterhub chart 4.4.0: key path -> the JSON-schema types its reference gives ("enum:" lists values).
Z2JH_4_4_0: dict[str, tuple[str, ...]] = {
    "hub": ("object",),
    "hub.config": ("object",),  # keys: Configurable class names (capitalised), values: objects, passed to traitlets
    "hub.concurrentSpawnLimit": ("integer", "null"),
    "singleuser": ("object",),
    "singleuser.image": ("object",),
    "singleuser.image.name": ("string",),
    "singleuser.image.tag": ("string",),
    "singleuser.image.pullPolicy": ("enum:", "", "IfNotPresent", "Always", "Never"),
    "singleuser.cmd": ("array", "string", "null"),
    "singleuser.defaultUrl": ("string", "null"),
    "singleuser.startTimeout": ("integer", "null"),
    "singleuser.memory": ("object",),
    "singleuser.memory.guarantee": ("number", "string", "null"),
    "singleuser.memory.limit": ("number", "string", "null"),
    "singleuser.cpu": ("object",),
    "singleuser.cpu.guarantee": ("number", "null"),
    "singleuser.cpu.limit": ("number", "null"),
    "singleuser.storage": ("object",),
    "singleuser.storage.type": ("enum:", "dynamic", "static", "none"),
    "singleuser.storage.capacity": ("string", "null"),
    "singleuser.extraEnv": ("object", "array"),
    "singleuser.networkPolicy": ("object",),
    "singleuser.networkPolicy.enabled": ("boolean",),
    "cull": ("object",),
    "cull.enabled": ("boolean",),
    "cull.timeout": ("integer", "null"),
    "cull.every": ("integer", "null"),
    "cull.users": ("boolean", "null"),
    "prePuller": ("object",),
    "prePuller.continuous": ("object",),
    "prePuller.continuous.enabled": ("boolean",),
    "scheduling": ("object",),
    "scheduling.userScheduler": ("object",),
    "scheduling.userScheduler.enabled": ("boolean",),
}
#: Keys whose values are free-form (not checked below them).
_FREE_FORM = ("hub.config", "singleuser.extraEnv")


def _json_type(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, float):
        return "number"
    return {str: "string", list: "array", dict: "object"}[type(value)]


def _walk(node: dict[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    out = []
    for key, value in node.items():
        path = f"{prefix}.{key}" if prefix else key
        out.append((path, value))
        if isinstance(value, dict) and path not in _FREE_FORM:
            out.extend(_walk(value, path))
    return out


def _type_ok(value: Any, allowed: tuple[str, ...]) -> bool:
    if allowed[0] == "enum:":
        return value in allowed[1:]
    kind = _json_type(value)
    return kind in allowed or (kind == "integer" and "number" in allowed)


def test_z2jh_values_use_only_the_charts_keys_with_the_charts_types() -> None:
    values = yaml.safe_load((ROOT / "deploy" / "z2jh" / "config.yaml").read_text())
    for path, value in _walk(values):
        assert path in Z2JH_4_4_0, f"{path} is not a key of the zero-to-jupyterhub chart 4.4.0 (or not written down)"
        assert _type_ok(value, Z2JH_4_4_0[path]), f"{path}: {value!r} is not {Z2JH_4_4_0[path]}"
    for name, config in values["hub"]["config"].items():
        assert re.match(r"^[A-Z]", name) and isinstance(config, dict), f"hub.config.{name}: a class name and an object"
    assert values["singleuser"]["cmd"] == ["rrbot-workshop", "singleuser"]
    assert PYPROJECT["project"]["scripts"]["rrbot-workshop"] == "rrbot_workshop.cli:main"
    assert values["cull"]["enabled"] is True and values["singleuser"]["defaultUrl"].endswith("my_notebooks/00_intro.ipynb")


def test_the_type_check_catches_wrong_keys_and_types() -> None:
    assert not _type_ok("1G", ("number", "null")) and _type_ok(2, ("number", "null"))
    assert not _type_ok("ephemeral", Z2JH_4_4_0["singleuser.storage.type"])
    assert [p for p, _ in _walk({"cull": {"timeout": 1, "bogus": 2}}) if p not in Z2JH_4_4_0] == ["cull.bogus"]


def _requirements(path: Path) -> list[str]:
    return [line.strip() for line in path.read_text().splitlines() if line.strip() and not line.startswith("#")]


def test_repo2docker_installs_the_laptops_pins_on_a_supported_python() -> None:
    pins = PYPROJECT["project"]["dependencies"] + PYPROJECT["project"]["optional-dependencies"]["hub"]
    assert _requirements(ROOT / "binder" / "requirements.txt") == pins
    assert all(re.fullmatch(r"[A-Za-z0-9_.\-\[\]]+==[0-9][A-Za-z0-9.]*", p) for p in pins)
    runtime = (ROOT / "binder" / "runtime.txt").read_text().strip()
    major, minor = (int(x) for x in runtime.removeprefix("python-").split("."))
    assert (3, 11) <= (major, minor) <= (3, 13)
    hub_pin = next(p for p in PYPROJECT["project"]["optional-dependencies"]["dev"] if p.startswith("jupyterhub=="))
    assert hub_pin in pins  # the room test runs the hub the deployments install


@pytest.mark.parametrize("script", ["postBuild", "start"])
def test_repo2docker_scripts_are_executable_bash(script: str) -> None:
    path = ROOT / "binder" / script
    assert path.stat().st_mode & 0o111 and path.read_text().startswith("#!/bin/bash")
    assert subprocess.run(["bash", "-n", str(path)], capture_output=True, check=False).returncode == 0


def test_devcontainer_sets_the_course_up_with_its_own_command() -> None:
    config = json.loads((ROOT / ".devcontainer" / "devcontainer.json").read_text())
    assert "workshop.py" in config["postCreateCommand"] and 8888 in config["forwardPorts"]
    assert re.search(r"python:3\.1[1-3]$", config["image"])


def _tljh_plugin() -> Any:
    path = ROOT / "deploy" / "tljh" / "tljh_rrbot_workshop" / "__init__.py"
    spec = importlib.util.spec_from_file_location("tljh_rrbot_workshop", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_tljh_plugin_installs_the_course_and_sets_limits_culling_and_the_server() -> None:
    plugin = _tljh_plugin()
    assert plugin.tljh_extra_user_pip_packages() == ["-e", "/opt/rrbot_workshop[hub]"]
    assert "hub" in PYPROJECT["project"]["optional-dependencies"]
    config: dict[str, Any] = {"limits": {"memory": "2G"}}
    plugin.tljh_config_post_install(config)
    assert config["limits"] == {"memory": "2G", "cpu": 1}  # the admin's value is kept
    assert config["services"]["cull"] == {"enabled": True, "timeout": 3600, "every": 300, "users": False}
    assert config["user_environment"]["default_app"] == "jupyterlab"
    c = SimpleNamespace(Spawner=SimpleNamespace(environment={"X": "1"}))
    plugin.tljh_custom_jupyterhub_config(c)
    assert c.Spawner.cmd == ["/opt/tljh/user/bin/rrbot-workshop", "singleuser"]
    assert c.Spawner.environment == {"X": "1", "MPLBACKEND": "Agg"}
    meta = tomllib.loads((ROOT / "deploy" / "tljh" / "pyproject.toml").read_text())
    assert meta["project"]["entry-points"]["tljh"] == {"rrbot_workshop": "tljh_rrbot_workshop"}


def test_the_tljh_hooks_are_tljh_hooks() -> None:
    import pluggy

    plugin = _tljh_plugin()
    manager = pluggy.PluginManager("tljh")
    manager.register(plugin)
    assert {"tljh_extra_user_pip_packages", "tljh_config_post_install", "tljh_custom_jupyterhub_config"} <= {
        name for name in dir(manager.hook) if name.startswith("tljh_")}
