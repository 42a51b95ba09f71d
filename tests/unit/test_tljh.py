"""The course's plugin for The Littlest JupyterHub, run through TLJH's own code (``../shared/upstream``).

The plugin is installed the way TLJH's installer installs ``--plugin`` (pip, into a folder of the test's own), found
through TLJH's plugin manager and hook specifications (``tljh.utils.get_plugin_manager``: pluggy, the ``tljh`` entry
points), and applied by TLJH's installer (``run_plugin_actions``, ``ensure_config_yaml``, ``ensure_admins``) to a TLJH
prefix in the test's folder; then JupyterHub loads TLJH's ``jupyterhub_config.py`` (TLJH's configurer over that config
and the plugin's hook over JupyterHub's traitlets ``Config``), and the classes it names are made from it. TLJH runs in
subprocesses, so nothing of it stays in the test's interpreter and the hash seed can be chosen.
"""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import pytest
from packaging.requirements import Requirement
from packaging.version import Version
from upstream import TLJH, extract

ROOT = Path(__file__).resolve().parents[2]
PLUGIN = ROOT / "deploy" / "tljh"
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())

#: Run by TLJH's installer code: the pip commands it would run to install the plugins' user packages.
_PIP_COMMANDS = """
import json
from unittest import mock
from tljh import installer, utils
pm = utils.get_plugin_manager()
ran = []
with mock.patch.object(utils, "run_subprocess", lambda cmd, *a, **k: ran.append(list(cmd))):
    installer.run_plugin_actions(pm)
print(json.dumps({"plugins": sorted(n for n, _ in pm.list_name_plugin()),
                  "items": [list(items) for items in pm.hook.tljh_extra_user_pip_packages()],
                  "pip": [c for c in ran if c[1:4] == ["-m", "pip", "install"]]}))
"""

#: For each scenario (a TLJH prefix and the installer's environment), in a child forked after JupyterHub is imported
#: once: TLJH's installer writes config.yaml (with the ``--admin`` the README gives), then JupyterHub loads TLJH's
#: config and makes the authenticator and the spawner it names. One JSON line per scenario.
_INSTALL_AND_LOAD = """
import json, os, sys, traceback
from pathlib import Path
from unittest import mock
from jupyterhub.app import JupyterHub
from jupyterhub.scopes import scope_definitions
from jupyterhub.services.service import Service

def scenario(env):
    os.environ.update(env)
    import tljh
    from tljh import installer, utils, config as tljh_config
    pm = utils.get_plugin_manager()
    installer.ensure_config_yaml(pm)
    installer.ensure_admins([["instructor"]])
    app = JupyterHub()
    app.load_config_file(str(Path(tljh.__file__).parent / "jupyterhub_config.py"))
    auth = app.authenticator_class(parent=app)
    auth.check_allow_config()
    spawner = app.spawner_class(parent=app, user=mock.Mock(name="learner"), hub=mock.Mock())
    return {
        "config_yaml": Path(tljh_config.CONFIG_FILE).read_text(),
        "authenticator": type(auth).__module__ + "." + type(auth).__name__,
        "admin_users": sorted(auth.admin_users), "allow_all": auth.allow_all,
        "user_password": getattr(auth, "user_password", None),
        "admin_password": getattr(auth, "admin_password", None),
        "spawner": type(spawner).__name__, "cmd": spawner.cmd, "environment": spawner.environment,
        "default_url": spawner.default_url, "mem_limit": spawner.mem_limit, "cpu_limit": spawner.cpu_limit,
        "services": app.services, "service_keys": sorted(Service.class_trait_names()),
        "roles": app.load_roles, "scopes": sorted(scope_definitions),
    }

for name, env in json.loads(sys.argv[1]).items():
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(read)
        try:
            out = {"result": scenario(env)}
        except BaseException as exc:
            out = {"error": f"{type(exc).__name__}: {exc}", "traceback": traceback.format_exc()}
        with os.fdopen(write, "w") as f:
            f.write(json.dumps(out, default=str))
        os._exit(0)
    os.close(write)
    with os.fdopen(read) as f:
        text = f.read()
    os.waitpid(pid, 0)
    print(json.dumps({"name": name, **json.loads(text)}))
"""

#: The installer's environment in each scenario (besides its own TLJH prefix).
_ROOM, _INSTRUCTOR = "room-pass-1234", "i" * 20 + "nstructor-pass-5678"
_SCENARIOS: dict[str, dict[str, str]] = {
    "default": {},
    "passwords": {"RRBOT_WORKSHOP_ROOM_PASSWORD": _ROOM, "RRBOT_WORKSHOP_INSTRUCTOR_PASSWORD": _INSTRUCTOR},
    "admin's values": {},
    "short room password": {"RRBOT_WORKSHOP_ROOM_PASSWORD": "short",
                            "RRBOT_WORKSHOP_INSTRUCTOR_PASSWORD": "x" * 40},
    "short instructor password": {"RRBOT_WORKSHOP_ROOM_PASSWORD": "room-password",
                                  "RRBOT_WORKSHOP_INSTRUCTOR_PASSWORD": "too-short-for-an-admin"},
    "same passwords": {"RRBOT_WORKSHOP_ROOM_PASSWORD": "y" * 40, "RRBOT_WORKSHOP_INSTRUCTOR_PASSWORD": "y" * 40},
}


@pytest.fixture(scope="module")
def tljh(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """TLJH's source, the plugin installed as TLJH installs it, and a TLJH prefix, all in a folder of the test."""
    base = tmp_path_factory.mktemp("tljh")
    source = extract(TLJH, base)
    # pip builds in the source folder (build/, *.egg-info): build a copy, so the repository stays as it is
    copy = shutil.copytree(PLUGIN, base / "plugin_source", ignore=shutil.ignore_patterns("build", "*.egg-info"))
    plugins = base / "plugins"
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation",
                    "--no-index", "--target", str(plugins), str(copy)], check=True, capture_output=True, timeout=300)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("RRBOT_WORKSHOP_", "JUPYTERHUB_"))}
    env.update(PYTHONPATH=os.pathsep.join([str(plugins), str(source)]), TLJH_INSTALL_PREFIX=str(base / "opt_tljh"))
    return {"base": base, "source": source, "env": env}


def _run(tljh: dict[str, Any], script: str, **env: str) -> dict[str, Any]:
    proc = subprocess.run([sys.executable, "-c", script], env={**tljh["env"], **env}, capture_output=True,
                          text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _pip_install_args(argv: list[str]) -> tuple[Any, list[str]] | str:
    """pip's own parser over ``pip install ARGS``: (options, arguments), or pip's error."""
    from pip._internal.commands import create_command

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            return create_command("install").parse_args(list(argv))
        except SystemExit:
            return err.getvalue().strip().splitlines()[-1]


def test_tljh_finds_the_plugin_through_its_entry_point_and_hookspecs(tljh: dict[str, Any]) -> None:
    out = _run(tljh, _PIP_COMMANDS)
    assert out["plugins"] == ["rrbot_workshop"]
    assert out["items"] == [[f"--editable={'/opt/rrbot_workshop'}"]]


@pytest.mark.parametrize("seeds", [range(0, 8), range(8, 16)], ids=["seeds 0-7", "seeds 8-15"])
def test_the_installers_pip_command_is_valid_whatever_the_hash_seed(tljh: dict[str, Any], seeds: range) -> None:
    """TLJH gathers plugin pip arguments through set(): the order of the items is the hash seed's."""
    for seed in seeds:
        (command,) = _run(tljh, _PIP_COMMANDS, PYTHONHASHSEED=str(seed))["pip"]
        assert command[:5] == [str(tljh["base"] / "opt_tljh" / "user" / "bin" / "python"), "-m", "pip", "install",
                               "--upgrade"]
        parsed = _pip_install_args(command[4:])
        assert not isinstance(parsed, str), f"PYTHONHASHSEED={seed}: {' '.join(command)}: {parsed}"
        options, arguments = parsed
        assert options.editables == ["/opt/rrbot_workshop"] and arguments == [], f"PYTHONHASHSEED={seed}"


def test_every_order_of_the_plugins_pip_items_is_a_valid_pip_command(tljh: dict[str, Any]) -> None:
    (items,) = _run(tljh, _PIP_COMMANDS)["items"]
    for order in itertools.permutations(sorted(set(items))):
        assert not isinstance(_pip_install_args(["--upgrade", *order]), str), order
    # what the plugin gave before: two items, and one of their orders is no pip command
    assert isinstance(_pip_install_args(["--upgrade", "/opt/rrbot_workshop[hub]", "-e"]), str)


def test_the_learners_environment_keeps_the_jupyterhub_tljh_installs(tljh: dict[str, Any]) -> None:
    """TLJH installs jupyterhub>=5.2,<6 in its hub's and users' environments; the course must not move it."""
    spec = next(line for line in (tljh["source"] / "tljh" / "requirements-hub-env.txt").read_text().splitlines()
                if line.startswith("jupyterhub>="))
    tljh_hub = Requirement(spec).specifier
    installed = [Requirement(r) for r in PYPROJECT["project"]["dependencies"]]
    assert not any(r.name == "jupyterhub" for r in installed)  # the plugin installs the course without [hub]
    (hub,) = [Requirement(r) for r in PYPROJECT["project"]["optional-dependencies"]["hub"]]
    lowest = next(Version(s.version) for s in tljh_hub if s.operator == ">=")
    for version in (lowest, Version("5.5.0"), Version("5.99.99")):
        assert version in tljh_hub and version in hub.specifier, version
    assert Version("6.1.1") in hub.specifier  # and the course's server runs on the newest hub too


@pytest.fixture(scope="module")
def loaded(tljh: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Each scenario of :data:`_SCENARIOS` installed in its own TLJH prefix and loaded: name -> result or error."""
    scenarios = {}
    for i, (name, env) in enumerate(_SCENARIOS.items()):
        prefix = tljh["base"] / f"opt_tljh_{i}"
        if name == "admin's values":
            (prefix / "config").mkdir(parents=True)
            (prefix / "config" / "config.yaml").write_text(
                "auth:\n  type: dummy\nlimits:\n  memory: 2G\nservices:\n  cull:\n    timeout: 600\n")
        scenarios[name] = {**env, "TLJH_INSTALL_PREFIX": str(prefix)}
    proc = subprocess.run([sys.executable, "-c", _INSTALL_AND_LOAD, json.dumps(scenarios)], env=tljh["env"],
                          capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    # (TLJH's configurer prints an empty line of its own)
    lines = [line for line in proc.stdout.splitlines() if line.startswith("{\"name\"")]
    return {out["name"]: out for out in map(json.loads, lines)}


def _result(loaded: dict[str, dict[str, Any]], name: str) -> dict[str, Any]:
    assert "result" in loaded[name], loaded[name].get("traceback")
    return loaded[name]["result"]


def test_tljh_loads_the_hub_config_with_the_plugin_and_only_the_instructor_is_admin(loaded) -> None:
    out = _result(loaded, "default")
    assert out["authenticator"] == "jupyterhub.authenticators.shared.SharedPasswordAuthenticator"
    assert out["admin_users"] == ["instructor"] and out["allow_all"] is True
    # made at random where the installer was given none: nobody can log in as the instructor first and take it
    assert len(out["user_password"]) >= 8 and len(out["admin_password"]) >= 32
    assert out["user_password"] != out["admin_password"]
    assert out["spawner"] == "UserCreatingSpawner"
    assert out["cmd"] == ["/opt/tljh/user/bin/rrbot-workshop", "singleuser"]
    assert out["default_url"] == "/lab/tree/my_notebooks/00_intro.ipynb"
    assert out["environment"] == {"MPLBACKEND": "Agg",
                                  "RRBOT_WORKSHOP_CLASS_SERVICE": "http://127.0.0.1:10101/services/rrbot-class/"}
    assert out["mem_limit"] == 2**30 and out["cpu_limit"] == 1
    services = {s["name"]: s for s in out["services"]}
    assert set(services) == {"cull-idle", "rrbot-class"}
    assert "--timeout=10800" in services["cull-idle"]["command"]
    assert set(services["rrbot-class"]) <= set(out["service_keys"])  # keys JupyterHub's Service knows
    assert services["rrbot-class"]["command"][:2] == ["/opt/tljh/user/bin/rrbot-workshop", "class-service"]
    service_role, viewers = out["roles"]
    assert service_role["services"] == ["rrbot-class"] and set(service_role["scopes"]) <= set(out["scopes"])
    assert viewers == {"name": "rrbot-class-viewers", "groups": ["instructors"],
                       "scopes": ["access:services!service=rrbot-class"]}


def test_the_installers_passwords_reach_the_hub(loaded) -> None:
    out = _result(loaded, "passwords")
    assert (out["user_password"], out["admin_password"]) == (_ROOM, _INSTRUCTOR)


@pytest.mark.parametrize(("name", "says"), [("short room password", "at least 8 characters"),
                                            ("short instructor password", "at least 32 characters"),
                                            ("same passwords", "must differ")])
def test_the_installer_refuses_passwords_jupyterhub_would_refuse(loaded, name: str, says: str) -> None:
    error = loaded[name].get("error", "")
    assert error.startswith("ValueError") and says in error and "RRBOT_WORKSHOP_" in error, loaded[name]


def test_values_the_admin_set_are_kept(loaded) -> None:
    out = _result(loaded, "admin's values")
    assert out["authenticator"] == "jupyterhub.auth.DummyAuthenticator"
    assert out["mem_limit"] == 2 * 2**30
    assert "--timeout=600" in {s["name"]: s for s in out["services"]}["cull-idle"]["command"]
