"""The Littlest JupyterHub plugin for an rrbot_workshop room.

Clone the course on the server first, then run TLJH's installer with this plugin (see deploy/tljh/README.md). The
hooks, all of TLJH's own (``tljh/hooks.py``):

* ``tljh_extra_user_pip_packages``: the course, editable from its clone, with its pinned dependencies, into the
  learners' shared environment. Not JupyterHub: TLJH installs the single-user server itself, at its hub's version.
* ``tljh_config_post_install``: who may log in and who is admin (JupyterHub's ``SharedPasswordAuthenticator``: a room
  password for learners, a separate, longer one for the instructor, never the first person to log in), per-learner
  limits, and an idle culler that leaves a warmed room up until the workshop starts. Every value the admin set
  already is kept.
* ``tljh_custom_jupyterhub_config``: every learner's server is ``rrbot-workshop singleuser`` (it makes or updates
  ``~/rrbot_workshop`` and opens the learner's first notebook), and the instructor's live view,
  ``rrbot-workshop class-service``, runs as a JupyterHub service that learners' self-checks report to.

This module runs in TLJH's hub environment, where the course is not installed: it imports nothing of it.
"""

from __future__ import annotations

import logging
import os
import secrets
from typing import Any

try:  # TLJH's hooks are pluggy hooks of the project "tljh"
    from pluggy import HookimplMarker
except ImportError:  # pragma: no cover - pluggy comes with TLJH
    def HookimplMarker(project: str) -> Any:  # noqa: N802
        return lambda function: function

hookimpl = HookimplMarker("tljh")
logger = logging.getLogger("tljh")

#: Where the course is cloned on the server (``RRBOT_WORKSHOP_COURSE`` overrides it at install time).
COURSE = os.environ.get("RRBOT_WORKSHOP_COURSE", "/opt/rrbot_workshop")
#: TLJH's users' environment, where the course is installed.
USER_ENV = "/opt/tljh/user"
#: The instructor's account (admin); ``--admin NAME`` given to the installer replaces it.
INSTRUCTOR = "instructor"
#: Environment variables the installer reads the two passwords from (``sudo -E`` or ``sudo VAR=...``).
ROOM_PASSWORD_ENV = "RRBOT_WORKSHOP_ROOM_PASSWORD"
INSTRUCTOR_PASSWORD_ENV = "RRBOT_WORKSHOP_INSTRUCTOR_PASSWORD"
#: JupyterHub's SharedPasswordAuthenticator (5.3+): its minimum lengths [characters].
ROOM_PASSWORD_MIN, INSTRUCTOR_PASSWORD_MIN = 8, 32

#: Per learner, from benchmarks/bench_room.py (see docs/instructors.md, "Running a workshop").
LIMITS = {"memory": "1G", "cpu": 1}
#: Stop a server idle for three hours, checked every ten minutes, so a room warmed before the workshop
#: (``rrbot-workshop room warm``) is still up when it starts; users and their files are kept.
CULL = {"enabled": True, "timeout": 10800, "every": 600, "users": False}

#: The instructor's live view: a JupyterHub service on loopback, reached at ``/services/rrbot-class/``.
SERVICE_NAME = "rrbot-class"
SERVICE_PORT = 10101
SERVICE_URL = f"http://127.0.0.1:{SERVICE_PORT}"
#: What a learner's self-check posts to (their own hub token proves who they are).
CLASS_SERVICE_ENV = "RRBOT_WORKSHOP_CLASS_SERVICE"
#: What the service may read from the hub: the users, their servers and activity, their groups.
SERVICE_SCOPES = ["list:users", "read:users", "read:users:activity", "read:servers", "read:groups"]
#: The hub group whose members see the live view besides the admins (teaching assistants).
INSTRUCTORS_GROUP = "instructors"


@hookimpl
def tljh_extra_user_pip_packages() -> list[str]:
    """The course, editable from its clone, as ONE pip argument.

    TLJH gathers every plugin's arguments through a ``set()``, which loses their order: ``["-e", path]`` comes out
    as ``path -e`` in about half of the hash seeds, and pip stops. ``--editable=PATH`` is one item.
    """
    return [f"--editable={COURSE}"]


def _password(env: str, minimum: int, what: str) -> str | None:
    value = os.environ.get(env)
    if value is None:
        return None
    if len(value) < minimum:
        raise ValueError(f"{env}: the {what} must be at least {minimum} characters (JupyterHub's "
                         f"SharedPasswordAuthenticator refuses shorter ones), not {len(value)}")
    return value


@hookimpl
def tljh_config_post_install(config: dict[str, Any]) -> None:
    """Log-in, limits, the idle culler and JupyterLab, unless the admin set them already.

    The passwords come from the installer's environment (:data:`ROOM_PASSWORD_ENV`,
    :data:`INSTRUCTOR_PASSWORD_ENV`); one not given is made at random (``sudo tljh-config show`` shows it; ``sudo
    tljh-config set auth.SharedPasswordAuthenticator.user_password ...`` and ``reload`` change it).

    Raises:
        ValueError: If a given password is shorter than JupyterHub accepts, or both are the same.
    """
    room = _password(ROOM_PASSWORD_ENV, ROOM_PASSWORD_MIN, "room password")
    instructor = _password(INSTRUCTOR_PASSWORD_ENV, INSTRUCTOR_PASSWORD_MIN, "instructor's password")
    if room is not None and room == instructor:
        raise ValueError(f"{ROOM_PASSWORD_ENV} and {INSTRUCTOR_PASSWORD_ENV} must differ: the room password must "
                         "not open the instructor's account")
    auth = config.setdefault("auth", {})
    auth.setdefault("type", "shared-password")
    if auth["type"] in ("shared-password", "jupyterhub.authenticators.shared.SharedPasswordAuthenticator"):
        shared = auth.setdefault("SharedPasswordAuthenticator", {})
        for key, given, size in (("user_password", room, 18), ("admin_password", instructor, 40)):
            if given is not None:
                shared[key] = given
            elif not shared.get(key):
                shared[key] = secrets.token_urlsafe(size)
                logger.info("rrbot_workshop: made a random auth.SharedPasswordAuthenticator.%s; "
                            "'sudo tljh-config show' shows it", key)
        # learners' accounts are made when they first log in with the room password (or ahead, by the instructor)
        shared.setdefault("allow_all", True)
    users = config.setdefault("users", {})
    if not users.get("admin"):
        users["admin"] = [INSTRUCTOR]
    limits = config.setdefault("limits", {})
    for key, value in LIMITS.items():
        limits.setdefault(key, value)
    cull = config.setdefault("services", {}).setdefault("cull", {})
    for key, value in CULL.items():
        cull.setdefault(key, value)
    config.setdefault("user_environment", {}).setdefault("default_app", "jupyterlab")


@hookimpl
def tljh_custom_jupyterhub_config(c: Any) -> None:
    """Learners' servers and the instructor's live view.

    ``c`` is JupyterHub's traitlets ``Config``: a value nobody set is a ``LazyConfigValue``, which takes ``update``
    and ``append`` but is no dict or list, so this hook only updates and appends.
    """
    c.Spawner.cmd = [f"{USER_ENV}/bin/rrbot-workshop", "singleuser"]
    c.Spawner.default_url = "/lab/tree/my_notebooks/00_intro.ipynb"
    c.Spawner.environment.update({"MPLBACKEND": "Agg",
                                  CLASS_SERVICE_ENV: f"{SERVICE_URL}/services/{SERVICE_NAME}/"})
    c.JupyterHub.services.append({
        "name": SERVICE_NAME,
        "url": SERVICE_URL,
        "command": [f"{USER_ENV}/bin/rrbot-workshop", "class-service", "--state",
                    "/opt/tljh/state/rrbot-class.jsonl"],
        "oauth_no_confirm": True,
        "display": True,
    })
    c.JupyterHub.load_roles.append({"name": SERVICE_NAME, "services": [SERVICE_NAME], "scopes": SERVICE_SCOPES})
    # the hub lets a user through to a service's page only with this scope (admins have it for every service)
    c.JupyterHub.load_roles.append({"name": f"{SERVICE_NAME}-viewers", "groups": [INSTRUCTORS_GROUP],
                                    "scopes": [f"access:services!service={SERVICE_NAME}"]})
