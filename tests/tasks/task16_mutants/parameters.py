"""Wrong controllers that break a rule of parameters, configure and the interfaces claimed."""

from __future__ import annotations

from task16_public_mutants import wrong

from rrbot_workshop.controller_interface.base import InterfaceConfiguration, InterfaceConfigurationType
from rrbot_workshop.controllers.displacement import DisplacementController
from rrbot_workshop.middleware.lifecycle import CallbackReturn, State
from rrbot_workshop.msgs import JointControllerState, JointJog, SetBoolRequest

_ONE_OF = '      one_of<>: [["position", "velocity", "acceleration", "effort"]]\n'


@wrong("interface_name_is_one_of_four",
       rule="interface_name must be one of position, velocity, acceleration and effort: any other name is refused "
            "when the controller is loaded",
       idea="load the controller with an interface name that is none of the four (and does not start with blup_): "
            "loading must refuse it.",
       api="with pytest.raises(ParameterError): make_harness(controller_class, interface=...)",
       example="blup_refused")
class InterfaceNameUnchecked(DisplacementController):
    """The schema lost its one_of<> line: only the blup_ validator is left."""

    PARAMETERS = (DisplacementController.PARAMETERS or "").replace(_ONE_OF, "")


@wrong("state_joints_of_another_size_fail_configure",
       rule="state_joints of another size than joints (more or fewer) fails configure; the same size, or none, "
            "configures",
       idea="configure with more state joints than joints, and with fewer: the controller must stay unconfigured.",
       api="make_harness(controller_class, joints=[...], state_joints=[...], states=[...]); h.configure() is "
           "State.UNCONFIGURED",
       example="blup_refused")
class StateJointsSizeOneWay(DisplacementController):
    """Refuses fewer state joints than joints, but not more."""

    def on_configure(self, previous_state: State) -> CallbackReturn:
        params = self.param_listener.get_params()  # type: ignore[union-attr]
        self._joints = list(params.joints)
        self._state_joints = list(params.state_joints) or list(self._joints)
        if len(self._state_joints) < len(self._joints):
            self.logger.error("state_joints is shorter than joints")
            return CallbackReturn.FAILURE
        self._interface = params.interface_name
        self.displacements = [float("nan")] * len(self._joints)
        self.slow_mode = False
        node = self.get_node()
        self._sub = node.create_subscription(JointJog, "~/reference", self._on_reference)
        self._srv = node.create_service(SetBoolRequest, "~/set_slow_control_mode", self._on_set_slow_mode)
        self._pub = node.create_publisher(JointControllerState, "~/state")
        return CallbackReturn.SUCCESS


@wrong("state_joints_read",
       rule="when state_joints is given, the states are read from those joints (the commands still go to joints)",
       idea="give state_joints other names than joints and start them at other values: the command of each joint is "
            "its state joint's value plus the displacement.",
       api="make_harness(controller_class, joints=['j1', 'j2'], state_joints=['s1', 's2'], states=[...]); the "
           "harness then owns s1/position and s2/position as states; or read "
           "h.controller.state_interface_configuration().names after h.configure()",
       example="state_plus_displacement")
class StateJointsIgnored(DisplacementController):
    """Reads the states of the commanded joints, whatever state_joints says."""

    def state_interface_configuration(self) -> InterfaceConfiguration:
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL,
                                      [f"{joint}/{self._interface}" for joint in self._joints])


@wrong("claims_the_joints_it_is_given",
       rule="the controller claims <joint>/<interface_name> for the joints and the interface its parameters give, in "
            "their order (not the RRBot's joint1 and joint2 position)",
       idea="try joints with other names and another count, and another interface than position: the controller must "
            "claim exactly those, and move them.",
       api="make_harness(controller_class, joints=['shoulder', 'elbow', 'wrist'], interface='velocity'); after "
           "h.configure(), h.controller.command_interface_configuration().names",
       example="state_plus_displacement")
class RRBotJointsHardCoded(DisplacementController):
    """Claims the RRBot's position interfaces, whatever the parameters say."""

    def command_interface_configuration(self) -> InterfaceConfiguration:
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, ["joint1/position", "joint2/position"])

    def state_interface_configuration(self) -> InterfaceConfiguration:
        return InterfaceConfiguration(InterfaceConfigurationType.INDIVIDUAL, ["joint1/position", "joint2/position"])


@wrong("topics_follow_the_controller_name",
       rule="the controller's topics and service are its own (~/reference, ~/set_slow_control_mode, ~/state): they "
            "follow the name it is loaded under, whatever that name is",
       idea="load the controller under another name than the notebook's and talk to it there: a message on "
            "/<that name>/reference must move the joints.",
       api="make_harness(controller_class, name='arm_jog'); h.publish('~/reference', ...) expands ~ to /arm_jog; "
           "h.bus.subscription_count('/arm_jog/reference')",
       example="blup_refused")
class TopicsSpelledOut(DisplacementController):
    """The notebook's controller name written into the topic names."""

    def on_configure(self, previous_state: State) -> CallbackReturn:
        params = self.param_listener.get_params()  # type: ignore[union-attr]
        self._joints = list(params.joints)
        self._state_joints = list(params.state_joints) or list(self._joints)
        if len(self._state_joints) != len(self._joints):
            self.logger.error("state_joints and joints differ in size")
            return CallbackReturn.FAILURE
        self._interface = params.interface_name
        self.displacements = [float("nan")] * len(self._joints)
        self.slow_mode = False
        node = self.get_node()
        self._sub = node.create_subscription(JointJog, "/displacement_controller/reference", self._on_reference)
        self._srv = node.create_service(SetBoolRequest, "/displacement_controller/set_slow_control_mode",
                                        self._on_set_slow_mode)
        self._pub = node.create_publisher(JointControllerState, "/displacement_controller/state")
        return CallbackReturn.SUCCESS
