"""Wrong controllers that break a rule of ~/reference (which messages are taken, and what they leave pending) or of
the slow-mode service."""

from __future__ import annotations

import math

from task16_public_mutants import publish_state, wrong

from rrbot_workshop.controllers.displacement import DisplacementController
from rrbot_workshop.middleware.lifecycle import ReturnType
from rrbot_workshop.msgs import JointJog, SetBoolRequest, SetBoolResponse


@wrong("matched_by_name",
       rule="displacements are matched to the joints by name: a message may list the controller's joints in any order",
       idea="send a message that names the joints in another order than the parameters, with different displacements "
            "for each: every joint must move by its own.",
       api="h.publish('~/reference', JointJog(joint_names=['joint2', 'joint1'], displacements=[1.0, 10.0])); "
           "h.update(); h.values(['joint1/position', 'joint2/position'])",
       example="state_plus_displacement")
class MatchedByPosition(DisplacementController):
    """Checks the count, then takes the displacements in the message's order (the original's way)."""

    def _on_reference(self, msg: JointJog) -> None:
        if len(msg.displacements) != len(self._joints):
            self._reject(f"{len(msg.displacements)} displacements for {len(self._joints)} joints")
            return
        self.displacements = [float(d) for d in msg.displacements]


@wrong("wrong_joint_count_refused",
       rule="a message that does not give one displacement for each joint of the controller (fewer or more joints) is "
            "refused and changes nothing",
       idea="send a message for only some of the controller's joints, then update: no joint may move.",
       api="h.publish('~/reference', JointJog(joint_names=['joint1'], displacements=[5.0])); h.update(); the commands "
           "keep their values (0.0 from make_harness)",
       example="unknown_joint_refused")
class SomeJointsAccepted(DisplacementController):
    """Takes a message for some of the joints and moves those."""

    def _on_reference(self, msg: JointJog) -> None:
        names = list(msg.joint_names)
        if len(names) != len(msg.displacements) or any(n not in self._joints for n in names) \
                or len(set(names)) != len(names):
            super()._on_reference(msg)
            return
        pending = [math.nan] * len(self._joints)
        for name, value in zip(names, msg.displacements, strict=True):
            pending[self._joints.index(name)] = float(value)
        self.displacements = pending


@wrong("repeated_joint_refused",
       rule="a message that names a joint twice is refused, even when its number of names is right",
       idea="send a message with the right number of names where one joint appears twice (and another not at all): "
            "no joint may move.",
       api="h.publish('~/reference', JointJog(joint_names=['joint1', 'joint1'], displacements=[1.0, 2.0])); "
           "h.update(); h.values([...])",
       example="unknown_joint_refused")
class RepeatedJointAccepted(DisplacementController):
    """Checks the count and that every name is known, but not that each joint is named once."""

    def _on_reference(self, msg: JointJog) -> None:
        names = list(msg.joint_names)
        if len(names) != len(self._joints) or len(msg.displacements) != len(names) \
                or any(n not in self._joints for n in names):
            super()._on_reference(msg)
            return
        pending = [math.nan] * len(self._joints)
        for name, value in zip(names, msg.displacements, strict=True):
            pending[self._joints.index(name)] = float(value)
        self.displacements = pending


@wrong("refused_message_keeps_the_pending_one",
       rule="a refused message changes nothing, not even a displacement still waiting for the next update",
       idea="send a valid message, then a message that must be refused, then update: the valid one is still applied.",
       api="two h.publish('~/reference', ...) before one h.update()",
       example="unknown_joint_refused")
class RefusedClearsPending(DisplacementController):
    """Clears what is pending before it looks at the new message."""

    def _on_reference(self, msg: JointJog) -> None:
        self.displacements = [math.nan] * len(self._joints)
        super()._on_reference(msg)


@wrong("newer_message_replaces_the_pending_one",
       rule="a newer message replaces a displacement not applied yet: displacements are not added up",
       idea="send two valid messages before one update: the joints move by the second only.",
       api="h.publish('~/reference', ...) twice, then h.update()",
       example="used_once")
class MessagesAddedUp(DisplacementController):
    """Adds a new message to what is still pending."""

    def _on_reference(self, msg: JointJog) -> None:
        before = self.displacements
        super()._on_reference(msg)
        if self.displacements is not before:  # taken: add what was pending
            self.displacements = [n + (0.0 if math.isnan(b) else b) for n, b in zip(self.displacements, before,
                                                                                     strict=True)]


@wrong("refusal_logged",
       rule="a refused message is refused with a reason in the log (a warning or an error), so its sender can find out "
            "why",
       idea="send a message that must be refused and look at what the controller logged while it took it.",
       api="pytest's caplog fixture: with caplog.at_level(logging.WARNING): h.publish(...); then caplog.records (each "
           "has .levelno and .getMessage())",
       example="unknown_joint_refused")
class RefusesSilently(DisplacementController):
    """Refuses the right messages, without a word."""

    def _reject(self, why: str) -> None:
        return


@wrong("slow_mode_set_not_flipped",
       rule="~/set_slow_control_mode sets the mode the request asks for (data=True slow, data=False fast), whatever "
            "the mode was: asking twice keeps it",
       idea="call the service with data=True twice (or data=False while fast), then send a displacement: the mode "
            "asked for counts.",
       api="h.bus.call_service(f'/{h.name}/set_slow_control_mode', SetBoolRequest(data=...)) returns the "
           "SetBoolResponse",
       example="slow_mode")
class SlowModeFlips(DisplacementController):
    """Each call flips the mode."""

    def _on_set_slow_mode(self, request: SetBoolRequest) -> SetBoolResponse:
        self.slow_mode = not self.slow_mode
        return SetBoolResponse(success=True, message="slow" if self.slow_mode else "fast")


@wrong("slow_mode_at_the_update_counts",
       rule="the mode at the update counts: slow mode switched on after a message arrived, before the update, halves "
            "it (and switched off, leaves it whole)",
       idea="send a displacement in fast mode, switch slow mode on, then update: the displacement is halved.",
       api="h.publish('~/reference', ...); h.bus.call_service(f'/{h.name}/set_slow_control_mode', "
           "SetBoolRequest(data=True)); h.update()",
       example="slow_mode")
class SlowModeAtArrival(DisplacementController):
    """Halves a displacement when it arrives in slow mode, not at the update."""

    def _on_reference(self, msg: JointJog) -> None:
        before = self.displacements
        super()._on_reference(msg)
        if self.displacements is not before and self.slow_mode:
            self.displacements = [d * 0.5 for d in self.displacements]

    def update(self, time: float, period: float) -> ReturnType:
        for i, displacement in enumerate(self.displacements):
            if not math.isnan(displacement):
                self.command_interfaces[i].set_value(self.state_interfaces[i].get_value() + displacement)
                self.displacements[i] = math.nan
        publish_state(self, time, period)
        return ReturnType.OK
