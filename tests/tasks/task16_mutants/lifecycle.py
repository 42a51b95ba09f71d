"""Wrong controllers that break a rule of activation, deactivation and activating again."""

from __future__ import annotations

import math

from task16_public_mutants import wrong

from rrbot_workshop.controllers.displacement import DisplacementController
from rrbot_workshop.middleware.lifecycle import CallbackReturn, State


@wrong("activation_forgets_earlier_messages",
       rule="a displacement received while the controller was inactive, or left pending when it was deactivated, is "
            "not applied after the next activation",
       idea="send a displacement after configure but before activate, then activate and update: nothing moves.",
       api="h.configure(); h.publish('~/reference', ...); h.activate(); h.update()",
       example="nan_on_deactivate")
class PendingKeptAcrossActivation(DisplacementController):
    """Keeps what was pending through an activation."""

    def on_activate(self, previous_state: State) -> CallbackReturn:
        return CallbackReturn.SUCCESS


@wrong("nan_on_every_command",
       rule="deactivation writes NaN on every command interface of the controller, not only the first",
       idea="deactivate a controller of three joints and look at each command interface.",
       api="make_harness(controller_class, joints=['a', 'b', 'c']); h.deactivate(); math.isnan on each of "
           "h.values([...])",
       example="used_once")
class NanOnTheFirstOnly(DisplacementController):
    """Writes NaN on the first command interface only."""

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        if self.command_interfaces:
            self.command_interfaces[0].set_value(math.nan)
        return CallbackReturn.SUCCESS


@wrong("works_after_reactivation",
       rule="a controller deactivated and activated again works as before: a message moves the joints",
       idea="activate, deactivate, activate again, then send a displacement and update.",
       api="h.activate(); h.deactivate(); h.activate(); then h.publish('~/reference', ...) and h.update()",
       example="nan_on_deactivate")
class ReactivationDeaf(DisplacementController):
    """Drops its subscription on deactivation and never makes it again."""

    def on_deactivate(self, previous_state: State) -> CallbackReturn:
        result = super().on_deactivate(previous_state)
        if self._sub is not None:
            self._sub.destroy()
            self._sub = None
        return result
