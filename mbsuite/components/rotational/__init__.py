"""Rotor systems with friction elements, shared by the models that stand on them (the drives, the Modelica Rotational
examples); it names no model. Laid out like `Modelica.Mechanics.Rotational` (Modelica Standard Library 4.1.0):

- `interfaces.py`: the `RotorSystem` (rotors, springs, torque sources, friction elements with the modes of
  `Interfaces.PartialFriction`) and the `RefResult` of a run;
- `components.py`: the MSL's Clutch, Brake, OneWayClutch, IdealPlanetary, IdealGear and
  QuadraticSpeedDependentTorque as elements, rows and sources of a rotor system;
- `commands.py`: the discrete controller protocol and the command queue (actuation delays in samples);
- `energy.py`: the energy balance of a run;
- the hand path: `event_exact.py` (event-exact stick/slip between DOP853 steps), `projection.py` (the stuck groups'
  momentum-conserving projection), `velocity_band.py` (the locking band scheme, for comparison);
- the MuJoCo path: `mujoco_sim.py` (`MujocoRotorSim`, the MJCF conventions), `rotor_run.py` (what a run packs),
  `native_stepper.py` with `native/rotors.c` (the state machine as the native core's stepper) and `stepper.py` (its
  readable Python twin).
"""
