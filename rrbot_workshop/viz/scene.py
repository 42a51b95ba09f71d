"""A meshcat scene kept in this process, mirrored to a live server when there is one.

meshcat's own ``Visualizer`` keeps the scene only in its server, so a static HTML export needs the
server running. :class:`Scene` keeps its own copy (the same tree the server keeps), which makes
:meth:`Scene.static_html` work offline and in CI, and forwards every command to a
:class:`~rrbot_workshop.viz.meshcat_server.MeshcatServer` if one is attached.
"""

from __future__ import annotations

import base64
import logging
import uuid
import warnings
from pathlib import Path as FilePath
from typing import Any

import numpy as np

__all__ = ["Scene", "ZmqConnection", "ground_grid"]

with warnings.catch_warnings():
    # meshcat 0.3.2 imports zmq.eventloop.ioloop, deprecated since pyzmq 17; nothing we can change.
    warnings.simplefilter("ignore", DeprecationWarning)
    import meshcat  # noqa: F401

_log = logging.getLogger(__name__)

_UUID_NAMESPACE = uuid.UUID("6f1d2a52-5c1b-4c57-9d0e-8b7a4f1c2e90")

#: Milliseconds to wait for the server's reply before treating it as gone.
_REPLY_TIMEOUT_MS = 5000


def _viewer_js() -> str:
    """The meshcat viewer's JavaScript bundle, shipped inside the meshcat wheel."""
    import meshcat

    return (FilePath(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text(encoding="utf-8")


def stable_uuids(element: Any, key: str) -> None:
    """Replace the random (MAC- and time-based) uuids of a meshcat object by ones derived from ``key``.

    meshcat uses ``uuid1``, which embeds the host's MAC address and the time; an exported HTML file
    would then differ on every run and carry the learner's MAC address.
    """
    element.uuid = str(uuid.uuid5(_UUID_NAMESPACE, key))
    for part in ("geometry", "material"):
        sub = getattr(element, part, None)
        if sub is not None and hasattr(sub, "uuid"):
            sub.uuid = str(uuid.uuid5(_UUID_NAMESPACE, f"{key}#{part}"))


def ground_grid(size: float = 20.0, divisions: int = 40) -> Any:
    """A square ground grid in the xy plane, centred on the origin, built from one segment per cell edge.

    It looks like meshcat's default ``/Grid`` (a three.js ``GridHelper`` of the same size, darker
    centre lines) but is made of short segments instead of lines spanning the whole grid. Software
    WebGL (SwiftShader, as in headless Chromium; GPU-less virtual machines show the same) was seen to
    drop a whole line segment as soon as one of its ends is behind the camera. With the camera
    standing inside the grid, as it does when a robot is framed, every full-length line has such an
    end, so only a band of far lines was left, seemingly floating behind the robot. Short segments
    lose only the pieces next to the camera, which are out of view anyway.

    Args:
        size: Side length of the grid in [m].
        divisions: Cells along each side.

    Returns:
        A ``meshcat.geometry.LineSegments`` to put at ``"/Grid"`` (replacing the default grid).

    Raises:
        ValueError: If ``size`` is not positive or ``divisions`` is below 1.
    """
    import meshcat.geometry as g

    if not size > 0:
        raise ValueError(f"grid size must be > 0 m, got {size}")
    if divisions < 1:
        raise ValueError(f"grid divisions must be >= 1, got {divisions}")
    ticks = np.linspace(-size / 2.0, size / 2.0, divisions + 1)
    starts, ends = ticks[:-1], ticks[1:]
    across, along = np.meshgrid(ticks, np.arange(divisions), indexing="ij")  # (line, piece)
    a, b = across.ravel(), along.ravel()
    zeros = np.zeros_like(a)
    # Segments parallel to x (fixed y = tick), then parallel to y (fixed x = tick): start, end, start, ...
    x_lines = np.stack([np.stack([starts[b], a, zeros], 1), np.stack([ends[b], a, zeros], 1)], 1)
    y_lines = np.stack([np.stack([a, starts[b], zeros], 1), np.stack([a, ends[b], zeros], 1)], 1)
    vertices = np.concatenate([x_lines, y_lines]).reshape(-1, 3)
    centre = np.isclose(np.concatenate([a, a]), 0.0, atol=size * 1e-9)
    shade = np.where(np.repeat(centre, 2), 0x44 / 255.0, 0x88 / 255.0)
    colors = np.repeat(shade[:, None], 3, axis=1)
    geometry = g.PointsGeometry(vertices.T.astype(np.float32), colors.T.astype(np.float32))
    return g.LineSegments(geometry, g.LineBasicMaterial(vertexColors=True))


class ZmqConnection:
    """Request-reply link to a meshcat server (what ``meshcat.visualizer.ViewerWindow`` does, quietly).

    Args:
        zmq_url: The server's ZeroMQ endpoint.
    """

    def __init__(self, zmq_url: str) -> None:
        import zmq

        self.zmq_url = zmq_url
        self._context: Any = zmq.Context.instance()
        self._socket: Any = None
        self.broken = False
        self._connect()

    def _connect(self) -> None:
        import zmq

        self._socket = self._context.socket(zmq.REQ)
        self._socket.setsockopt(zmq.LINGER, 0)
        self._socket.setsockopt(zmq.RCVTIMEO, _REPLY_TIMEOUT_MS)
        self._socket.connect(self.zmq_url)

    def send(self, frames: list[bytes]) -> bytes | None:
        """Send one multipart command and return the reply, or None if the server does not answer."""
        import zmq

        if self.broken:
            return None
        try:
            self._socket.send_multipart(frames)
            return bytes(self._socket.recv())
        except zmq.ZMQError as exc:
            _log.warning("meshcat server at %s did not answer (%s); live view stopped", self.zmq_url, exc)
            self.broken = True
            self.close()
            return None

    def close(self) -> None:
        """Close the socket."""
        if self._socket is not None:
            self._socket.close(linger=0)
            self._socket = None


class Scene:
    """The scene tree of one viewer.

    Args:
        connection: Live server to mirror commands to, or None for an offline scene.
    """

    def __init__(self, connection: ZmqConnection | None = None) -> None:
        from meshcat.servers.tree import SceneTree

        self._tree = SceneTree()
        self.connection = connection

    # ------------------------------------------------------------------------------------- commands
    def _send(self, command: Any) -> None:
        import umsgpack
        from meshcat.servers.tree import SceneTree, find_node

        lowered = command.lower()
        data = umsgpack.packb(lowered)
        kind = lowered["type"]
        path_text = lowered["path"]
        path = [p for p in path_text.split("/") if p]
        node = find_node(self._tree, path)
        if kind == "set_object":
            node.object = data
            node.properties = []
        elif kind == "set_transform":
            node.transform = data
        elif kind == "set_property":
            node.properties.append(data)
        elif kind == "set_animation":
            node.animation = data
        elif kind == "delete":
            if path:
                parent = find_node(self._tree, path[:-1])
                parent.pop(path[-1], None)
            else:
                self._tree = SceneTree()
        if self.connection is not None:
            self.connection.send([kind.encode("utf-8"), path_text.encode("utf-8"), data])

    @staticmethod
    def _path(path: str) -> Any:
        from meshcat.path import Path

        return Path(tuple(p for p in path.split("/") if p))

    def set_object(self, path: str, geometry: Any, material: Any = None) -> None:
        """Put a geometry (with a material) at ``path`` (e.g. ``"/meshcat/rrbot/link1/visual_0"``)."""
        from meshcat.commands import SetObject

        command = SetObject(geometry, material, self._path(path))
        stable_uuids(command.object, path)
        self._send(command)

    def set_transform(self, path: str, matrix: np.ndarray) -> None:
        """Set the 4x4 pose of ``path`` relative to its parent."""
        from meshcat.commands import SetTransform

        self._send(SetTransform(np.asarray(matrix, dtype=float), self._path(path)))

    def set_property(self, path: str, key: str, value: Any) -> None:
        """Set a property (``"visible"``, ``"position"``, ...) of ``path``."""
        from meshcat.commands import SetProperty

        self._send(SetProperty(key, value, self._path(path)))

    def set_animation(self, animation: Any, play: bool = True, repetitions: int = 1) -> None:
        """Attach a ``meshcat.animation.Animation`` to the scene."""
        from meshcat.commands import SetAnimation

        self._send(SetAnimation(animation, play=play, repetitions=repetitions))

    def delete(self, path: str) -> None:
        """Remove ``path`` and everything under it."""
        from meshcat.commands import Delete

        self._send(Delete(self._path(path)))

    def has_object(self, path: str) -> bool:
        """True if an object was set at ``path``."""
        node: Any = self._tree
        for part in (p for p in path.split("/") if p):
            if part not in node:
                return False
            node = node[part]
        return node.object is not None

    # ------------------------------------------------------------------------------------- export
    def commands(self) -> list[bytes]:
        """Every stored command, in the order a viewer must replay them."""
        from meshcat.servers.tree import walk

        out: list[bytes] = []
        for node in walk(self._tree):
            if node.object is not None:
                out.append(node.object)
            out.extend(node.properties)
            if node.transform is not None:
                out.append(node.transform)
            if node.animation is not None:
                out.append(node.animation)
        return out

    def static_html(self, title: str = "rrbot_workshop viewer") -> str:
        """One self-contained HTML page: the meshcat viewer (JavaScript inlined) and this scene."""
        replay = "\n".join(
            "viewer.handle_command_bytearray(decode(\"" + base64.b64encode(c).decode("ascii") + "\"));"
            for c in self.commands()
        )
        return _PAGE.format(title=title, viewer_js=_viewer_js(), replay=replay)


_PAGE = """<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
  body {{ margin: 0; }}
  #meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
<script>
{viewer_js}
</script>
<script>
function decode(text) {{
  var raw = atob(text);
  var bytes = new Uint8Array(raw.length);
  for (var i = 0; i < raw.length; i++) {{ bytes[i] = raw.charCodeAt(i); }}
  return bytes;
}}
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
{replay}
</script>
</body>
</html>
"""
