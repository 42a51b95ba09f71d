"""The Littlest JupyterHub plugin for an rrbot_workshop room.

Install the course on the server first, then TLJH with this plugin (see deploy/tljh/README.md). The hooks:

* ``tljh_extra_user_pip_packages``: the course, from its clone, with the pinned dependencies and the hub extra,
  installed once into the users' shared environment;
* ``tljh_config_post_install``: per-learner limits and the idle culler (learners' files stay; an idle server stops);
* ``tljh_custom_jupyterhub_config``: every learner's server is ``rrbot-workshop singleuser``, which makes or updates
  ``~/rrbot_workshop`` from the installed course and opens the learner's first notebook.
"""

from __future__ import annotations

import os
from typing import Any

try:  # TLJH's hooks are pluggy hooks of the project "tljh"
    from pluggy import HookimplMarker
except ImportError:  # pragma: no cover - pluggy comes with TLJH
    def HookimplMarker(project: str) -> Any:  # noqa: N802
        return lambda function: function

hookimpl = HookimplMarker("tljh")

#: Where the course is cloned on the server (``RRBOT_WORKSHOP_COURSE`` overrides it).
COURSE = os.environ.get("RRBOT_WORKSHOP_COURSE", "/opt/rrbot_workshop")
#: TLJH's users' environment, where the course is installed.
USER_ENV = "/opt/tljh/user"

#: Per learner, from benchmarks/bench_room.py (see the README's "Running a workshop").
LIMITS = {"memory": "1G", "cpu": 1}
#: Stop a server idle for an hour; check every five minutes; users themselves are kept.
CULL = {"enabled": True, "timeout": 3600, "every": 300, "users": False}


@hookimpl
def tljh_extra_user_pip_packages() -> list[str]:
    """The course, editable from its clone, with the hub extra (JupyterHub's single-user server)."""
    return ["-e", f"{COURSE}[hub]"]


@hookimpl
def tljh_config_post_install(config: dict[str, Any]) -> None:
    """Limits per learner, the idle culler, JupyterLab as the default app (unless the admin set them already)."""
    limits = config.setdefault("limits", {})
    for key, value in LIMITS.items():
        limits.setdefault(key, value)
    cull = config.setdefault("services", {}).setdefault("cull", {})
    for key, value in CULL.items():
        cull.setdefault(key, value)
    config.setdefault("user_environment", {}).setdefault("default_app", "jupyterlab")


@hookimpl
def tljh_custom_jupyterhub_config(c: Any) -> None:
    """Every learner's server makes their workspace first, then opens their first notebook."""
    c.Spawner.cmd = [f"{USER_ENV}/bin/rrbot-workshop", "singleuser"]
    c.Spawner.default_url = "/lab/tree/my_notebooks/00_intro.ipynb"
    c.Spawner.environment = {**dict(getattr(c.Spawner, "environment", {}) or {}), "MPLBACKEND": "Agg"}
