"""rw.tuning: a joint's model from the URDF, the PID closed loop at the controller's period, step figures."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rrbot_workshop as rw
from rrbot_workshop import tuning

_PENDULUM = """<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base"/>
  <link name="arm">
    <inertial>
      <origin xyz="0 0 -0.5" rpy="0 0 0"/>
      <mass value="2.0"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.01"/>
    </inertial>
  </link>
  <joint name="swing" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/>
    <dynamics damping="0.3"/>
  </joint>
</robot>
"""


def test_inertia_is_the_link_inertia_plus_its_mass_at_the_lever() -> None:
    """Hanging pendulum: J = iyy + m l^2 = 0.1 + 2 * 0.25; damping from <dynamics>; gravity pulls it back (k = m g l)."""
    plant = tuning.joint_plant(_PENDULUM, "swing")
    assert plant.inertia == pytest.approx(0.6)
    assert plant.damping == pytest.approx(0.3)
    assert plant.gravity_stiffness == pytest.approx(2.0 * 9.81 * 0.5, rel=1e-4)
    assert plant.gravity_torque == pytest.approx(0.0, abs=1e-9)


def test_horizontal_pendulum_holds_its_weight_and_has_no_stiffness() -> None:
    """At 90 degrees the arm is horizontal: the joint holds m g l and gravity's stiffness vanishes."""
    plant = tuning.joint_plant(_PENDULUM, "swing", {"swing": math.pi / 2})
    assert abs(plant.gravity_torque) == pytest.approx(2.0 * 9.81 * 0.5, rel=1e-6)
    assert plant.gravity_stiffness == pytest.approx(0.0, abs=1e-3)


def test_rrbot_joint1_carries_both_links() -> None:
    """RRBot's joint1 (vertical axis) moves link1 and link2: no gravity term, inertia from both links."""
    urdf = rw.description.process_xacro(rw.description.descriptions_root() / "rrbot/urdf/rrbot.urdf.xacro")
    plant = tuning.joint_plant(urdf, "joint1")
    assert plant.gravity_stiffness == 0.0 and plant.gravity_torque == 0.0
    assert 0.05 < plant.inertia < 0.5


def test_transfer_function_has_the_plant_coefficients() -> None:
    plant = tuning.JointPlant("j", inertia=2.0, damping=0.5, gravity_stiffness=3.0, gravity_torque=0.0)
    tf = plant.transfer_function()
    assert np.allclose(tf.num[0][0], [1.0]) and np.allclose(tf.den[0][0], [2.0, 0.5, 3.0])


def test_integral_action_removes_the_steady_state_error() -> None:
    """With i > 0 the loop reaches the step exactly; P alone on a plant with gravity stiffness leaves an offset."""
    plant = tuning.JointPlant("j", inertia=0.1, damping=0.1, gravity_stiffness=5.0, gravity_torque=0.0)
    with_i = tuning.predict_step(plant, tuning.PidGains(50.0, 100.0, 2.0), period=0.01, step=0.5, duration=10.0)
    p_only = tuning.predict_step(plant, tuning.PidGains(50.0, 0.0, 2.0), period=0.01, step=0.5, duration=10.0)
    assert abs(with_i.steady_state_error) < 1e-4
    assert p_only.steady_state_error == pytest.approx(0.5 * 5.0 / 55.0, rel=1e-3)


def test_prediction_matches_the_simulated_pid() -> None:
    """The model of RRBot's joint1 predicts MuJoCo's step response under pid_controller within a few mrad."""
    from rrbot_workshop.msgs import MultiDOFCommand

    urdf = rw.description.process_xacro(rw.description.descriptions_root() / "rrbot/urdf/rrbot.urdf.xacro", sim_mujoco=True)
    system = rw.bringup("rrbot", "rrbot_sim_effort_controllers.yaml", xacro_args={"sim_mujoco": True},
                        spawn=["joint_state_broadcaster", "pid_controller_joint1", "pid_controller_joint2"])
    try:
        for j in ("joint1", "joint2"):
            system.publish(f"/pid_controller_{j}/reference", MultiDOFCommand(dof_names=[j], values=[0.0], values_dot=[0.0]))
        system.spin(seconds=1.0)
        measured = tuning.measure_step(system, "pid_controller_joint1", 0.5, duration=1.0)
    finally:
        system.shutdown()
    predicted = tuning.predict_step(tuning.joint_plant(urdf, "joint1"), tuning.PidGains(100.0, 50.0, 10.0),
                                    period=0.01, step=0.5, duration=1.0)
    assert np.abs(predicted.position - measured.position).max() < 0.01
    assert measured.overshoot == pytest.approx(predicted.overshoot, abs=1.0)


def test_step_metrics_of_a_known_series() -> None:
    t = np.arange(6) * 0.1
    y = [0.0, 0.6, 1.1, 1.05, 1.0, 1.0]
    r = tuning.step_metrics(t, y, 0.0, 1.0)
    assert r.overshoot == pytest.approx(10.0)
    assert r.settling_time == pytest.approx(0.4)
    assert r.steady_state_error == 0.0


def test_a_response_that_never_settles_has_infinite_settling_time() -> None:
    assert tuning.step_metrics([0, 1, 2], [0.0, 0.5, 0.7], 0.0, 1.0).settling_time == math.inf


@pytest.mark.parametrize(("call", "match"), [
    (lambda: tuning.joint_plant(_PENDULUM, "elbow"), "no joint 'elbow'"),
    (lambda: tuning.joint_plant(_PENDULUM, "swing", {"elbow": 0.0}), "unknown joints"),
    (lambda: tuning.joint_plant("<robot", "swing"), "cannot be read"),
])
def test_bad_description_input_names_the_problem(call: object, match: str) -> None:
    with pytest.raises(rw.DescriptionError, match=match):
        call()  # type: ignore[operator]


def test_bad_numbers_are_refused() -> None:
    plant = tuning.JointPlant("j", 1.0, 0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="period"):
        tuning.closed_loop(plant, tuning.PidGains(1.0), period=0.0)
    with pytest.raises(ValueError, match="step is zero"):
        tuning.step_metrics([0.0, 1.0], [0.0, 0.0], 0.3, 0.3)
    with pytest.raises(ValueError, match="same length"):
        tuning.step_metrics([0.0, 1.0], [0.0], 0.0, 1.0)
