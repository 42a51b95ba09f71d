"""A learner's Jupyter server on a hub: JupyterHub's single-user server, started with less work.

``python -m rrbot_workshop.classroom.server ARGS`` is ``jupyterhub-singleuser ARGS`` (the hub's own entry point, from
the jupyterhub installed beside the course: its version is the deployment's) with two savings, measured with
``benchmarks/bench_room.py``:

* **A slow import, deferred.** Jupyter's event logging imports ``jsonschema``, whose format checkers import
  ``rfc3987_syntax`` (MIT) when it is installed, and that module builds some 35 parsers when imported: about half of
  the server's start. :func:`defer_import` puts a stand-in in its place that imports the real module the first time
  a checker calls it, so nothing is lost: an ``iri`` format is still checked, later. The other way out, installing
  ``rfc3987`` (which jsonschema prefers), would bring GPL code into the install; this keeps it free of it.
* **Server extensions a learner does not use** (:data:`UNUSED_EXTENSIONS`): left off through
  ``--ServerApp.jpserver_extensions`` (see :func:`extension_args`); JupyterLab, its terminals and the hub's own
  extension stay.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import types
from collections.abc import Callable
from typing import Any

__all__ = ["DEFERRED", "UNUSED_EXTENSIONS", "defer_import", "extension_args", "main"]

#: Modules whose import is deferred until first used: name -> the attributes importers take from them at import.
DEFERRED: dict[str, tuple[str, ...]] = {"rfc3987_syntax": ("is_valid_syntax",)}
#: Server extensions a learner's server leaves off: the language-server bridge (the course installs no language
#: server, yet it looks for them at every start) and the classic notebook's shim (JupyterLab does not need it).
UNUSED_EXTENSIONS = ("jupyter_lsp", "notebook_shim")


def defer_import(name: str, attributes: tuple[str, ...]) -> bool:
    """Put a stand-in for module ``name`` in ``sys.modules`` that imports the real one when first used.

    ``from name import attribute`` (for each of ``attributes``) gives a function that imports the module and calls
    the real one; any other public attribute imports it at once. Nothing happens when the module is imported already or not
    installed.

    Args:
        name: The module.
        attributes: Functions importers take from the module at their own import.

    Returns:
        True when the stand-in was put in place.
    """
    if name in sys.modules:
        return False
    spec = importlib.util.find_spec(name)
    if spec is None or spec.loader is None:
        return False
    stand_in = types.ModuleType(name, f"{name}, imported when first used (rrbot_workshop.classroom.server)")
    real: list[types.ModuleType] = []

    def load() -> types.ModuleType:
        if not real:
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            try:
                spec.loader.exec_module(module)  # type: ignore[union-attr]
            except BaseException:
                sys.modules[name] = stand_in
                raise
            real.append(module)
        return real[0]

    def forward(attribute: str) -> Callable[..., Any]:
        def call(*args: Any, **kwargs: Any) -> Any:
            return getattr(load(), attribute)(*args, **kwargs)

        call.__name__ = call.__qualname__ = attribute
        return call

    def other(attribute: str) -> Any:
        if attribute.startswith("__"):  # the import system asks for __path__ and the like: not a use
            raise AttributeError(attribute)
        return getattr(load(), attribute)

    for attribute in attributes:
        setattr(stand_in, attribute, forward(attribute))
    stand_in.__getattr__ = other  # type: ignore[method-assign]
    sys.modules[name] = stand_in
    return True


def extension_args(unused: tuple[str, ...] = UNUSED_EXTENSIONS) -> list[str]:
    """The server's arguments that leave the ``unused`` server extensions off."""
    return [f"--ServerApp.jpserver_extensions={name}=False" for name in unused]


def main(argv: list[str] | None = None) -> int:
    """Run JupyterHub's single-user server with ``argv`` (default: this process's arguments)."""
    for name, attributes in DEFERRED.items():
        defer_import(name, attributes)
    from jupyterhub.singleuser import main as singleuser_main

    sys.argv = ["jupyterhub-singleuser", *(sys.argv[1:] if argv is None else argv)]
    return int(singleuser_main() or 0)


if __name__ == "__main__":
    sys.exit(main())
