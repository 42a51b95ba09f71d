"""Open an exported animation in headless Chromium and check the robot is drawn (not a blank page)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from browser_driver import CHROMIUM, Browser, unavailable

from rrbot_workshop.viz.viewer import Viewer

pytestmark = [pytest.mark.browser]


@pytest.fixture(autouse=True, scope="module")
def _browser_available() -> None:
    if CHROMIUM is None:
        unavailable("headless Chromium not installed (apt-get install -y chromium)")

# Bright orange pedestal and arm, blue ball at the tool: colours that the default scene does not contain.
URDF = """<?xml version="1.0"?>
<robot name="browserbot">
  <material name="orange"><color rgba="1.0 0.42 0.04 1.0"/></material>
  <link name="world"/>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base_link"/></joint>
  <link name="base_link">
    <visual><origin xyz="0 0 0.5"/><geometry><box size="0.2 0.2 1.0"/></geometry><material name="orange"/></visual>
  </link>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/><child link="arm"/><origin xyz="0 0.15 1.0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <link name="arm">
    <visual><origin xyz="0 0 0.4"/><geometry><box size="0.15 0.15 0.8"/></geometry><material name="orange"/></visual>
  </link>
  <joint name="tool" type="fixed"><parent link="arm"/><child link="ball"/><origin xyz="0 0 0.85"/></joint>
  <link name="ball">
    <visual><geometry><sphere radius="0.12"/></geometry><material name="blue"><color rgba="0.1 0.2 0.95 1"/></material></visual>
  </link>
</robot>
"""


#: Animation frames the page draws before the screenshot: the work asked of the browser, on any machine.
FRAMES = 20


def _screenshot(html: Path, png: Path, profile: Path) -> None:
    """The page after it has loaded and drawn :data:`FRAMES` frames (software WebGL, 800 x 600)."""
    assert CHROMIUM is not None
    browser = Browser(CHROMIUM, profile, size=(800, 600), webgl=True)
    try:
        browser.viewport(800, 600)
        browser.open(html.as_uri())
        browser.frames(FRAMES)
        browser.screenshot(png)
    finally:
        browser.close()


def test_recorded_animation_renders_the_robot(tmp_path: Path):
    viewer = Viewer(URDF, open_server=False)
    with viewer.record(fps=30):
        for i in range(101):  # 1 s swing of joint1
            viewer.set_joint_positions({"joint1": 0.8 * math.sin(math.pi * i / 100)}, time=0.01 * i)
    html = viewer.save_html(tmp_path / "animation.html")
    png = tmp_path / "animation.png"
    _screenshot(html, png, tmp_path / "profile")
    assert png.is_file(), "Chromium wrote no screenshot"

    from PIL import Image

    pixels = np.asarray(Image.open(png).convert("RGB"), dtype=float)
    assert pixels.shape[:2] == (600, 800)
    assert pixels.std() > 10.0  # not a blank page
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    orange = (r > 150) & (g > 30) & (g < 140) & (b < 60) & (r - g > 70)
    blue = (b > 150) & (b - r > 120) & (b - g > 100)  # saturated blue; the sky-blue background is not
    assert orange.sum() > 1500, f"only {orange.sum()} orange pixels: robot not drawn"
    assert blue.sum() > 100, f"only {blue.sum()} blue pixels: tool ball not drawn"
    ys, xs = np.nonzero(orange)
    assert 100 < xs.mean() < 700 and 50 < ys.mean() < 550  # framed, not at the edge


def test_ground_grid_fills_the_view_below_the_robot(tmp_path: Path):
    """Grid lines cross every row and every quarter of the bottom of the view (the ground in front of the robot).

    Before the grid was cut into short segments, SwiftShader dropped every line reaching behind the
    camera and only a band of far lines was left, level with the middle of the robot.
    """
    viewer = Viewer(URDF, open_server=False)
    html = viewer.save_html(tmp_path / "still.html")
    png = tmp_path / "still.png"
    _screenshot(html, png, tmp_path / "profile")
    assert png.is_file(), "Chromium wrote no screenshot"

    from PIL import Image

    bottom = np.asarray(Image.open(png).convert("RGB"), dtype=float)[450:]
    background = np.median(bottom, axis=1, keepdims=True)  # the gradient is constant along a row
    lines = np.abs(bottom - background).sum(axis=2) > 30
    assert lines.any(axis=1).all(), "rows at the bottom of the view without a grid line"
    assert all(lines[:, i * 200:(i + 1) * 200].any() for i in range(4)), "grid missing in part of the view"
