"""The seeded defects of `scripts/mutants.py`, one module per model and one for the layers below the models."""

from mutations import catenary, coupler, drives, iftomm, layers, pantograph
from mutations.mutation import Mutation

GROUPS: dict[str, tuple[Mutation, ...]] = {
    "coupler": coupler.MUTATIONS, "iftomm": iftomm.MUTATIONS, "drives": drives.MUTATIONS,
    "pantograph": pantograph.MUTATIONS, "catenary": catenary.MUTATIONS, "layers below the models": layers.MUTATIONS}
MUTATIONS: tuple[Mutation, ...] = tuple(m for group in GROUPS.values() for m in group)

__all__ = ["GROUPS", "MUTATIONS", "Mutation"]
