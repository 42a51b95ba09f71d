"""Recorded robot motion: link poses sampled at a fixed frame rate of simulated time.

While a :class:`~rrbot_workshop.viz.viewer.Viewer` records, every pose it is shown goes to a
:class:`PoseRecording`, which keeps one pose per frame: the first pose at or after the frame's start time.
Time is simulated time, so a recording of a three-second motion has three seconds of frames however long
the computer took. :meth:`PoseRecording.animation` turns the frames into a ``meshcat.animation.Animation``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["PoseRecording"]


class PoseRecording:
    """Link poses sampled at a fixed frame rate of simulated time.

    Args:
        fps: Frames per second of simulated time [Hz].

    Attributes:
        fps: Frames per second of simulated time [Hz].
        frames: ``(frame index, link name -> 4x4 pose)`` in recording order.
    """

    def __init__(self, fps: float) -> None:
        self.fps = fps
        self._t0: float | None = None
        self._last_time: float | None = None
        self._last_frame = -1
        self.frames: list[tuple[int, dict[str, np.ndarray]]] = []

    def sample(self, time: float | None,
               poses: dict[str, np.ndarray] | Callable[[], dict[str, np.ndarray]]) -> None:
        """Offer the link ``poses`` at ``time`` [s] (None: one frame after the previous sample).

        ``poses`` may be a function that gives them: it is called only when ``time`` starts a new frame, so a
        recording at a few frames per second of a 100 Hz control loop computes the robot's pose a few times per
        second, not at every cycle.
        """
        if time is None:  # no clock information: the next frame
            time = (self._last_time + 1.0 / self.fps) if self._last_time is not None else 0.0
        if self._t0 is None:
            self._t0 = time
        self._last_time = time
        frame = math.floor((time - self._t0) * self.fps + 1e-6)
        if frame <= self._last_frame:  # this frame already holds the pose at its start time
            return
        self._last_frame = frame
        self.frames.append((frame, poses() if callable(poses) else poses))

    def animation(self, root: str) -> Any:
        """The frames as a ``meshcat.animation.Animation`` of the links drawn under scene path ``root``."""
        with warnings.catch_warnings():  # meshcat imports zmq.eventloop.ioloop, deprecated since pyzmq 17
            warnings.simplefilter("ignore", DeprecationWarning)
            from meshcat.animation import Animation, AnimationFrameVisualizer
            from meshcat.path import Path as MeshcatPath

        anim = Animation(default_framerate=self.fps)
        # a link that keeps its pose the whole recording (the base, links behind fixed joints) needs a keyframe at
        # the start and one at the end (its clip as long as the others), not one per frame: it looks the same, and
        # the page's animation is a fraction of the size to build and send
        first = self.frames[0][1] if self.frames else {}
        still = {link for link, pose in first.items()
                 if all(link in poses and np.array_equal(poses[link], pose) for _, poses in self.frames[1:])}
        for index, (frame, poses) in enumerate(self.frames):
            for link, pose in poses.items():
                if link in still and 0 < index < len(self.frames) - 1:
                    continue
                entries = tuple(p for p in f"{root}/{link}".split("/") if p)
                AnimationFrameVisualizer(anim, MeshcatPath(entries), frame).set_transform(pose)
        return anim
