"""Can I trust this result: one package, one vocabulary.

- **estimate** (`estimate.py`): the estimated error of a headline output, from the run and refined (or coarser) copies
  of it, its observed order and the **tolerance** the model declares its defaults meet;
- **health figure** (`health.py`): a number a run reports about itself (an energy residual, a stability margin, a
  closure error) with its bound; `judge` turns a figure above its bound into an `AccuracyError` (or a warning when the
  scene allows inaccurate results);
- **perturbation** (`perturbation.py`): relative changes of 1e-12 ... 1e-9 drawn into every parameter, input and
  initial state while active; `robustness.py` runs scenes and hard cases under them and checks that their invariants
  hold and their headline outputs move by no more than the condition allows.

Nothing here names a model: a model declares its headline outputs, tolerances and health figures on its `SPEC`.
"""
