"""The controller manager's configure and cleanup services, ported from Jazzy's ``test_controller_manager_srvs.cpp``
(ros2_control, controller_manager/test): ``cleanup_controller_srv`` and ``configure_controller_srv``, every variation.

The requests go through the services on the bus (``/controller_manager/<service>``), as the upstream tests call them
with a ROS client; ``ok`` is the response field they assert.
"""

from __future__ import annotations

import logging

import pytest
from core_helpers import make_cm

from rrbot_workshop.controller_manager.manager import ControllerManager
from rrbot_workshop.exceptions import ControllerError
from rrbot_workshop.middleware.lifecycle import State

CTRL = "test_controller_name"
CHAIN = "test_chainable_controller_name"
CHAIN_TYPE = "test_controller/TestChainableController"


def _call(cm: ControllerManager, service: str, name: str) -> bool:
    return bool(cm.bus.call_service(f"/controller_manager/{service}", {"name": name}).ok)


def _manager() -> ControllerManager:
    """A manager whose YAML declares the test controller and the chainable one (joint1/position commanded)."""
    return make_cm({
        CTRL: {"command_interfaces": ["joint2/position"]},
        CHAIN: {"type": CHAIN_TYPE, "command_interfaces": ["joint1/position"],
                "state_interfaces": ["joint1/position", "joint1/velocity"],
                "reference_interfaces": ["joint1/position", "joint1/velocity"],
                "exported_state_interfaces": ["joint1/position", "joint1/velocity"]},
    })


# ---------------------------------------------------------------------------------- cleanup_controller_srv


def test_cleanup_of_a_controller_that_is_not_loaded_fails() -> None:
    """cleanup_controller_srv, variation 1: no controller of that name is loaded, the service answers not ok."""
    cm = _manager()
    assert not _call(cm, "cleanup_controller", CTRL)
    assert CTRL not in cm.controllers


def test_cleanup_of_an_unconfigured_controller_is_ok_and_changes_nothing() -> None:
    """cleanup_controller_srv, variation 2: a controller only loaded has nothing to clean up; Jazzy answers OK and
    it stays unconfigured and loaded."""
    cm = _manager()
    cm.load_controller(CTRL)
    assert _call(cm, "cleanup_controller", CTRL)
    assert cm.controllers[CTRL].state is State.UNCONFIGURED
    assert list(cm.controllers) == [CTRL]
    published = len(cm.bus.history("/controller_manager/activity"))
    cm.cleanup_controller(CTRL)  # the method as well: no error
    assert cm.controllers[CTRL].state is State.UNCONFIGURED
    assert len(cm.bus.history("/controller_manager/activity")) == published, "nothing changed: no ~/activity"


def test_cleanup_of_an_active_controller_fails_and_it_stays_active() -> None:
    """cleanup_controller_srv, variation 3: an active controller cannot be cleaned up; it stays active."""
    cm = _manager()
    cm.load_controller(CTRL)
    cm.configure_controller(CTRL)
    cm.switch_controllers(activate=[CTRL], strictness="strict")
    assert not _call(cm, "cleanup_controller", CTRL)
    assert cm.controllers[CTRL].state is State.ACTIVE
    with pytest.raises(ControllerError, match=f"'{CTRL}' is 'active' and cannot be cleaned up.*deactivate it first"):
        cm.cleanup_controller(CTRL)


def test_cleanup_of_an_inactive_controller_makes_it_unconfigured() -> None:
    """cleanup_controller_srv, variation 4: after deactivation the cleanup succeeds and it is unconfigured."""
    cm = _manager()
    cm.load_controller(CTRL)
    cm.configure_controller(CTRL)
    cm.switch_controllers(activate=[CTRL], strictness="strict")
    cm.switch_controllers(deactivate=[CTRL], strictness="strict")
    assert cm.controllers[CTRL].state is State.INACTIVE
    assert _call(cm, "cleanup_controller", CTRL)
    assert cm.controllers[CTRL].state is State.UNCONFIGURED
    assert list(cm.controllers) == [CTRL]


def test_set_state_unconfigured_of_an_unconfigured_controller_is_ok() -> None:
    """``ros2 control set_controller_state NAME unconfigured`` on a controller only loaded: nothing to do, no error."""
    cm = _manager()
    cm.load_controller(CTRL)
    cm.set_controller_state(CTRL, "unconfigured")
    assert cm.controllers[CTRL].state is State.UNCONFIGURED


# ---------------------------------------------------------------------------------- configure_controller_srv


def test_configure_of_a_controller_that_is_not_loaded_fails() -> None:
    """configure_controller_srv: configuring a name that is not loaded answers not ok (both controllers)."""
    cm = _manager()
    assert not _call(cm, "configure_controller", CTRL)
    assert not _call(cm, "configure_controller", CHAIN)
    assert dict(cm.controllers) == {}


def test_configure_twice_leaves_the_controller_inactive() -> None:
    """configure_controller_srv: configure makes it inactive; a second configure succeeds and it is inactive again
    (the plain controller and the chainable one alike)."""
    cm = _manager()
    cm.load_controller(CTRL)
    for _ in range(2):
        assert _call(cm, "configure_controller", CTRL)
        assert cm.controllers[CTRL].state is State.INACTIVE
    cm.load_controller(CHAIN)
    for _ in range(2):
        assert _call(cm, "configure_controller", CHAIN)
        assert cm.controllers[CHAIN].state is State.INACTIVE


@pytest.mark.parametrize(("kind", "names"), [
    ("command", ["joint1/position", "joint1/position"]),
    ("state", ["joint1/position", "joint1/position", "joint1/velocity"]),
])
def test_configure_refuses_an_interface_listed_twice(kind: str, names: list[str],
                                                     caplog: pytest.LogCaptureFixture) -> None:
    """configure_controller_srv: a chainable controller whose command (or state) interface configuration lists the
    same interface twice is refused ("are not unique"), cleaned up (its exports removed) and left unconfigured; with
    unique lists again it configures."""
    cm = _manager()
    cm.load_controller(CHAIN)
    assert _call(cm, "configure_controller", CHAIN)
    node = cm.get_controller(CHAIN).get_node()
    node.set_parameters({f"{kind}_interfaces": names})
    with caplog.at_level(logging.ERROR):
        assert not _call(cm, "configure_controller", CHAIN)
    assert f"the {kind} interfaces of controller '{CHAIN}' are not unique" in caplog.text
    assert cm.controllers[CHAIN].state is State.UNCONFIGURED
    rm = cm.resource_manager
    assert rm.get_controller_reference_interface_names(CHAIN) == []
    assert rm.get_controller_exported_state_interface_names(CHAIN) == []
    with pytest.raises(ControllerError, match=f"'{CHAIN}'.*{kind} interfaces are not unique.*joint1/position"):
        cm.configure_controller(CHAIN)
    assert cm.controllers[CHAIN].state is State.UNCONFIGURED
    node.set_parameters({f"{kind}_interfaces": list(dict.fromkeys(names))})
    assert _call(cm, "configure_controller", CHAIN)
    assert cm.controllers[CHAIN].state is State.INACTIVE
    assert rm.get_controller_reference_interface_names(CHAIN) == [f"{CHAIN}/joint1/position",
                                                                  f"{CHAIN}/joint1/velocity"]


def test_unload_after_configure_finalizes_each_controller() -> None:
    """configure_controller_srv, its end: unloading each configured controller through the service succeeds and
    finalizes it."""
    cm = _manager()
    for name in (CTRL, CHAIN):
        cm.load_controller(name)
        cm.configure_controller(name)
    plain, chain = cm.get_controller(CTRL), cm.get_controller(CHAIN)
    assert _call(cm, "unload_controller", CTRL)
    assert plain.get_lifecycle_state() is State.FINALIZED
    assert list(cm.controllers) == [CHAIN]
    assert _call(cm, "unload_controller", CHAIN)
    assert dict(cm.controllers) == {}
    assert chain.get_lifecycle_state() is State.FINALIZED
