"""Tests of rrbot_workshop.viz.animation.PoseRecording (poses sampled on simulated time)."""

from __future__ import annotations

import numpy as np

from rrbot_workshop.viz.animation import PoseRecording


def _pose(x: float) -> dict[str, np.ndarray]:
    pose = np.eye(4)
    pose[0, 3] = x
    return {"link1": pose}


def test_each_frame_keeps_the_first_pose_at_or_after_its_start():
    recording = PoseRecording(fps=10.0)
    for k, t in enumerate((5.0, 5.04, 5.1, 5.12, 5.35)):
        recording.sample(t, _pose(float(k)))
    assert [(frame, poses["link1"][0, 3]) for frame, poses in recording.frames] == [(0, 0.0), (1, 2.0), (3, 4.0)]


def test_samples_without_time_are_one_frame_apart():
    recording = PoseRecording(fps=20.0)
    for k in range(3):
        recording.sample(None, _pose(float(k)))
    assert [frame for frame, _ in recording.frames] == [0, 1, 2]


def test_animation_has_one_clip_per_link_under_the_root_with_every_frame():
    recording = PoseRecording(fps=10.0)
    recording.sample(0.0, _pose(0.0))
    recording.sample(0.1, _pose(1.0))
    animation = recording.animation("/meshcat/robot")
    assert [path.lower() for path in animation.clips] == ["/meshcat/robot/link1"]
    assert [len(clip.tracks["position"].frames) for clip in animation.clips.values()] == [2]


def test_a_link_that_keeps_its_pose_gets_the_first_and_last_keyframes_and_a_moving_one_every_frame():
    recording = PoseRecording(fps=10.0)
    for k in range(4):
        recording.sample(k * 0.1, {**_pose(float(k)), "base_link": np.eye(4)})
    clips = recording.animation("/meshcat/robot").clips
    assert {path.lower().rsplit("/", 1)[1]: clip.tracks["position"].frames for path, clip in clips.items()} == {
        "link1": [0, 1, 2, 3], "base_link": [0, 3]}
