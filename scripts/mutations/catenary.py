"""Seeded defects in the FE catenary (EN 50318): assembly, contact, passage bookkeeping, quality."""

from mutations.mutation import Mutation

MUTATIONS: tuple[Mutation, ...] = (
    Mutation("catenary_droppers_bilateral", "mbsuite/models/catenary/sim.py",
             "        self.slack = dropper_law == \"slack\"", "        self.slack = False",
             "droppers made bilateral (they push as well as pull) in the slack-dropper scenes", "tests/catenary"),
)
