"""Model components that more than one model stands on, naming no model (like the Modelica Standard Library's
`Components` and `Interfaces`): a model imports them; they import no model.

- `rotational/`: rotor systems with friction elements (clutches, brakes, one-way clutches, gears), their event-exact
  hand path and their MuJoCo path with its native stepper (the drives and the Modelica Rotational examples);
- `linear_pantograph.py`: linear pantographs as one state-space model of the head (lumped chains, transfer
  functions), fitted by the pantograph model and run under the wire by the catenary.
"""
