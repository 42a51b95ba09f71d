"""A live plot in the notebook (``rqt_plot``): chosen interfaces and topic fields over the last seconds of sim time.

Signals are named as the :class:`~rrbot_workshop.viz.recorder.Recorder` names interfaces (``"joint1/position"``,
``"command:joint1/position"``, a chainable controller's reference interface) or, for a topic, as
``"<topic>:<field>"``: ``"/joint_states:position[joint2]"``, ``"/joint_trajectory_controller/controller_state:
error.positions[0]"``. An index in brackets is a position in the list, or, where the message has a ``name`` (or
``joint_names``) list, the entry of that name.

The panel redraws after each spin of the system (a cell's ``spin``, a panel's run button, every fifth of a second
while the system spins in the background) as a PNG in an ``ipywidgets.Image``: the figure is matplotlib's, drawn off
screen, one axes per unit.
"""

from __future__ import annotations

import io
import math
import re
import time as _wall
from collections import deque
from collections.abc import Sequence
from typing import Any

from rrbot_workshop.exceptions import RRBotWorkshopError

__all__ = ["PlotPanel", "field_value"]

_STEP = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[([^\]]+)\]")


def field_value(msg: Any, path: str) -> float:
    """The number at ``path`` in ``msg`` (``"position[joint1]"``, ``"error.positions[0]"``, ``"twist.linear.x"``).

    Raises:
        RRBotWorkshopError: If the path does not lead to a number; the message says which step failed.
    """
    value, names = msg, None
    for attribute, index in _STEP.findall(path.replace(".", " ")):
        try:
            if attribute:
                names = getattr(value, "name", None) or getattr(value, "joint_names", None) or names
                value = getattr(value, attribute)
            elif index.lstrip("-").isdigit():
                value = value[int(index)]
            else:
                value = value[list(names or []).index(index)]
        except (AttributeError, IndexError, ValueError, TypeError):
            fields = sorted(k for k in vars(value) if not k.startswith("_")) if hasattr(value, "__dict__") else []
            raise RRBotWorkshopError(f"'{path}': no '{attribute or index}' in {type(value).__name__}"
                                     + (f" (fields: {', '.join(fields)})" if fields else "")) from None
    try:
        return float(value)
    except (TypeError, ValueError):
        raise RRBotWorkshopError(f"'{path}' is a {type(value).__name__}, not a number") from None


class PlotPanel:
    """Plots ``signals`` of ``system`` over the last ``window`` seconds of its (simulated) time.

    Args:
        system: A running system.
        signals: Interface names and ``"<topic>:<field>"`` names (see the module docstring).
        window: Seconds of simulated time shown [s].
        refresh_every: While the system spins in the background, redraw at most this often [wall s].
        figsize: Figure size in inches.

    Raises:
        InterfaceNotFound: If an interface does not exist.
        RRBotWorkshopError: If no signal is given.
    """

    def __init__(self, system: Any, signals: Sequence[str], window: float = 5.0, refresh_every: float = 0.2,
                 figsize: tuple[float, float] = (7.0, 3.2)) -> None:
        import ipywidgets

        from rrbot_workshop.viz.recorder import Recorder

        if not signals:
            raise RRBotWorkshopError("PlotPanel needs at least one signal, e.g. ['joint1/position']")
        self.system = system
        self.signals = list(dict.fromkeys(signals))
        self.window = float(window)
        self.refresh_every = float(refresh_every)
        self.figsize = figsize
        interfaces = [s for s in self.signals if not _is_topic_field(s)]
        samples = max(2, int(math.ceil(self.window / system.period)) + 1)
        self._recorder = Recorder(system, interfaces, max_samples=samples) if interfaces else None
        self._topic_samples: dict[str, deque[tuple[float, float]]] = {}
        self._subscriptions = []
        for signal in self.signals:
            if _is_topic_field(signal):
                topic, path = signal.split(":", 1)
                self._topic_samples[signal] = deque()
                self._subscriptions.append(system.bus.create_subscription(
                    None, topic, lambda msg, s=signal, p=path: self._on_message(s, p, msg), owner="plot_panel"))
        self._last_draw = -math.inf
        self._remove_listener = system.add_spin_listener(self._after_spin)
        #: The PNG shown, as bytes (what a screenshot of the panel shows).
        self.image = ipywidgets.Image(format="png")
        self.status = ipywidgets.Label(value="")
        self.widget = ipywidgets.VBox([self.image, self.status])
        self.refresh()

    def _on_message(self, signal: str, path: str, msg: Any) -> None:
        try:
            value = field_value(msg, path)
        except RRBotWorkshopError as exc:
            self.status.value = str(exc)
            value = math.nan
        samples = self._topic_samples[signal]
        samples.append((self.system.time, value))
        while samples and samples[0][0] < self.system.time - self.window:
            samples.popleft()

    def _after_spin(self, _system: Any) -> None:
        if self.system.background is None or _wall.monotonic() - self._last_draw >= self.refresh_every:
            self.refresh()

    def series(self) -> dict[str, tuple[list[float], list[float]]]:
        """``{signal: (times, values)}`` within the window, as plotted."""
        out: dict[str, tuple[list[float], list[float]]] = {}
        if self._recorder is not None and len(self._recorder):
            data = self._recorder.data
            for name in self._recorder.names:
                out[name] = (list(data["time"]), list(data[name]))
        for signal, samples in self._topic_samples.items():
            out[signal] = ([t for t, _ in samples], [v for _, v in samples])
        return {s: out.get(s, ([], [])) for s in self.signals}

    def refresh(self) -> None:
        """Redraw the figure now."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        from rrbot_workshop.viz.plots import unit_of

        self._last_draw = _wall.monotonic()
        by_unit: dict[str, list[str]] = {}
        for signal in self.signals:
            by_unit.setdefault(unit_of(signal.split(":", 1)[-1].split("[")[0]), []).append(signal)
        fig = Figure(figsize=self.figsize, layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(len(by_unit), 1, sharex=True, squeeze=False)[:, 0]
        series = self.series()
        now = self.system.time
        for ax, (unit, names) in zip(axes, by_unit.items(), strict=True):
            for name in names:
                ax.plot(*series[name], label=name)
            ax.set_ylabel(unit)
            ax.set_xlim(max(0.0, now - self.window), max(now, self.window))
            ax.grid(True, alpha=0.3)
            ax.legend(loc="upper left", fontsize="small")
        axes[-1].set_xlabel("simulated time [s]")
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=80)
        self.image.value = buffer.getvalue()
        self.status.value = self.status.value if self.status.value.startswith("'") else f"t = {now:.2f} s"

    def stop(self) -> None:
        """Stop sampling and redrawing (the last figure stays)."""
        if self._recorder is not None:
            self._recorder.stop()
        for sub in self._subscriptions:
            sub.destroy()
        self._subscriptions.clear()
        self._remove_listener()

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self.widget)


def _is_topic_field(signal: str) -> bool:
    return signal.startswith("/") and ":" in signal
