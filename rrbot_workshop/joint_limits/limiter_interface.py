"""The joint limiter interface (Jazzy's ``JointLimiterInterface``): init, configure, enforce, reset.

A limiter is made for its joints, either with limits given directly (``init(joint_names, limits, soft_limits)``) or
from a node's parameters (``init_from_parameters(joint_names, params, urdf_limits)``: the ``joint_limits.<joint>.*``
layout of :mod:`~rrbot_workshop.joint_limits.rosparam`). ``configure`` gives it the joint's state to start from;
``enforce`` limits a desired command in place each cycle and says whether it changed anything.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import Any, Generic, TypeVar

from rrbot_workshop.description.info import JointLimits, SoftJointLimits
from rrbot_workshop.exceptions import ArgumentError, ParameterError
from rrbot_workshop.joint_limits.rosparam import get_joint_limits, get_soft_joint_limits

__all__ = ["JointLimiterInterface"]

_log = logging.getLogger(__name__)

DataT = TypeVar("DataT")


class JointLimiterInterface(Generic[DataT]):
    """Base of the joint limiters; ``DataT`` is what they limit.

    Args:
        joint_names: If given, :meth:`init` is called with these arguments.
        limits: Hard limits, one per joint.
        soft_limits: Soft limits, one per joint, or empty.
    """

    def __init__(
        self,
        joint_names: Sequence[str] | None = None,
        limits: Sequence[JointLimits] = (),
        soft_limits: Sequence[SoftJointLimits] = (),
    ) -> None:
        self.joint_names: list[str] = []
        self.joint_limits: list[JointLimits] = []
        self.soft_joint_limits: list[SoftJointLimits] = []
        if joint_names is not None:
            self.init(joint_names, limits, soft_limits)

    @property
    def number_of_joints(self) -> int:
        """How many joints the limiter was made for."""
        return len(self.joint_names)

    def init(
        self,
        joint_names: Sequence[str],
        limits: Sequence[JointLimits],
        soft_limits: Sequence[SoftJointLimits] = (),
    ) -> None:
        """Make the limiter for ``joint_names`` with these limits.

        Args:
            joint_names: Names of the joints.
            limits: Hard limits, one per joint.
            soft_limits: Soft limits, one per joint, or empty for none.

        Raises:
            ParameterError: If the numbers of names and limits differ, or the limiter does not take that many joints.
        """
        names, hard, soft = list(joint_names), list(limits), list(soft_limits)
        if len(names) != len(hard):
            raise ParameterError(type(self).__name__, "limits", f"{len(names)} joint names ({', '.join(names)}) but "
                                                                f"{len(hard)} limits; give one JointLimits per joint")
        if soft and len(soft) != len(names):
            raise ParameterError(type(self).__name__, "soft_limits", f"{len(names)} joint names but {len(soft)} soft "
                                                                     "limits; give one per joint, or none")
        self.joint_names, self.joint_limits, self.soft_joint_limits = names, hard, soft
        self.on_init()

    def init_from_parameters(
        self,
        joint_names: Sequence[str],
        params: Mapping[str, Any],
        limits: Mapping[str, JointLimits] | None = None,
        soft_limits: Mapping[str, SoftJointLimits] | None = None,
        *,
        source: str = "",
    ) -> None:
        """Make the limiter from a node's ``joint_limits.<joint>.*`` parameters, over ``limits`` (the URDF's).

        Args:
            joint_names: Names of the joints.
            params: The node's parameters (nested or dotted ``joint_limits`` section).
            limits: Joint name -> hard limits to start from (for instance ``HardwareInfo.limits``).
            soft_limits: Joint name -> soft limits to start from (``HardwareInfo.soft_limits``).
            source: The node or file the parameters come from, for error messages.

        Raises:
            ParameterError: If a parameter is wrong (see :func:`~rrbot_workshop.joint_limits.get_joint_limits`).
        """
        hard = [get_joint_limits(j, params, (limits or {}).get(j), source=source) for j in joint_names]
        soft = [get_soft_joint_limits(j, params, (soft_limits or {}).get(j), source=source) for j in joint_names]
        given = [s for s in soft if s is not None]
        self.init(joint_names, hard, [s or SoftJointLimits() for s in soft] if given else [])
        for name, lim in zip(joint_names, hard, strict=True):
            _log.debug("limits of joint '%s': %s", name, lim)

    def configure(self, current_joint_states: DataT) -> bool:
        """Start from ``current_joint_states`` (they become the previous command)."""
        return self.on_configure(current_joint_states)

    def enforce(self, actual: DataT, desired: DataT, dt: float) -> bool:
        """Limit ``desired`` in place.

        Args:
            actual: What the joint measures now.
            desired: The command; changed in place to obey the limits.
            dt: Period in [s]; nothing is limited if it is not positive.

        Returns:
            True if a value of ``desired`` was changed.

        Raises:
            JointLimitsError: If a position is commanded while the measured position is beyond a position limit.
            ArgumentError: If ``actual`` or ``desired`` is None.
        """
        for argument, value in (("actual", actual), ("desired", desired)):
            if value is None:
                raise ArgumentError(f"{type(self).__name__}.enforce", argument, value,
                                    "the joint's data (e.g. JointControlInterfacesData)")
        return self.on_enforce(actual, desired, dt)

    def reset_internals(self) -> None:
        """Forget the previous command (the next one starts from the measured state)."""

    def on_init(self) -> None:
        """Check the joints and prepare the limiter's own state (subclasses)."""

    def on_configure(self, current_joint_states: DataT) -> bool:
        """See :meth:`configure` (subclasses)."""
        raise NotImplementedError

    def on_enforce(self, actual: DataT, desired: DataT, dt: float) -> bool:
        """See :meth:`enforce` (subclasses)."""
        raise NotImplementedError
