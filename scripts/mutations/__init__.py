"""The seeded defects of `scripts/mutants.py`, one module per model and one for the layers below the models."""

from mutations import catenary, coupler, drives, iftomm, layers, pantograph
from mutations.mutation import Mutation

MUTATIONS: tuple[Mutation, ...] = (*coupler.MUTATIONS, *iftomm.MUTATIONS, *drives.MUTATIONS, *pantograph.MUTATIONS,
                                   *catenary.MUTATIONS, *layers.MUTATIONS)

__all__ = ["MUTATIONS", "Mutation"]
