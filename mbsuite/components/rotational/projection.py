"""The projection of a set of stuck friction elements: accelerations on the constraint subspace, the plastic-impact
velocity projection and the capacity-weighted constraint torques (both hand-path solvers)."""

from __future__ import annotations

import numpy as np

from .interfaces import RotorSystem


class StuckProjection:
    """Precomputed projection for one set of stuck elements."""

    def __init__(self, sys: RotorSystem, stuck: list[int], caps: np.ndarray):
        n = sys.n
        Minv = np.diag(1.0 / sys.J)
        self.stuck = stuck
        if stuck:
            G = sys.G(stuck)
            S = G @ Minv @ G.T
            Sp = np.linalg.pinv(S, rcond=1e-12)
            self.Pa = Minv - Minv @ G.T @ Sp @ G @ Minv
            self.Pw = np.eye(n) - Minv @ G.T @ Sp @ G  # plastic-impact velocity projection
            W = np.diag(np.maximum(caps, 1e-300) ** 2)
            R = np.eye(n) - np.diag(sys.J) @ self.Pa  # f -> constraint torque resultant r = f - M a
            self.L = W @ G @ np.linalg.pinv(G.T @ W @ G, rcond=1e-12) @ R
        else:
            self.Pa = Minv
            self.Pw = np.eye(n)
            self.L = np.zeros((0, n))

    def lam(self, f: np.ndarray) -> np.ndarray:
        """Constraint torques of the stuck elements for the generalised forces f."""
        return self.L @ f

