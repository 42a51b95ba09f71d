"""A viewer lets go of its meshcat server, connection and subscription when it is garbage-collected or replaced,
not only when closed (issue 23: a replaced or collected viewer kept its server until the kernel ended)."""

from __future__ import annotations

import gc
import sys

import pytest

from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.viz import meshcat_server
from rrbot_workshop.viz.meshcat_server import live_servers
from rrbot_workshop.viz.viewer import Viewer

URDF = """<robot name="releaser">
  <link name="base"/><link name="arm"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")


class _System:
    def __init__(self) -> None:
        self.urdf = URDF
        self.bus = TopicBus()


@pytest.fixture(autouse=True)
def _no_server_survives():  # noqa: ANN202
    yield
    for server in list(meshcat_server._LIVE):
        server.close()


def _gone(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "Z"
    except FileNotFoundError:
        return True


def test_a_collected_viewer_stops_its_server() -> None:
    viewer = Viewer(URDF)
    pid = viewer.server_pid
    assert pid is not None and not _gone(pid)
    del viewer
    gc.collect()
    assert _gone(pid) and live_servers() == []


def test_a_collected_viewer_of_a_system_stops_its_server_and_its_subscription() -> None:
    """The bus holds the viewer's callback weakly: dropping the viewer is enough."""
    system = _System()
    viewer = Viewer(system)
    pid = viewer.server_pid
    assert system.bus.subscription_count("/joint_states") == 1
    del viewer
    gc.collect()
    assert _gone(pid) and live_servers() == []
    assert system.bus.subscription_count("/joint_states") == 0


def test_a_viewer_replaced_in_its_variable_stops_its_server() -> None:
    """`viewer = Viewer(...)` run again with another prefix: the first one is unreferenced and goes."""
    system = _System()
    viewer = Viewer(system, prefix="first")
    first_pid = viewer.server_pid
    viewer = Viewer(system, prefix="second")
    gc.collect()
    assert _gone(first_pid) and not _gone(viewer.server_pid)
    assert [s.pid for s in live_servers()] == [viewer.server_pid]
    viewer.close()
    assert live_servers() == []


def test_a_viewer_replaced_by_one_of_the_same_robot_hands_its_server_over() -> None:
    first = Viewer(URDF)
    pid = first.server_pid
    second = Viewer(URDF)
    del first
    gc.collect()
    assert second.server_pid == pid and not _gone(pid)
    second.close()
    assert _gone(pid)
