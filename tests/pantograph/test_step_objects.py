"""The reference path's integrator is a step object (`mbsuite.stepping.StepObject`) and stepping it segment by
segment gives the same solution as `simulate`."""

import numpy as np

from mbsuite.models.pantograph.equations import PantographODE
from mbsuite.models.pantograph.inputs import InputSignal
from mbsuite.models.pantograph.reference import EventExactIntegrator, simulate
from mbsuite.stepping import StepObject


def test_event_exact_integrator_is_a_step_object():
    ode = PantographODE()
    u = InputSignal("sine", ode.p.y_op, 1.85e-3, 2.0)
    x0 = ode.equilibrium(u(0.0))
    sim = EventExactIntegrator(ode, u, 0.5, x0, max_step=1.0 / 32.0)
    assert isinstance(sim, StepObject)
    assert sim.status == "running" and sim.t == 0.0
    sim.step()
    assert 0.0 < sim.t <= 0.5  # one smooth segment: to the first stick/slip event or the end
    sim.run(0.5)
    assert sim.status == "finished" and sim.t == 0.5
    ref = simulate(ode, u, 0.5, x0, max_step=1.0 / 32.0)
    sol = sim.solution()
    assert np.array_equal(sol.t, ref.t) and np.array_equal(sol.x, ref.x) and sol.events == ref.events
    assert sol.nsegments == ref.nsegments > 1  # the head joint sticks within the first half second
