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
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from rrbot_workshop.viz.animation import PoseRecording
from rrbot_workshop.viz.meshcat_geometry import shape_geometry, shape_material
from rrbot_workshop.viz.robot_model import RobotModel, load_urdf_text
from rrbot_workshop.viz.scene import Scene, ZmqConnection, ground_grid

__all__ = ["Viewer"]

_log = logging.getLogger(__name__)

# Scene paths: robots go under /meshcat; /Grid and /Axes are meshcat's default ground grid and axes.
_ROBOTS, _GRID, _AXES = "/meshcat", "/Grid", "/Axes"

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
        self._server: Any = None
        connection = None
        if open_server:
            from rrbot_workshop.viz.meshcat_server import MeshcatServer

            self._server = MeshcatServer()
            connection = ZmqConnection(self._server.zmq_url)
        self.scene = Scene(connection)
        self._live_period = 1.0 / live_rate if live_rate > 0 else 0.0
        self._last_sent_stamp: float | None = None
        self._subscription: Any = None
        self._recording: PoseRecording | None = None
        self._animation: Any = None
        self._closed = False
        self._draw_robot()
        self._frame_camera()
        self._push_pose()
        if self._system is not None and getattr(self._system, "bus", None) is not None:
            from rrbot_workshop.msgs import JointState

            self._subscription = self._system.bus.create_subscription(
                JointState, "/joint_states", self._on_joint_state, owner="viewer"
            )

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
        self.model.set_positions(positions)
        if self._recording is not None:
            self._recording.sample(stamp if stamp > 0.0 else None, self.model.link_poses())
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
        if self._animation is None:
            return 0
        clips = list(self._animation.clips.values())
        return len(clips[0].tracks["position"].frames) if clips else 0

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

        Returns:
            An ``ipywidgets.VBox``; its ``children`` are the ``FloatSlider``s in URDF joint order.
        """
        import ipywidgets as widgets

        boxes = []
        for joint in self.model.joint_ranges:
            value = min(max(self.model.positions[joint.name], joint.lower), joint.upper)
            slider = widgets.FloatSlider(
                value=value, min=joint.lower, max=joint.upper, step=0.01, description=joint.name,
                continuous_update=True, readout_format=".2f",
            )

            def on_change(change: Mapping[str, Any], name: str = joint.name) -> None:
                self.set_joint_positions({name: float(change["new"])})

            slider.observe(on_change, names="value")
            boxes.append(slider)
        return widgets.VBox(boxes)

    # ------------------------------------------------------------------------------------- shutdown
    @property
    def server_pid(self) -> int | None:
        """Process id of the meshcat server, or None."""
        return None if self._server is None else int(self._server.pid)

    def close(self) -> None:
        """Stop following the system and stop the meshcat server. The scene stays exportable."""
        if self._subscription is not None:
            self._subscription.destroy()
            self._subscription = None
        if self.scene.connection is not None:
            self.scene.connection.close()
            self.scene.connection = None
        if self._server is not None:
            self._server.close()
        self._closed = True

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        where = self.url or "no server"
        return f"<Viewer '{self.model.name}' ({len(self.model.joint_names)} joints) {where}>"

