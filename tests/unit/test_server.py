"""The learner's Jupyter server on a hub (:mod:`rrbot_workshop.classroom.server`): the slow import deferred, not lost.

Each test runs in a fresh interpreter, since the deferral acts on ``sys.modules``.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from rrbot_workshop.classroom.server import UNUSED_EXTENSIONS, extension_args


def _python(code: str) -> dict:
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_jsonschema_imports_without_building_the_iri_parsers_and_still_checks_iris() -> None:
    pytest.importorskip("rfc3987_syntax")
    out = _python("""
import json, sys
from rrbot_workshop.classroom.server import DEFERRED, defer_import
placed = [defer_import(name, attributes) for name, attributes in DEFERRED.items()]
import jsonschema
loaded_at_import = "rfc3987_syntax.syntax_helpers" in sys.modules
checker = jsonschema.Draft7Validator.FORMAT_CHECKER
good, bad = checker.conforms("https://example.org/ü", "iri"), checker.conforms("not an iri", "iri")
print(json.dumps({"placed": placed, "loaded_at_import": loaded_at_import, "good": good, "bad": bad,
                  "loaded_after": "rfc3987_syntax.syntax_helpers" in sys.modules}))
""")
    assert out == {"placed": [True], "loaded_at_import": False, "good": True, "bad": False, "loaded_after": True}


def test_a_module_imported_already_or_missing_is_left_alone() -> None:
    out = _python("""
import json, sys
import json as already
from rrbot_workshop.classroom.server import defer_import
print(json.dumps([defer_import("json", ("dumps",)), defer_import("no_such_module_here", ("x",)),
                  "no_such_module_here" in sys.modules, sys.modules["json"] is already]))
""")
    assert out == [False, False, False, True]


def test_the_gpl_licensed_rfc3987_is_not_what_makes_it_fast() -> None:
    """jsonschema prefers ``rfc3987`` (GPL) when installed; the course's install has none, and needs none."""
    import importlib.util

    assert importlib.util.find_spec("rfc3987") is None


def test_the_server_leaves_unused_extensions_off_on_its_command_line() -> None:
    from jupyter_server.serverapp import ServerApp

    app = ServerApp()
    app.parse_command_line(extension_args())
    assert app.jpserver_extensions == dict.fromkeys(UNUSED_EXTENSIONS, False)
    assert "jupyterlab" not in UNUSED_EXTENSIONS and "jupyter_server_terminals" not in UNUSED_EXTENSIONS
