"""Tests of the meshcat viewer: geometry, kinematics, recording, HTML export, and the loopback server."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import textwrap
import time
import uuid
from pathlib import Path

import numpy as np
import pytest

from rrbot_workshop.exceptions import DescriptionError
from rrbot_workshop.middleware.topics import TopicBus
from rrbot_workshop.msgs import Header, JointState
from rrbot_workshop.viz import meshcat_server
from rrbot_workshop.viz.meshcat_server import MeshcatServer, live_servers
from rrbot_workshop.viz.viewer import Viewer

TWO_LINK_URDF = textwrap.dedent(
    """\
    <?xml version="1.0"?>
    <robot name="twolink">
      <material name="orange"><color rgba="1.0 0.42 0.04 1.0"/></material>
      <link name="world"/>
      <joint name="fixed_base" type="fixed"><parent link="world"/><child link="base_link"/></joint>
      <link name="base_link">
        <visual><origin xyz="0 0 1.0"/><geometry><box size="0.1 0.1 2.0"/></geometry><material name="orange"/></visual>
      </link>
      <joint name="joint1" type="continuous">
        <parent link="base_link"/><child link="link1"/><origin xyz="0 0.1 2.0"/><axis xyz="0 1 0"/>
      </joint>
      <link name="link1">
        <visual><origin xyz="0 0 0.5"/><geometry><cylinder radius="0.05" length="1.0"/></geometry></visual>
      </link>
      <joint name="joint2" type="revolute">
        <parent link="link1"/><child link="link2"/><origin xyz="0 0.1 1.0"/><axis xyz="0 1 0"/>
        <limit lower="-2.0" upper="2.0" effort="100" velocity="1"/>
      </joint>
      <link name="link2">
        <visual><geometry><sphere radius="0.1"/></geometry>
          <material name="blue"><color rgba="0.1 0.2 0.9 1"/></material></visual>
      </link>
      <ros2_control name="TwoLink" type="system">
        <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
        <joint name="joint1"><command_interface name="position"/><state_interface name="position"/></joint>
      </ros2_control>
    </robot>
    """
)


@pytest.fixture(autouse=True)
def _no_server_survives():
    """Every test leaves no meshcat server running (close them, then check)."""
    yield
    for server in list(meshcat_server._LIVE):
        server.close()
    assert live_servers() == []


class _StandInSystem:
    """What the viewer needs of a running System: ``urdf`` and ``bus``."""

    def __init__(self, urdf: str) -> None:
        self.urdf = urdf
        self.bus = TopicBus()


def _offline(urdf: str = TWO_LINK_URDF) -> Viewer:
    return Viewer(urdf, open_server=False)


# ------------------------------------------------------------------------------------------ geometry
def test_visuals_of_every_shape_are_read_with_their_colours():
    viewer = _offline()
    kinds = {(s.link, s.kind) for s in viewer.model.visuals}
    assert kinds == {("base_link", "box"), ("link1", "cylinder"), ("link2", "sphere")}
    base = next(s for s in viewer.model.visuals if s.link == "base_link")
    assert base.rgba == pytest.approx((1.0, 0.42, 0.04, 1.0))  # named material declared under <robot>
    ball = next(s for s in viewer.model.visuals if s.link == "link2")
    assert ball.rgba == pytest.approx((0.1, 0.2, 0.9, 1.0))


def test_every_visual_becomes_a_scene_object():
    viewer = _offline()
    for path in ("base_link/visual_0", "link1/visual_0", "link2/visual_0"):
        assert viewer.scene.has_object(f"/meshcat/twolink/{path}")


def test_joint_ranges_come_from_urdf_limits():
    ranges = {r.name: (r.lower, r.upper) for r in _offline().model.joint_ranges}
    assert ranges == {"joint1": (-math.pi, math.pi), "joint2": (-2.0, 2.0)}


def test_mesh_visual_is_loaded_relative_to_the_urdf_file(tmp_path: Path):
    (tmp_path / "tri.stl").write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid t\n"
    )
    urdf = tmp_path / "mesh.urdf"
    urdf.write_text(
        '<robot name="m"><link name="a"><visual><geometry><mesh filename="tri.stl" scale="2 2 2"/></geometry>'
        "</visual></link></robot>"
    )
    viewer = Viewer(urdf, open_server=False)
    assert [s.kind for s in viewer.model.visuals] == ["mesh"]
    assert viewer.scene.has_object("/meshcat/m/a/visual_0")


def test_missing_mesh_is_left_out_with_a_warning(caplog: pytest.LogCaptureFixture):
    urdf = '<robot name="m"><link name="a"><visual><geometry><mesh filename="package://nope/x.stl"/></geometry></visual></link></robot>'
    viewer = Viewer(urdf, open_server=False)
    assert viewer.model.visuals == []
    assert "not found" in caplog.text


def test_missing_file_raises_description_error(tmp_path: Path):
    with pytest.raises(DescriptionError, match="no such URDF file"):
        Viewer(tmp_path / "absent.urdf", open_server=False)


def test_urdf_without_links_raises_description_error():
    with pytest.raises(DescriptionError):
        Viewer('<robot name="empty"></robot>', open_server=False)


def test_rrbot_description_is_drawn():
    """The course's RRBot (processed from xacro) gives one scene object per visual."""
    from rrbot_workshop.description import descriptions_root

    viewer = Viewer(descriptions_root() / "rrbot/urdf/rrbot.urdf.xacro", open_server=False)
    assert viewer.model.joint_names == ["joint1", "joint2"]
    assert viewer.model.visuals
    for shape in viewer.model.visuals:
        assert viewer.scene.has_object(f"/meshcat/rrbot/{shape.link}/visual_{shape.index}")


# ------------------------------------------------------------------------------------------ kinematics
def test_set_joint_positions_moves_the_child_links():
    viewer = _offline()
    viewer.set_joint_positions({"joint1": math.pi / 2})
    tip = viewer.link_poses()["link2"][:3, 3]
    # joint1 at (0, 0.1, 2) turns about y: the 1 m link now points along +x.
    assert tip == pytest.approx([1.0, 0.2, 2.0], abs=1e-9)


def test_unknown_and_non_finite_joint_values_are_ignored():
    viewer = _offline()
    viewer.set_joint_positions({"wheel": 3.0, "joint2": float("nan"), "joint1": 0.3})
    assert viewer.joint_positions == {"joint1": 0.3, "joint2": 0.0}


def test_follows_joint_states_published_on_the_bus():
    system = _StandInSystem(TWO_LINK_URDF)
    viewer = Viewer(system, open_server=False)
    system.bus.publish("/joint_states", JointState(name=["joint2", "joint1"], position=[0.5, -0.25]))
    system.bus.deliver()
    assert viewer.joint_positions == {"joint1": -0.25, "joint2": 0.5}


def test_close_stops_following_the_bus():
    system = _StandInSystem(TWO_LINK_URDF)
    viewer = Viewer(system, open_server=False)
    viewer.close()
    assert system.bus.subscription_count("/joint_states") == 0


def test_sliders_span_joint_limits_and_move_the_robot():
    viewer = _offline()
    box = viewer.sliders()
    j1, j2, status = box.children
    assert (j2.description, j2.min, j2.max) == ("joint2", -2.0, 2.0)
    j1.value = 0.4
    assert viewer.joint_positions["joint1"] == pytest.approx(0.4)
    assert status.value == ""


# ------------------------------------------------------------------------------------------ recording
def test_recording_samples_frames_at_the_frame_rate_of_simulated_time():
    viewer = _offline()
    with viewer.record(fps=30):
        for i in range(200):  # 2 s at 100 Hz
            viewer.set_joint_positions({"joint1": 0.01 * i}, time=0.01 * i)
    assert viewer.frame_count == 60


def test_recording_from_stamped_joint_states():
    system = _StandInSystem(TWO_LINK_URDF)
    viewer = Viewer(system, open_server=False)
    viewer.start_recording(fps=10)
    for i in range(1, 101):  # 1 s at 100 Hz
        system.bus.publish("/joint_states", JointState(Header(stamp=0.01 * i), ["joint1"], [0.01 * i]))
        system.bus.deliver()
    animation = viewer.stop_recording()
    assert animation is not None
    assert viewer.frame_count == 11  # the start pose, then one frame every 0.1 s


def test_start_recording_rejects_a_non_positive_frame_rate():
    with pytest.raises(ValueError, match="fps"):
        _offline().start_recording(fps=0)


# ------------------------------------------------------------------------------------------ export
def test_save_html_writes_one_self_contained_page(tmp_path: Path):
    viewer = _offline()
    path = viewer.save_html(tmp_path / "robot.html")
    text = path.read_text()
    assert "new MeshCat.Viewer" in text
    assert "<script src=" not in text and "http://" not in text.split("<script>")[0]


def test_exported_html_is_deterministic_and_carries_no_host_uuid():
    first, second = _offline().static_html(), _offline().static_html()
    assert first == second
    viewer = _offline()
    object_uuid = None
    import umsgpack

    for command in viewer.scene.commands():
        data = umsgpack.unpackb(command)
        if data["type"] == "set_object":
            object_uuid = data["object"]["object"]["uuid"]
            break
    assert object_uuid is not None and uuid.UUID(object_uuid).version == 5  # not uuid1 (MAC + time)


def test_recorded_animation_is_in_the_export(tmp_path: Path):
    viewer = _offline()
    with viewer.record():
        viewer.set_joint_positions({"joint1": 1.0}, time=1.0)
    import umsgpack

    kinds = [umsgpack.unpackb(c)["type"] for c in viewer.scene.commands()]
    assert "set_animation" in kinds


def _sent(commands: list[bytes]) -> dict[tuple[str, str], dict]:
    """Decoded meshcat commands keyed by (type, path); a later command replaces an earlier one."""
    import umsgpack

    out = {}
    for raw in commands:
        data = umsgpack.unpackb(raw)
        out[(data["type"], data.get("path", ""))] = data
    return out


def _column_major(matrix: list[float]) -> np.ndarray:
    return np.asarray(matrix, dtype=float).reshape(4, 4).T


def test_grid_and_axes_get_the_same_shift_as_the_robot():
    """/Grid and /Axes carry the /meshcat transform, so the grid lies at the URDF world's z = 0."""
    viewer = _offline()
    sent = _sent(viewer.scene.commands())
    robots = _column_major(sent[("set_transform", "/meshcat")]["matrix"])
    lower, upper = viewer.model.bounds()
    assert np.allclose(robots[:3, 3], -(lower + upper) / 2.0)  # robot centre on the orbit point
    for root in ("/Grid", "/Axes"):
        assert np.allclose(_column_major(sent[("set_transform", root)]["matrix"]), robots), root


def test_default_grid_is_replaced_by_short_segments_on_the_ground():
    """The /Grid object is a 20 m ground grid whose segments are each one 0.5 m cell edge long."""
    viewer = _offline()
    grid = _sent(viewer.scene.commands())[("set_object", "/Grid")]["object"]
    assert grid["object"]["type"] == "LineSegments"
    array = grid["geometries"][0]["data"]["attributes"]["position"]["array"]
    vertices = np.frombuffer(array.data, dtype=np.float32).reshape(-1, 3)
    lengths = np.linalg.norm(vertices[1::2] - vertices[0::2], axis=1)
    assert np.allclose(lengths, 0.5)
    assert np.allclose(vertices[:, 2], 0.0)
    assert np.allclose(vertices.min(axis=0)[:2], -10.0) and np.allclose(vertices.max(axis=0)[:2], 10.0)


def test_ground_grid_covers_every_cell_edge_once():
    """A 2 x 2 grid has 12 unit segments: 3 lines of 2 pieces in each direction."""
    from rrbot_workshop.viz.scene import ground_grid

    vertices = ground_grid(size=2.0, divisions=2).geometry.position.T
    segments = {tuple(sorted((tuple(a), tuple(b)))) for a, b in zip(vertices[0::2], vertices[1::2], strict=True)}
    assert len(vertices) == 24 and len(segments) == 12


@pytest.mark.parametrize(("size", "divisions", "field"), [(0.0, 4, "size"), (2.0, 0, "divisions")])
def test_ground_grid_rejects_an_empty_grid(size: float, divisions: int, field: str):
    from rrbot_workshop.viz.scene import ground_grid

    with pytest.raises(ValueError, match=field):
        ground_grid(size=size, divisions=divisions)


def test_live_view_gets_the_same_grid_and_shift(monkeypatch: pytest.MonkeyPatch):
    """With a server, the commands sent to it replace and shift the grid as the export does."""
    from rrbot_workshop.viz import viewer as viewer_module

    frames: list[list[bytes]] = []

    class _Server:
        zmq_url, web_url, pid = "tcp://127.0.0.1:1", "http://127.0.0.1:1/static/", 0

        def close(self) -> None:
            pass

    class _Connection:
        def __init__(self, zmq_url: str) -> None:
            self.broken = False

        def send(self, message: list[bytes]) -> bytes:
            frames.append(message)
            return b"ok"

        def close(self) -> None:
            pass

    monkeypatch.setattr(meshcat_server, "MeshcatServer", _Server)
    monkeypatch.setattr(viewer_module, "ZmqConnection", _Connection)
    viewer = Viewer(TWO_LINK_URDF)
    live = _sent([message[2] for message in frames])
    viewer.close()
    exported = _sent(_offline().scene.commands())
    assert live[("set_object", "/Grid")] == exported[("set_object", "/Grid")]
    for root in ("/meshcat", "/Grid", "/Axes"):
        assert live[("set_transform", root)]["matrix"] == exported[("set_transform", root)]["matrix"], root


def test_show_without_server_embeds_the_static_page():
    shown = _offline().show()
    assert "srcdoc=" in shown.data and "MeshCat" in shown.data


# ------------------------------------------------------------------------------------------ server
def _listening_addresses(pid: int) -> list[str]:
    """Local addresses of the TCP sockets in LISTEN state owned by ``pid`` (from /proc)."""
    inodes = set()
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            target = os.readlink(f"/proc/{pid}/fd/{fd}")
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    found = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table) as f:
            next(f)
            for line in f:
                fields = line.split()
                local, state, inode = fields[1], fields[3], fields[9]
                if state == "0A" and inode in inodes:  # 0A = LISTEN
                    found.append(local)
    return found


def _decode(local: str) -> str:
    address, port = local.split(":")
    if len(address) == 8:
        octets = [str(int(address[i:i + 2], 16)) for i in (6, 4, 2, 0)]
        return ".".join(octets) + f":{int(port, 16)}"
    return f"[{address}]:{int(port, 16)}"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_server_listens_on_loopback_only():
    with MeshcatServer() as server:
        deadline = time.monotonic() + 5.0
        addresses: list[str] = []
        while len(addresses) < 2 and time.monotonic() < deadline:
            addresses = [_decode(a) for a in _listening_addresses(server.pid)]
        assert len(addresses) == 2  # zmq and web
        assert all(a.startswith("127.0.0.1:") for a in addresses), addresses
        assert server.web_url.startswith("http://127.0.0.1:")
        assert server.zmq_url.startswith("tcp://127.0.0.1:")


def test_close_stops_the_server_process():
    viewer = Viewer(TWO_LINK_URDF)
    pid = viewer.server_pid
    assert viewer.url is not None and viewer.url.startswith("http://127.0.0.1:")
    viewer.close()
    assert viewer.url is None
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)


def test_live_view_receives_poses_from_the_system():
    system = _StandInSystem(TWO_LINK_URDF)
    with Viewer(system) as viewer:
        system.bus.publish("/joint_states", JointState(Header(stamp=0.5), ["joint1"], [0.7]))
        system.bus.deliver()
        assert viewer.scene.connection is not None and not viewer.scene.connection.broken
        assert viewer.joint_positions["joint1"] == pytest.approx(0.7)


def _gone_or_zombie(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "Z"
    except FileNotFoundError:
        return True


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_server_exits_when_its_parent_is_killed():
    code = "from rrbot_workshop.viz.meshcat_server import MeshcatServer\nimport time\ns = MeshcatServer()\nprint(s.pid, flush=True)\ntime.sleep(60)\n"
    parent = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        child = int(parent.stdout.readline())
        os.kill(parent.pid, signal.SIGKILL)
        parent.wait()
        deadline = time.monotonic() + 10.0
        while not _gone_or_zombie(child) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert _gone_or_zombie(child)
    finally:
        if parent.poll() is None:
            parent.kill()
            parent.wait()


def test_link_poses_are_finite_after_many_updates():
    viewer = _offline()
    for q in np.linspace(-3, 3, 50):
        viewer.set_joint_positions({"joint1": q, "joint2": q / 2})
    assert all(np.isfinite(p).all() for p in viewer.link_poses().values())


# ------------------------------------------------------------------------------------------ re-run cells
def _children() -> set[int]:
    """Process ids whose parent is this process (read from /proc)."""
    me, found = os.getpid(), set()
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == me and fields[0] != "Z":
                found.add(int(entry))
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_rerunning_a_viewer_cell_reuses_its_server_and_leaks_no_process():
    before_servers, before_children = len(live_servers()), _children()
    first = Viewer(TWO_LINK_URDF)
    url, pid = first.url, first.server_pid
    assert len(live_servers()) == before_servers + 1
    for _ in range(3):  # the cell `viewer = rw.viz.Viewer(urdf)` run three more times
        latest = Viewer(TWO_LINK_URDF)
    assert len(live_servers()) == before_servers + 1
    assert _children() - before_children == {pid}
    assert (latest.url, latest.server_pid) == (url, pid)
    assert first.closed and first.url is None and not latest.closed
    first.close()  # closing a replaced viewer leaves the server to its new owner
    assert latest.url == url and _children() - before_children == {pid}
    latest.close()
    assert live_servers()[before_servers:] == [] and _children() - before_children == set()


def test_a_viewer_of_another_robot_name_gets_its_own_server():
    one = Viewer(TWO_LINK_URDF)
    other = Viewer(TWO_LINK_URDF, prefix="left")
    assert one.server_pid != other.server_pid and not one.closed
    one.close()
    other.close()


def test_sliders_of_a_closed_viewer_say_so_and_move_nothing():
    viewer = _offline()
    box = viewer.sliders()
    *sliders, status = box.children
    assert status.value == ""
    viewer.close()
    assert all(s.disabled for s in sliders)
    assert "closed" in status.value and "move nothing" in status.value
    status.value = ""
    sliders[0].value = 0.9
    assert viewer.joint_positions["joint1"] == 0.0
    assert "move nothing" in status.value


def test_sliders_of_a_replaced_viewer_point_to_the_new_one():
    first = Viewer(TWO_LINK_URDF)
    *sliders, status = first.sliders().children
    second = Viewer(TWO_LINK_URDF)
    assert all(s.disabled for s in sliders)
    assert "replaced by a newer viewer of 'twolink'" in status.value and "new viewer" in status.value
    second.close()
