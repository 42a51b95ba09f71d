"""SVG diagrams of a running system: controller chains, the ros2_control architecture, lifecycle states.

* :func:`controller_chains` draws what ``ros2 control view_controller_chains`` draws: hardware state
  interfaces on the left, controllers in chain order (preceding controllers first), hardware command
  interfaces on the right, and an arrow for every interface a controller writes or reads. Solid arrows
  are claims an active controller holds; an inactive controller's required command interfaces (what it
  would claim once activated) are grey and dashed.
* :func:`architecture` draws the controller manager with its controllers above the resource manager
  with its hardware components and their interfaces, linked by the claims between them.
* :func:`lifecycle_states` places every controller and hardware component in its lifecycle state.

Each returns an :class:`~rrbot_workshop.viz.svg.SvgDiagram` (shown inline by Jupyter, ``.save(path)``).
The input is the system's introspection answers (``list_controllers``, ``list_hardware_components``,
``list_hardware_interfaces``), so the pictures show what a learner can query. One exception: for an
active controller of a running system, the state interfaces drawn are those it holds on loan
(``controller.state_interfaces``, as a learner can also look up). ``list_controllers`` reports an
active controller whose state interface configuration is ALL (``joint_state_broadcaster``) as requiring
every state interface available *now*, including state interfaces that chainable controllers exported
after it was activated and that it never received; ros2_control's own service does the same.
"""

from __future__ import annotations

from rrbot_workshop.viz.architecture_diagram import architecture
from rrbot_workshop.viz.chains_diagram import chain_ranks, controller_chains
from rrbot_workshop.viz.lifecycle_diagram import lifecycle_states

__all__ = ["controller_chains", "architecture", "lifecycle_states", "chain_ranks"]
