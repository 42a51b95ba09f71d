"""Wrong controllers that break a rule of update: the commands, how often a displacement is used, and ~/state."""

from __future__ import annotations

import math

from task16_public_mutants import publish_state, wrong

from rrbot_workshop.controllers.displacement import DisplacementController
from rrbot_workshop.middleware.lifecycle import ReturnType
from rrbot_workshop.msgs import Header, JointControllerState, JointJog


@wrong("displacement_used_once",
       rule="each displacement is applied in one update only: later updates leave the command as it is, wherever the "
            "joint is",
       idea="apply one displacement, move the state joints somewhere else, update again: the command must not move.",
       api="h.update(); h.set('joint1/position', ...) moves a state as the hardware would; h.update() again",
       example="state_plus_displacement")
class AppliedEveryCycle(DisplacementController):
    """Keeps the displacement after using it: every update moves the joint again."""

    def update(self, time: float, period: float) -> ReturnType:
        factor = 0.5 if self.slow_mode else 1.0
        for i, displacement in enumerate(self.displacements):
            if not math.isnan(displacement):
                self.command_interfaces[i].set_value(self.state_interfaces[i].get_value() + factor * displacement)
        publish_state(self, time, period)
        return ReturnType.OK


@wrong("state_read_at_the_update",
       rule="the state a displacement is added to is the one read at the update, not the one when the message arrived",
       idea="send a displacement, then move the state joints (as the hardware would between cycles), then update: the "
            "command starts from where the joints are now.",
       api="h.publish('~/reference', ...); h.set('joint1/position', ...); h.update()",
       example="state_plus_displacement")
class StateReadAtArrival(DisplacementController):
    """Remembers where the joints were when the message came."""

    def _on_reference(self, msg: JointJog) -> None:
        before = self.displacements
        super()._on_reference(msg)
        if self.displacements is not before:
            self.origin = [float(s.get_value()) for s in self.state_interfaces] or [0.0] * len(self._joints)

    def update(self, time: float, period: float) -> ReturnType:
        factor = 0.5 if self.slow_mode else 1.0
        origin = getattr(self, "origin", [0.0] * len(self._joints))
        for i, displacement in enumerate(self.displacements):
            if not math.isnan(displacement):
                self.command_interfaces[i].set_value(origin[i] + factor * displacement)
                self.displacements[i] = math.nan
        publish_state(self, time, period)
        return ReturnType.OK


@wrong("state_published_every_update",
       rule="~/state is published after every update, also one that applies no displacement",
       idea="update without sending any message: ~/state must still get a message (for the first joint).",
       api="h.configure(); h.activate(); h.update(); h.latest('~/state') is the last message published there (None "
           "if there was none)",
       example="state_topic")
class StatePublishedWhenMoving(DisplacementController):
    """Publishes ~/state only when an update moved something."""

    def update(self, time: float, period: float) -> ReturnType:
        factor = 0.5 if self.slow_mode else 1.0
        moved = False
        for i, displacement in enumerate(self.displacements):
            if not math.isnan(displacement):
                self.command_interfaces[i].set_value(self.state_interfaces[i].get_value() + factor * displacement)
                self.displacements[i] = math.nan
                moved = True
        if moved:
            publish_state(self, time, period)
        return ReturnType.OK


@wrong("state_error_is_set_point_minus_process_value",
       rule="~/state's error is its set_point minus its process_value (the first joint's command minus its state)",
       idea="make the first joint's command and state differ (apply a displacement, leave the state where it was), "
            "then look at every field of ~/state.",
       api="msg = h.latest('~/state'); msg.set_point, msg.process_value, msg.error, msg.command, msg.time_step, "
           "msg.header.stamp, msg.header.frame_id",
       example="state_topic")
class StateErrorReversed(DisplacementController):
    """Reports the error the other way round."""

    def update(self, time: float, period: float) -> ReturnType:
        factor = 0.5 if self.slow_mode else 1.0
        for i, displacement in enumerate(self.displacements):
            if not math.isnan(displacement):
                self.command_interfaces[i].set_value(self.state_interfaces[i].get_value() + factor * displacement)
                self.displacements[i] = math.nan
        if self._pub is not None and self.command_interfaces:
            set_point = float(self.command_interfaces[0].get_value())
            process_value = float(self.state_interfaces[0].get_value())
            self._pub.publish(JointControllerState(
                header=Header(stamp=time, frame_id=self._joints[0]), set_point=set_point, process_value=process_value,
                error=process_value - set_point, time_step=period, command=set_point))
        return ReturnType.OK


@wrong("state_time_step_is_the_period",
       rule="~/state's time_step is the period the update received: a controller updated at 50 Hz reports 0.02 s, never "
            "an assumed 0.01 s",
       idea="run the controller at another rate than 100 Hz and read ~/state's time_step after an update.",
       api="make_harness(controller_class, update_rate=50): each h.update() passes a period of 1/50 s; "
           "h.latest('~/state').time_step",
       example="state_topic")
class TimeStepAssumed(DisplacementController):
    """Reports the 100 Hz period, whatever the period is."""

    def update(self, time: float, period: float) -> ReturnType:
        return super().update(time, 0.01)
