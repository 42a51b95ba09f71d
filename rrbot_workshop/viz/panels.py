"""Panels in the notebook, the rqt tools' equivalents: a controller manager panel and a trajectory panel.

* :class:`ControllerManagerPanel` (``rqt_controller_manager``): every controller and hardware component with its
  state, buttons to load, configure, activate, deactivate, switch to (activating it in place of the controllers that
  command its interfaces), clean up and unload the chosen controller and to set the
  chosen component's state, a button that runs the robot for a second of simulated time, and the lifecycle diagram.
  Before a switch it asks the controller manager's dry run (:meth:`ControllerManager.explain_switch`, ``%control
  why``): a button that would fail changes nothing and shows why instead.
* :class:`TrajectoryPanel` (``rqt_joint_trajectory_controller``): one slider per joint of a joint trajectory
  controller, within the description's limits, a duration, and a button that sends the goal and runs the robot.
* :class:`~rrbot_workshop.viz.live_plot.PlotPanel` (``rqt_plot``): interfaces and topic fields over the last seconds.

Time is the system's (simulated by default): the robot moves when a panel's run button, or a cell, spins it, or all
the time after ``system.spin_in_background()`` (the panels then follow by themselves). Each
action is a method (``panel.activate()``, ``panel.send()``) that the buttons call, so a test or a cell drives a panel
exactly as a click does.
"""

from __future__ import annotations

import html
from typing import Any

from rrbot_workshop.controller_manager.activity import ACTIVITY_TOPIC
from rrbot_workshop.exceptions import RRBotWorkshopError
from rrbot_workshop.viz.live_plot import PlotPanel

__all__ = ["ControllerManagerPanel", "TrajectoryPanel", "PlotPanel"]


def _widgets() -> Any:
    import ipywidgets

    return ipywidgets


class ControllerManagerPanel:
    """Controllers and hardware of ``system`` with their states, and buttons for the lifecycle requests.

    Args:
        system: A running system.
        run_seconds: Simulated time the run button spins [s].
    """

    VERBS = ("load", "configure", "activate", "deactivate", "switch to", "cleanup", "unload")

    def __init__(self, system: Any, run_seconds: float = 1.0) -> None:
        w = _widgets()
        self.system = system
        self.cm = system.controller_manager
        self.run_seconds = run_seconds
        self.controller = w.Dropdown(description="controller", options=self._controller_names())
        self.component = w.Dropdown(description="hardware", options=self.cm.resource_manager.component_names())
        fit = {"width": "auto", "min_width": "6em"}  # a button as wide as its word: no "acti..." in a narrow notebook
        self.buttons = {verb: w.Button(description=verb, layout=w.Layout(**fit)) for verb in self.VERBS}
        for verb, button in self.buttons.items():
            button.on_click(lambda _b, v=verb: getattr(self, v.replace(" ", "_"))())
        self.hardware_buttons = {s: w.Button(description=s, layout=w.Layout(**fit))
                                 for s in ("unconfigured", "inactive", "active")}
        for state, button in self.hardware_buttons.items():
            button.on_click(lambda _b, s=state: self.set_hardware_state(s))
        self.run_button = w.Button(description=f"run {run_seconds:g} s", layout=w.Layout(**fit))
        self.run_button.on_click(lambda _b: self.run())
        self.table = w.HTML()
        self.message = w.HTML()
        self.diagram = w.HTML()
        #: The text of the message line (what the last action did, or why it would fail).
        self.last_message = ""
        self.widget = w.VBox([
            self.table,
            w.HBox([self.controller, *self.buttons.values()], layout=w.Layout(flex_flow="row wrap")),
            w.HBox([self.component, *self.hardware_buttons.values(), self.run_button],
                   layout=w.Layout(flex_flow="row wrap")),
            self.message,
            self.diagram,
        ])
        self.refresh()
        # as rqt_controller_manager listens to ~/activity: redraw when a state changes, whoever changed it (a cell,
        # a fault in the loop, another panel); delivered with the next cycle, at once while spinning in the background
        topic = getattr(system.controller_manager.activity, "topic", ACTIVITY_TOPIC)  # <manager>/activity
        self._activity = system.bus.create_subscription(None, topic, lambda _msg: self.refresh(),
                                                        owner="controller_manager_panel")

    def stop(self) -> None:
        """Stop following the controller manager's activity (the panel keeps its last view)."""
        self._activity.destroy()

    # ----------------------------------------------------------------- what is shown
    def _controller_names(self) -> list[str]:
        return sorted(set(self.cm.params.controller_types) | set(self.cm.controllers))

    def states(self) -> tuple[dict[str, str], dict[str, str]]:
        """``({controller: state}, {component: state})``; a declared controller not loaded reads ``"not loaded"``."""
        loaded = {c.name: c.state for c in self.cm.list_controllers()}
        controllers = {name: loaded.get(name, "not loaded") for name in self._controller_names()}
        return controllers, {h.name: h.state.label for h in self.cm.list_hardware_components()}

    def refresh(self) -> None:
        """Redraw the table and the lifecycle diagram."""
        from rrbot_workshop.viz.diagrams import lifecycle_states

        controllers, components = self.states()
        rows = "".join(f"<tr><td>{html.escape(n)}</td><td>controller</td><td>{s}</td></tr>" for n, s in controllers.items())
        rows += "".join(f"<tr><td>{html.escape(n)}</td><td>hardware</td><td>{s}</td></tr>" for n, s in components.items())
        self.table.value = f"<table><tr><th>name</th><th>kind</th><th>state</th></tr>{rows}</table>"
        self.diagram.value = lifecycle_states(self.cm).svg
        if self.controller.options != tuple(self._controller_names()):
            chosen = self.controller.value
            self.controller.options = self._controller_names()
            if chosen in self.controller.options:
                self.controller.value = chosen

    def _say(self, text: str, ok: bool = True) -> None:
        self.last_message = text
        color = "inherit" if ok else "#b00020"
        self.message.value = f'<pre style="color:{color}; white-space:pre-wrap">{html.escape(text)}</pre>'

    def _request(self, what: str, call: Any) -> bool:
        try:
            call()
        except RRBotWorkshopError as exc:
            self._say(f"{what}: {exc}", ok=False)
            self.refresh()
            return False
        self._say(f"{what}: done")
        self.refresh()
        return True

    # ----------------------------------------------------------------- actions (the buttons call these)
    def load(self, name: str | None = None) -> bool:
        """Load (``ros2 control load_controller``) the chosen controller."""
        name = name or self.controller.value
        return self._request(f"load {name}", lambda: self.cm.load_controller(name))

    def configure(self, name: str | None = None) -> bool:
        """Configure the chosen controller (unconfigured -> inactive)."""
        name = name or self.controller.value
        return self._request(f"configure {name}", lambda: self.cm.configure_controller(name))

    def _switch(self, activate: list[str], deactivate: list[str]) -> bool:
        what = " and ".join(f"{verb} {', '.join(names)}" for verb, names in
                            (("activate", activate), ("deactivate", deactivate)) if names)
        answer = self.cm.explain_switch(activate, deactivate)
        if not answer.ok:
            self._say(f"{what} would fail; nothing was changed.\n{answer}", ok=False)
            self.refresh()
            return False
        return self._request(what, lambda: self.cm.switch_controllers(activate, deactivate, "strict"))

    def activate(self, name: str | None = None) -> bool:
        """Activate the chosen controller in a strict switch, or say why it would fail."""
        return self._switch([name or self.controller.value], [])

    def deactivate(self, name: str | None = None) -> bool:
        """Deactivate the chosen controller in a strict switch, or say why it would fail."""
        return self._switch([], [name or self.controller.value])

    def switch_to(self, name: str | None = None) -> bool:
        """Activate the chosen controller and, in the same strict switch, deactivate the active controllers that
        command any of its command interfaces (forward position -> trajectory controller); or say why it would fail."""
        name = name or self.controller.value
        spec = self.cm.controllers.get(name)
        wanted = set(self.cm.command_interface_names(spec)) if spec is not None else set()
        holders = [other for other, s in self.cm.controllers.items() if other != name and s.state.label == "active"
                   and wanted & set(self.cm.command_interface_names(s))]
        return self._switch([name], holders)

    def switch(self, activate: list[str], deactivate: list[str]) -> bool:
        """One strict switch, or the reasons it would fail."""
        return self._switch(list(activate), list(deactivate))

    def cleanup(self, name: str | None = None) -> bool:
        """Clean up the chosen controller (inactive -> unconfigured)."""
        name = name or self.controller.value
        return self._request(f"cleanup {name}", lambda: self.cm.cleanup_controller(name))

    def unload(self, name: str | None = None) -> bool:
        """Unload the chosen controller."""
        name = name or self.controller.value
        return self._request(f"unload {name}", lambda: self.cm.unload_controller(name))

    def set_hardware_state(self, state: str, name: str | None = None) -> bool:
        """Drive the chosen hardware component to ``state``."""
        name = name or self.component.value

        def call() -> None:
            if not self.cm.set_hardware_component_state(name, state):
                raise RRBotWorkshopError(f"hardware component '{name}' did not reach '{state}'")

        return self._request(f"set {name} {state}", call)

    def run(self, seconds: float | None = None) -> None:
        """Spin the system for ``seconds`` [s] of its time (default: ``run_seconds``); nothing to do while it spins
        in the background."""
        if self.system.background is not None:
            self._say("the system spins in the background: no need to run it")
            return
        self.system.spin(self.run_seconds if seconds is None else seconds)
        self.refresh()

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self.widget)


class TrajectoryPanel:
    """Sliders for the joints of a joint trajectory controller; the send button sends one goal and runs the robot.

    Args:
        system: A running system.
        controller: The joint trajectory controller's name.

    Raises:
        RRBotWorkshopError: If the controller is not loaded or has no ``joints`` parameter.
    """

    def __init__(self, system: Any, controller: str = "joint_trajectory_controller") -> None:
        from rrbot_workshop.description import parse_ros2_control

        w = _widgets()
        self.system = system
        self.controller = controller
        joints = system.controller_manager.params.parameters_for(controller).get("joints")
        if controller not in system.controller_manager.controllers or not joints:
            raise RRBotWorkshopError(f"'{controller}' is not a loaded controller with a 'joints' parameter "
                                     f"(loaded: {sorted(system.controller_manager.controllers)})")
        self.joints = list(joints)
        limits: dict[str, Any] = {}
        for info in parse_ros2_control(system.controller_manager.robot_description):
            limits.update(info.limits)
        positions = dict(zip(system.latest("/joint_states").name, system.latest("/joint_states").position,
                             strict=True)) if system.latest("/joint_states") else {}
        self.sliders = []
        for joint in self.joints:
            lim = limits.get(joint)
            low = lim.min_position if lim is not None and lim.has_position_limits else -3.14
            high = lim.max_position if lim is not None and lim.has_position_limits else 3.14
            value = min(max(positions.get(joint, 0.0), low), high)
            self.sliders.append(w.FloatSlider(description=joint, min=low, max=high, step=0.01, value=value,
                                              readout_format=".2f", continuous_update=False))
        self.duration = w.FloatSlider(description="duration [s]", min=0.5, max=10.0, step=0.5, value=2.0)
        self.send_button = w.Button(description="send and run")
        self.send_button.on_click(lambda _b: self.send())
        self.status = w.Label(value="")
        self.widget = w.VBox([*self.sliders, self.duration, self.send_button, self.status])

    def send(self, run: bool = True) -> list[float]:
        """Send the sliders' positions as one goal reached in ``duration``; run until then (plus 0.5 s), unless the
        system spins in the background (then the background loop moves the robot, and the status says where it started).

        Returns:
            The joints' positions afterwards (those of the controller's joints in ``/joint_states``).
        """
        from rrbot_workshop.msgs import JointTrajectory, JointTrajectoryPoint

        goal = [float(s.value) for s in self.sliders]
        self.system.publish(f"/{self.controller}/joint_trajectory", JointTrajectory(
            joint_names=list(self.joints),
            points=[JointTrajectoryPoint(positions=goal, time_from_start=float(self.duration.value))]))
        moving_by_itself = self.system.background is not None
        if run and not moving_by_itself:
            self.system.spin(float(self.duration.value) + 0.5)
        state = self.system.latest("/joint_states")
        reached = [state.position[state.name.index(j)] for j in self.joints] if state is not None else []
        where = [round(q, 3) for q in reached]
        if moving_by_itself:  # the loop runs after this click returns: say where the robot starts from
            self.status.value = f"goal {[round(g, 3) for g in goal]} sent from {where}; the background loop moves it"
        else:
            self.status.value = f"goal {[round(g, 3) for g in goal]}, now at {where}"
        return reached

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self.widget)
