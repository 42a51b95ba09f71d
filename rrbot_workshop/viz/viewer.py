"""The 3D viewer: RViz's robot model display, in meshcat, on 127.0.0.1 only.

A :class:`Viewer` draws a URDF's visuals and poses them by forward kinematics. Attached to a running
system it subscribes to ``/joint_states`` (as ``robot_state_publisher`` does) and follows the robot.
It can record an animation sampled on simulated time and export everything as one self-contained HTML
file that opens offline.

Example:
    >>> viewer = rw.viz.Viewer(system)     # live view of a running system
    >>> with viewer.record():
    ...     system.spin(seconds=3.0)
    >>> viewer.save_html("motion.html")
    >>> viewer.close()
"""

from __future__ import annotations

import contextlib
import html
import logging
import math
import os
import weakref
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from rrbot_workshop.viz.animation import PoseRecording
from rrbot_workshop.viz.meshcat_geometry import shape_geometry, shape_material
from rrbot_workshop.viz.robot_model import RobotModel, load_urdf_text
from rrbot_workshop.viz.scene import Scene, ZmqConnection, ground_grid

__all__ = ["Viewer", "live_viewer"]

_log = logging.getLogger(__name__)

# Scene paths: robots go under /meshcat; /Grid and /Axes are meshcat's default ground grid and axes.
_ROBOTS, _GRID, _AXES = "/meshcat", "/Grid", "/Axes"

# The live viewer of each scene root in this kernel: a new live viewer of the same robot takes over its
# meshcat server (same URL, no second process) and the old viewer is closed.
_LIVE_VIEWERS: dict[str, weakref.ref[Viewer]] = {}


def live_viewer(root: str) -> Viewer | None:
    """The open live viewer drawing under scene path ``root`` in this kernel, or None."""
    ref = _LIVE_VIEWERS.get(root)
    viewer = ref() if ref is not None else None
    if viewer is None or viewer._closed or viewer._server is None:
        return None
    return viewer


class _Held:
    """The resources of one viewer that outlive nothing: released by ``close()`` or when the viewer is collected."""

    __slots__ = ("server", "connection", "subscription")

    def __init__(self) -> None:
        self.server: Any = None
        self.connection: Any = None
        self.subscription: Any = None


def _release(held: _Held) -> None:
    """A viewer was garbage-collected without ``close()``: stop following, disconnect, stop its server."""
    for name, stop in (("subscription", "destroy"), ("connection", "close"), ("server", "close")):
        thing = getattr(held, name)
        setattr(held, name, None)
        if thing is not None:
            try:
                getattr(thing, stop)()
            except Exception:  # noqa: BLE001 - a finalizer must not raise; say what was left
                _log.warning("releasing a collected viewer's %s failed", name, exc_info=True)


def _is_system(source: Any) -> bool:
    return not isinstance(source, (str, os.PathLike)) and hasattr(source, "urdf")


class Viewer:
    """A meshcat view of one robot description, optionally following a running system.

    Args:
        source: URDF text, a path to a ``.urdf`` or ``.xacro`` file, or a running ``System`` (anything
            with ``.urdf`` and ``.bus``; its ``/joint_states`` then drive the view).
        open_server: Start a meshcat server (bound to 127.0.0.1) for a live view. With False nothing is
            started; :meth:`save_html` and :meth:`show` still work from the scene kept in this process.
        live_rate: Most updates per second of simulated time sent to the live view [Hz]. The pose kept
            in this process always follows every message.
        prefix: Scene path under which the robot is drawn (defaults to the URDF's robot name).

    One live view per robot and kernel: a second live ``Viewer`` drawing under the same scene path (the
    same robot name, or the same ``prefix``) takes over the first one's meshcat server, whose page keeps
    its URL, and closes the first viewer (its sliders then say so). Re-running a viewer cell therefore
    never starts a second server. Pass another ``prefix`` to see two robots of the same name at once.

    Raises:
        DescriptionError: If the description cannot be read.
        RuntimeError: If the meshcat server does not start.
    """

    def __init__(
        self, source: Any, *, open_server: bool = True, live_rate: float = 30.0, prefix: str | None = None
    ) -> None:
        self._system = source if _is_system(source) else None
        if self._system is not None:
            urdf, base_dir = str(self._system.urdf), None
        else:
            urdf, base_dir = load_urdf_text(source)
        self.model = RobotModel(urdf, base_dir=base_dir)
        self._root = f"{_ROBOTS}/" + (prefix or self.model.name).strip("/")
        # What must be let go when this viewer goes, even if nobody calls close(): its server, its connection and
        # its subscription. The finalizer holds this record, never the viewer, so the viewer can be collected.
        self._held = _Held()
        weakref.finalize(self, _release, self._held)
        self._slider_boxes: list[weakref.ref[Any]] = []
        self._closed_reason = ""
        connection = None
        reused = False
        if open_server:
            self._server, reused = self._take_over_or_start_server()
            connection = ZmqConnection(self._server.zmq_url)
            self._held.connection = connection
            _LIVE_VIEWERS[self._root] = weakref.ref(self)
        self.scene = Scene(connection)
        if reused:
            self.scene.delete(self._root)  # what the previous viewer of this robot drew on the same server
        self._live_period = 1.0 / live_rate if live_rate > 0 else 0.0
        self._last_sent_stamp: float | None = None
        self._recording: PoseRecording | None = None
        self._animation: Any = None
        self._frame_count = 0
        self._closed = False
        self._draw_robot()
        self._frame_camera()
        self._push_pose()
        if self._system is not None and getattr(self._system, "bus", None) is not None:
            from rrbot_workshop.msgs import JointState

            follow = weakref.WeakMethod(self._on_joint_state)  # the bus must not keep the viewer alive

            def on_joint_state(msg: Any) -> None:
                method = follow()
                if method is not None:
                    method(msg)

            self._subscription = self._system.bus.create_subscription(
                JointState, "/joint_states", on_joint_state, owner="viewer"
            )

    @property
    def _server(self) -> Any:
        return self._held.server

    @_server.setter
    def _server(self, server: Any) -> None:
        self._held.server = server

    @property
    def _subscription(self) -> Any:
        return self._held.subscription

    @_subscription.setter
    def _subscription(self, subscription: Any) -> None:
        self._held.subscription = subscription

    def _take_over_or_start_server(self) -> tuple[Any, bool]:
        """The meshcat server of the previous live viewer of this robot (closing that viewer), or a new one.

        Returns:
            The server, and True if it was taken over.
        """
        previous = live_viewer(self._root)
        if previous is not None and previous._server is not None and previous._server.running:
            server = previous._server
            previous._server = None  # handed over: closing the old viewer must not stop it
            previous._close(f"replaced by a newer viewer of '{self.model.name}'")
            _log.info("viewer of '%s': reusing the meshcat server of the previous viewer (%s)",
                      self.model.name, server.web_url)
            return server, True
        from rrbot_workshop.viz.meshcat_server import MeshcatServer

        return MeshcatServer(), False

    # ------------------------------------------------------------------------------------- drawing
    def _link_path(self, link: str) -> str:
        return f"{self._root}/{link}"

    def _draw_robot(self) -> None:
        for shape in self.model.visuals:
            try:
                geometry, local = shape_geometry(shape)
            except (OSError, ValueError) as exc:
                _log.warning("link '%s': visual %d left out: %s", shape.link, shape.index, exc)
                continue
            path = f"{self._link_path(shape.link)}/visual_{shape.index}"
            self.scene.set_object(path, geometry, shape_material(shape))
            self.scene.set_transform(path, local)

    def _frame_camera(self) -> None:
        """Frame the robot: centre it on the camera's orbit point and step back until it fits.

        meshcat's orbit controls always aim at the world origin and offer no way to move that
        target, so the scene (robot, grid and axes) is shifted instead: the robot's bounding box
        centre lands on the origin, and the camera is placed at a distance where the box fits the
        75 degree field of view, looking from the front-left, a little above. The grid and axes get
        the same shift as ``/meshcat``, so they lie at z = 0 of the URDF's world, under the robot.

        The default grid is replaced by :func:`~rrbot_workshop.viz.scene.ground_grid` (same look,
        short segments): the camera stands inside the grid, and software WebGL (headless Chromium)
        drops every full-length grid line that reaches behind it.
        """
        lower, upper = self.model.bounds()
        centre = (lower + upper) / 2.0
        radius = max(float(np.linalg.norm(upper - lower)) / 2.0, 0.25)
        shift = np.eye(4)
        shift[:3, 3] = -centre
        self.scene.set_object(_GRID, ground_grid())
        for root in (_ROBOTS, _GRID, _AXES):
            self.scene.set_transform(root, shift)
        distance = 1.15 * radius / math.sin(math.radians(75.0 / 2.0))
        direction = np.array([0.55, -1.0, 0.35])
        eye = direction / np.linalg.norm(direction) * distance
        # The camera lives in meshcat's y-up "rotated" frame: world (x, y, z) is (x, z, -y) there.
        self.scene.set_property(
            "/Cameras/default/rotated/<object>", "position", [float(eye[0]), float(eye[2]), float(-eye[1])]
        )

    def _push_pose(self) -> None:
        for link, pose in self.model.link_poses().items():
            self.scene.set_transform(self._link_path(link), pose)

    # ------------------------------------------------------------------------------------- updates
    @property
    def joint_positions(self) -> dict[str, float]:
        """Joint positions currently shown, in [rad] or [m]."""
        return self.model.positions

    def link_poses(self) -> dict[str, np.ndarray]:
        """4x4 pose of every link in the root frame, as currently shown."""
        return self.model.link_poses()

    def set_joint_positions(self, positions: Mapping[str, float], time: float | None = None) -> None:
        """Show the robot at ``positions`` (joint name -> [rad] or [m]); unknown names are ignored.

        Args:
            positions: Joint positions; joints left out keep their value.
            time: Simulated time of this pose in [s], used while recording (None: one frame after the
                previous one).
        """
        self.model.set_positions(positions)
        self._push_pose()
        if self._recording is not None:
            self._recording.sample(time, self.model.link_poses())

    def _on_joint_state(self, msg: Any) -> None:
        positions = {n: p for n, p in zip(msg.name, msg.position, strict=False)}
        if not positions:
            return
        stamp = float(getattr(getattr(msg, "header", None), "stamp", 0.0) or 0.0)
        self.model.set_positions(positions)  # cheap: the pose is computed when a frame or the live view needs it
        if self._recording is not None:
            self._recording.sample(stamp if stamp > 0.0 else None, self.model.link_poses)
        if self.scene.connection is None:
            return
        last = self._last_sent_stamp
        if last is None or stamp <= last or stamp - last >= self._live_period - 1e-9:
            self._last_sent_stamp = stamp
            self._push_pose()

    # ------------------------------------------------------------------------------------- recording
    def start_recording(self, fps: float = 30.0) -> None:
        """Start collecting an animation, one frame every ``1/fps`` [s] of simulated time.

        Frames come from ``/joint_states`` (stamped with simulated time) and from
        :meth:`set_joint_positions`.

        Raises:
            ValueError: If ``fps`` is not positive.
        """
        if not fps > 0:
            raise ValueError(f"fps must be > 0 frames per second, got {fps}")
        self._recording = PoseRecording(fps)
        self._recording.sample(None, self.model.link_poses())

    def stop_recording(self, play: bool = True) -> Any:
        """Stop recording and attach the animation to the scene (and to the live view).

        Returns:
            The ``meshcat.animation.Animation``, or None if nothing was being recorded.
        """
        recording, self._recording = self._recording, None
        if recording is None:
            return None
        self._animation = recording.animation(self._root)
        self._frame_count = len(recording.frames)
        self.scene.set_animation(self._animation, play=play, repetitions=1)
        return self._animation

    @contextlib.contextmanager
    def record(self, fps: float = 30.0) -> Iterator[Viewer]:
        """Context manager: record while the block runs (``with viewer.record(): system.spin(2.0)``)."""
        self.start_recording(fps)
        try:
            yield self
        finally:
            self.stop_recording()

    @property
    def frame_count(self) -> int:
        """Frames in the last finished recording (0 if none)."""
        return self._frame_count if self._animation is not None else 0

    # ------------------------------------------------------------------------------------- output
    def static_html(self) -> str:
        """The scene (and recorded animation) as one self-contained HTML page."""
        self._push_pose()
        return self.scene.static_html(title=f"{self.model.name} - rrbot_workshop")

    def save_html(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`static_html` to ``path``; the file opens offline in any browser.

        Returns:
            The path written.
        """
        out = Path(path)
        out.write_text(self.static_html(), encoding="utf-8")
        return out

    @property
    def url(self) -> str | None:
        """URL of the live view (on 127.0.0.1), or None without a server."""
        return None if self._server is None or self._closed else str(self._server.web_url)

    def show(self, height: int = 400) -> Any:
        """An IPython display object: the live view, or the static page if there is no server."""
        from IPython.display import HTML, IFrame

        if self.url is not None:
            return IFrame(self.url, width="100%", height=height)
        return HTML(self._srcdoc_iframe(height))

    def _srcdoc_iframe(self, height: int) -> str:
        doc = html.escape(self.static_html(), quote=True)
        return f'<div><iframe srcdoc="{doc}" style="width: 100%; height: {height}px; border: none"></iframe></div>'

    def _repr_html_(self) -> str:
        if self.url is not None:
            return f'<iframe src="{self.url}" style="width: 100%; height: 400px; border: none"></iframe>'
        return self._srcdoc_iframe(400)

    def sliders(self) -> Any:
        """One ipywidgets slider per movable joint, limits from the URDF (like ``joint_state_publisher_gui``).

        When this viewer is closed (by :meth:`close`, or replaced by a newer viewer of the same robot) the
        sliders are disabled and the line under them says so; moving one then changes nothing and repeats
        that message instead of failing silently.

        Returns:
            An ``ipywidgets.VBox``: the ``FloatSlider``s in URDF joint order, then a status ``Label``.
        """
        import ipywidgets as widgets

        status = widgets.Label(value="")
        boxes = []
        for joint in self.model.joint_ranges:
            value = min(max(self.model.positions[joint.name], joint.lower), joint.upper)
            slider = widgets.FloatSlider(
                value=value, min=joint.lower, max=joint.upper, step=0.01, description=joint.name,
                continuous_update=True, readout_format=".2f",
            )

            def on_change(change: Mapping[str, Any], name: str = joint.name) -> None:
                if self._closed:
                    status.value = self._gone_message()
                    return
                self.set_joint_positions({name: float(change["new"])})

            slider.observe(on_change, names="value")
            boxes.append(slider)
        box = widgets.VBox([*boxes, status])
        self._slider_boxes.append(weakref.ref(box))
        if self._closed:
            self._mark_sliders_gone()
        return box

    def _gone_message(self) -> str:
        if self._closed_reason.startswith("replaced"):
            then = "use the sliders of the new viewer"
        else:
            then = "create a new viewer and call its sliders()"
        return f"This viewer of '{self.model.name}' is {self._closed_reason or 'closed'}: these sliders move nothing; {then}."

    def _mark_sliders_gone(self) -> None:
        for ref in self._slider_boxes:
            box = ref()
            if box is None:
                continue
            *sliders, status = box.children
            for slider in sliders:
                slider.disabled = True
            status.value = self._gone_message()

    # ------------------------------------------------------------------------------------- shutdown
    @property
    def server_pid(self) -> int | None:
        """Process id of the meshcat server, or None."""
        return None if self._server is None else int(self._server.pid)

    @property
    def closed(self) -> bool:
        """True once :meth:`close` ran or a newer viewer of the same robot took over."""
        return self._closed

    def close(self) -> None:
        """Stop following the system and stop the meshcat server. The scene stays exportable."""
        self._close("closed")

    def _close(self, reason: str) -> None:
        if self._closed:
            return
        if self._subscription is not None:
            self._subscription.destroy()
            self._subscription = None
        if self.scene.connection is not None:
            self.scene.connection.close()
            self.scene.connection = None
        self._held.connection = None
        if self._server is not None:
            self._server.close()
            self._server = None
        if _LIVE_VIEWERS.get(self._root) is not None and _LIVE_VIEWERS[self._root]() is self:
            del _LIVE_VIEWERS[self._root]
        self._closed = True
        self._closed_reason = reason
        self._mark_sliders_gone()

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        where = self.url or "no server"
        return f"<Viewer '{self.model.name}' ({len(self.model.joint_names)} joints) {where}>"

