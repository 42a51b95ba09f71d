"""The Jupyter side of :mod:`.kernels`: the kernel provisioner that asks the server's template for each kernel, and the
server extension that starts the template with the server.

Both are named in the server's arguments (:func:`.kernels.server_args`, given by ``./workshop start`` and by a
learner's server on a hub); the provisioner is found through its entry point in pyproject.toml. A client that starts
kernels without a server (nbval in ``./workshop test``, named by Jupyter's ``JUPYTER_DEFAULT_PROVISIONER_NAME``) starts
its template at its first kernel, which waits for it.
"""

from __future__ import annotations

import asyncio
import atexit
import contextlib
import os
import time
from typing import Any

from jupyter_client.provisioning import LocalProvisioner

from rrbot_workshop.classroom import kernels

__all__ = ["ForkingProvisioner"]

#: The ``Popen`` arguments for the kernel's output a forked kernel takes: an open file or descriptor each.
STREAMS = ("stdout", "stderr")


def _streams(kwargs: dict[str, Any]) -> dict[str, int] | None:
    """The kernel's output streams given as open files or descriptors: name -> descriptor; ``None`` when one is given
    another way (a pipe, ``DEVNULL``): such a kernel starts as a new process."""
    streams = {}
    for name in STREAMS:
        given = kwargs.get(name)
        if given is None:
            continue
        if isinstance(given, int) and given >= 0:
            streams[name] = given
        elif hasattr(given, "fileno"):
            try:
                streams[name] = int(given.fileno())
            except (OSError, ValueError):
                return None
        else:
            return None
    return streams


class ForkingProvisioner(LocalProvisioner):  # type: ignore[misc]
    """:class:`~jupyter_client.provisioning.LocalProvisioner`, with the kernel forked from the server's template when
    it can be (see :mod:`.kernels`); everything else (ports, connection file, interrupts, restarts) is its own."""

    async def launch_kernel(self, cmd: list[str], **kwargs: Any) -> Any:
        kernel = None
        env = kwargs.get("env")
        streams = _streams(kwargs)
        if not set(kwargs) - {"env", "cwd", "kernel_id", "extra_arguments", *STREAMS} and isinstance(env, dict) \
                and streams is not None:
            template = kernels.template()
            flags = kernels.kernel_flags(list(cmd))
            if not template.started() and flags is not None and template.start(flags):  # no server started it:
                atexit.register(template.stop)  # a client of its own (nbval), whose next kernels gain
            deadline = time.monotonic() + kernels.READY_WAIT
            while template.starting() and time.monotonic() < deadline:  # a notebook opened as the server started
                await asyncio.sleep(0.1)
            kernel = template.launch(list(cmd), dict(env), str(kwargs.get("cwd") or os.getcwd()), streams)
        if kernel is None:
            return await super().launch_kernel(cmd, **kwargs)
        self.process = kernel  # type: ignore[assignment]  # shaped like Popen: poll, wait, send_signal, kill
        self.pid = self.pgid = kernel.pid  # the child starts a session of its own
        self.cwd = kwargs.get("cwd", os.getcwd())
        return self.connection_info


def _jupyter_server_extension_points() -> list[dict[str, str]]:
    return [{"module": kernels.EXTENSION}]


def _load_jupyter_server_extension(serverapp: Any) -> None:
    """Start the template with the server, with the Python options of the server's default kernel; it ends with the
    server."""
    flags: list[str] | None = []
    with contextlib.suppress(Exception):  # no such kernel: the template serves none, harmlessly
        spec = serverapp.kernel_spec_manager.get_kernel_spec(serverapp.kernel_manager.default_kernel_name)
        flags = kernels.kernel_flags(list(spec.argv))
    if flags is not None and kernels.template().start(flags):
        atexit.register(kernels.template().stop)
        serverapp.log.info("rrbot_workshop: kernels are forked from a template process (%s=0 turns it off)",
                           kernels.FORK_ENV)
