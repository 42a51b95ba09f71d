"""A PID controller with control_toolbox's semantics (the ``control_toolbox::Pid`` used by ros2_controllers).

One step of :meth:`Pid.compute_command`, with ``e`` the error (reference - measurement):

1. ``u* = p*e + i_term + d*e_dot``, where ``i_term`` is the integral accumulated **before** this step and
   ``e_dot`` is either given or ``(e - e_last)/dt`` (``e_last`` starts at 0);
2. ``u = clamp(u*, u_clamp_min, u_clamp_max)``;
3. only then, unless ``|e| <= error_deadband``, the integral is updated by the anti-windup strategy:

   * ``"none"``: ``i_term += dt*i*e``;
   * ``"back_calculation"`` (only when ``i != 0``): ``i_term += dt*(i*e + (u - u*)/Tt)``; ``Tt = 0`` means
     ``sqrt(d/i)``, or ``p/i`` when ``d = 0``;
   * ``"conditional_integration"``: ``i_term += dt*i*e`` unless the output saturated and ``e*u* > 0``;
4. ``i_term = clamp(i_term, i_clamp_min, i_clamp_max)``.

``dt == 0`` returns the previous command and changes nothing; ``dt < 0`` raises; a non-finite error
returns NaN without touching the state. (Humble integrated *before* computing the output; Jazzy's
order is the one above.)
"""

from __future__ import annotations

import logging
import math
import numbers
import sys
from dataclasses import dataclass, replace
from typing import Any

from rrbot_workshop.exceptions import ArgumentError, ParameterError

__all__ = ["ANTIWINDUP_STRATEGIES", "Gains", "Pid"]

#: Valid values of ``antiwindup_strategy``.
ANTIWINDUP_STRATEGIES = ("legacy", "none", "back_calculation", "conditional_integration")

_EPS = sys.float_info.epsilon
_OWNER = "Pid"
_NUMBERS = ("p", "i", "d", "u_clamp_max", "u_clamp_min", "i_clamp_max", "i_clamp_min", "tracking_time_constant",
            "error_deadband")
_log = logging.getLogger(__name__)


def _is_zero(value: float, tolerance: float = _EPS) -> bool:
    return abs(value) <= tolerance


def _clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


@dataclass(frozen=True)
class Gains:
    """PID gains and limits (``control_toolbox::Pid::Gains`` with its ``AntiWindupStrategy``).

    Attributes:
        p: Proportional gain.
        i: Integral gain.
        d: Derivative gain.
        u_clamp_max: Upper limit of the output.
        u_clamp_min: Lower limit of the output.
        i_clamp_max: Upper limit of the integral term (in output units).
        i_clamp_min: Lower limit of the integral term (in output units).
        antiwindup_strategy: One of :data:`ANTIWINDUP_STRATEGIES`; ``"legacy"`` (Jazzy's default) integrates the
            error first and uses the integral clamped to ``[i_clamp_min, i_clamp_max]`` in the same cycle.
        tracking_time_constant: Back-calculation time constant ``Tt`` in [s]; 0 picks the default rule.
        error_deadband: Errors with ``|e| <=`` this do not integrate.
        antiwindup: Legacy strategy only (the deprecated boolean of Jazzy): also keep the stored integral within
            the clamps, so it cannot wind up beyond them.
    """

    p: float = 0.0
    i: float = 0.0
    d: float = 0.0
    u_clamp_max: float = math.inf
    u_clamp_min: float = -math.inf
    i_clamp_max: float = math.inf
    i_clamp_min: float = -math.inf
    antiwindup_strategy: str = "legacy"
    tracking_time_constant: float = 0.0
    error_deadband: float = _EPS
    antiwindup: bool = False

    def validated(self) -> Gains:
        """Check the gains; return a copy with the default tracking time constant filled in.

        Raises:
            ParameterError: If a limit is NaN, ``u_clamp_min >= u_clamp_max``, the integral limits do
                not satisfy ``i_clamp_min <= 0 <= i_clamp_max`` with ``i_clamp_min < i_clamp_max``, the
                strategy is unknown, or the tracking time constant is negative, non-finite or cannot
                be derived from the gains, or a gain is not a number.
        """
        for field_name in _NUMBERS:
            value = getattr(self, field_name)
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise ParameterError(_OWNER, field_name, f"must be a number, got {value!r} ({type(value).__name__})")
        if not isinstance(self.antiwindup_strategy, str):
            raise ParameterError(_OWNER, "antiwindup_strategy",
                                 f"must be one of {', '.join(ANTIWINDUP_STRATEGIES)}, got {self.antiwindup_strategy!r}")
        if math.isnan(self.u_clamp_min) or math.isnan(self.u_clamp_max):
            raise ParameterError(
                _OWNER, "u_clamp_min/u_clamp_max", f"must not be NaN (u_clamp_min: {self.u_clamp_min}, "
                f"u_clamp_max: {self.u_clamp_max})")
        if not self.u_clamp_min < self.u_clamp_max:
            raise ParameterError(
                _OWNER, "u_clamp_min", f"must be less than u_clamp_max (u_clamp_min: {self.u_clamp_min}, "
                f"u_clamp_max: {self.u_clamp_max})")
        if math.isnan(self.i_clamp_min) or math.isnan(self.i_clamp_max):
            raise ParameterError(
                _OWNER, "i_clamp_min/i_clamp_max", f"must not be NaN (i_clamp_min: {self.i_clamp_min}, "
                f"i_clamp_max: {self.i_clamp_max})")
        if not (self.i_clamp_min <= 0.0 <= self.i_clamp_max and self.i_clamp_min < self.i_clamp_max):
            raise ParameterError(
                _OWNER, "i_clamp_min", f"needs i_clamp_min <= 0 <= i_clamp_max and i_clamp_min < i_clamp_max "
                f"(i_clamp_min: {self.i_clamp_min}, i_clamp_max: {self.i_clamp_max})")
        if self.antiwindup_strategy not in ANTIWINDUP_STRATEGIES:
            raise ParameterError(
                _OWNER, "antiwindup_strategy",
                f"'{self.antiwindup_strategy}' is unknown (valid: {', '.join(ANTIWINDUP_STRATEGIES)})")
        if not math.isfinite(self.error_deadband) or self.error_deadband < 0.0:
            raise ParameterError(_OWNER, "error_deadband", f"must be finite and >= 0, got {self.error_deadband}")
        tt = self.tracking_time_constant
        if self.antiwindup_strategy == "back_calculation":
            if not math.isfinite(tt) or tt < 0.0:
                raise ParameterError(
                    _OWNER, "tracking_time_constant",
                    f"back_calculation needs a finite tracking_time_constant >= 0 [s], got {tt}")
            if _is_zero(tt) and not _is_zero(self.i):
                ratio = self.d / self.i if not _is_zero(self.d) else self.p / self.i
                if not _is_zero(self.d):
                    if ratio < 0.0:
                        raise ParameterError(
                            _OWNER, "tracking_time_constant",
                            f"is 0 and its default sqrt(d/i) is undefined for d={self.d}, i={self.i}; set it")
                    ratio = math.sqrt(ratio)
                # Jazzy would divide by a zero or negative Tt here and turn the integral into NaN or
                # make it diverge; we refuse such gains instead.
                if not ratio > 0.0:
                    raise ParameterError(
                        _OWNER, "tracking_time_constant",
                        f"is 0 and its default p/i = {ratio} is not positive for p={self.p}, i={self.i}; set it")
                return replace(self, tracking_time_constant=ratio)
        return self


class Pid:
    """A PID controller (``control_toolbox::Pid``).

    Args:
        p: Proportional gain.
        i: Integral gain.
        d: Derivative gain.
        u_clamp_max: Upper limit of the output.
        u_clamp_min: Lower limit of the output.
        i_clamp_max: Upper limit of the integral term.
        i_clamp_min: Lower limit of the integral term.
        antiwindup_strategy: ``"legacy"`` (default, as Jazzy), ``"none"``, ``"back_calculation"`` or
            ``"conditional_integration"``.
        tracking_time_constant: Back-calculation ``Tt`` in [s]; 0 means the default rule.
        error_deadband: No integration while ``|error| <=`` this.
        antiwindup: With ``"legacy"``: keep the stored integral within the integral clamps (Jazzy's deprecated
            ``antiwindup`` parameter).

    Raises:
        ParameterError: If the gains are invalid (see :meth:`Gains.validated`).

    Example:
        >>> pid = Pid(p=1.0, i=2.0, d=3.0)
        >>> pid.compute_command(100.001, 0.01)  # error in, command out
    """

    def __init__(
        self,
        p: float = 0.0,
        i: float = 0.0,
        d: float = 0.0,
        u_clamp_max: float = math.inf,
        u_clamp_min: float = -math.inf,
        i_clamp_max: float = math.inf,
        i_clamp_min: float = -math.inf,
        antiwindup_strategy: str = "legacy",
        tracking_time_constant: float = 0.0,
        error_deadband: float = _EPS,
        antiwindup: bool = False,
    ) -> None:
        self._gains = Gains(
            p, i, d, u_clamp_max, u_clamp_min, i_clamp_max, i_clamp_min, antiwindup_strategy,
            tracking_time_constant, error_deadband, antiwindup,
        ).validated()
        self._i_term = 0.0
        self.reset()

    # ----------------------------------------------------------------- gains
    def get_gains(self) -> Gains:
        """Current gains (with the effective tracking time constant)."""
        return self._gains

    def set_gains(self, *args: Any, **kwargs: Any) -> bool:
        """Replace the gains: ``set_gains(gains)`` or ``set_gains(p, i, d, u_clamp_max=..., ...)``.

        As control_toolbox does, invalid gains (bad limits, an unknown strategy, a value that is not a number) are
        logged as an error and the old gains stay in force; the call returns False.

        Returns:
            True if the new gains are in force.
        """
        try:
            if len(args) == 1 and not kwargs and isinstance(args[0], Gains):
                gains = args[0]
            else:
                gains = Gains(*args, **kwargs)
            self._gains = gains.validated()
        except ParameterError as exc:
            _log.error("Pid.set_gains: %s; the gains stay %s", exc, self._gains)
            return False
        except TypeError as exc:  # wrong arguments: Gains' own signature said no
            _log.error("Pid.set_gains: %s (valid: set_gains(Gains(...)) or set_gains(p, i, d, u_clamp_max=..., ...)); "
                       "the gains stay %s", exc, self._gains)
            return False
        return True

    # ----------------------------------------------------------------- state
    def reset(self, save_i_term: bool = False) -> None:
        """Zero the errors and the command; keep the integral only if ``save_i_term``."""
        self._p_error_last = 0.0
        self._p_error = 0.0
        self._d_error = 0.0
        self._cmd = 0.0
        self._cmd_unsat = 0.0
        if not save_i_term:
            self._i_term = 0.0

    def clear_saved_iterm(self) -> None:
        """Zero the integral term."""
        self._i_term = 0.0

    @property
    def p_term(self) -> float:
        """Proportional contribution of the last step (``p * error``)."""
        return self._gains.p * self._p_error

    @property
    def i_term(self) -> float:
        """Integral term (already updated by the last step; used by the next one)."""
        return self._i_term

    @property
    def d_term(self) -> float:
        """Derivative contribution of the last step (``d * error_dot``)."""
        return self._gains.d * self._d_error

    def get_current_pid_errors(self) -> tuple[float, float, float]:
        """``(error, i_term, error_dot)`` as control_toolbox reports them."""
        return self._p_error, self._i_term, self._d_error

    def get_current_cmd(self) -> float:
        """The last command."""
        return self._cmd

    def set_current_cmd(self, cmd: float) -> None:
        """Overwrite the stored command (returned while ``dt == 0``)."""
        self._cmd = cmd

    # ----------------------------------------------------------------- the step
    def compute_command(self, error: float, *args: float) -> float:
        """One PID step: ``compute_command(error, dt)`` or ``compute_command(error, error_dot, dt)``.

        Args:
            error: Reference minus measurement.
            *args: ``dt`` (time step in [s]; the derivative is differentiated from the errors), or
                ``error_dot, dt`` (derivative of the error given directly).

        Returns:
            The (clamped) command; the previous command if ``dt == 0``; NaN if an input is not finite.

        Raises:
            ArgumentError: If ``dt`` is negative (Jazzy throws ``std::invalid_argument``), an argument is not a
                number, or neither one nor two values follow ``error`` (a :class:`ValueError` and a
                :class:`TypeError`).
        """
        if len(args) not in (1, 2):
            raise ArgumentError("Pid.compute_command", "arguments", (error, *args),
                                "(error, dt) or (error, error_dot, dt)")
        for argument, value in zip(("error", *(("dt",) if len(args) == 1 else ("error_dot", "dt"))), (error, *args),
                                   strict=True):
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise ArgumentError("Pid.compute_command", argument, value, "a number")
        if len(args) == 1:
            dt = args[0]
            self._check_dt(dt)
            if _is_zero(dt):
                return self._cmd
            if not math.isfinite(error):
                self._cmd = math.nan
                return self._cmd
            error_dot = (error - self._p_error_last) / dt
            self._p_error_last = error
            return self._step(error, error_dot, dt)
        if len(args) == 2:
            error_dot, dt = args
            self._check_dt(dt)
            if _is_zero(dt):
                return self._cmd
            return self._step(error, error_dot, dt)
        raise AssertionError("unreachable: the argument count is checked first")

    @staticmethod
    def _check_dt(dt: float) -> None:
        if dt < 0.0:
            raise ArgumentError("Pid.compute_command", "dt", dt, "a time step >= 0 [s]")

    def _step(self, error: float, error_dot: float, dt: float) -> float:
        g = self._gains
        self._p_error = error
        self._d_error = error_dot
        if not (math.isfinite(error) and math.isfinite(error_dot)):
            self._cmd = math.nan
            return self._cmd
        if g.antiwindup_strategy == "legacy":
            # Jazzy's default: integrate first, use the clamped integral in this very command.
            if not _is_zero(error, g.error_deadband):
                self._i_term += dt * g.i * error
                if g.antiwindup:
                    self._i_term = _clamp(self._i_term, g.i_clamp_min, g.i_clamp_max)
            u_unsat = g.p * error + _clamp(self._i_term, g.i_clamp_min, g.i_clamp_max) + g.d * error_dot
            u = _clamp(u_unsat, g.u_clamp_min, g.u_clamp_max)
            self._cmd_unsat = u_unsat
            self._cmd = u
            return u
        u_unsat = g.p * error + self._i_term + g.d * error_dot
        u = _clamp(u_unsat, g.u_clamp_min, g.u_clamp_max)
        self._cmd_unsat = u_unsat
        self._cmd = u
        if not _is_zero(error, g.error_deadband):
            if g.antiwindup_strategy == "back_calculation":
                if not _is_zero(g.i):
                    self._i_term += dt * (g.i * error + (u - u_unsat) / g.tracking_time_constant)
            elif g.antiwindup_strategy == "conditional_integration":
                saturated = not _is_zero(u_unsat - u)
                if not (saturated and error * u_unsat > 0.0):
                    self._i_term += dt * g.i * error
            else:
                self._i_term += dt * g.i * error
        self._i_term = _clamp(self._i_term, g.i_clamp_min, g.i_clamp_max)
        return u
