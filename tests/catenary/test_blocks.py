"""The compiled core's block sweeps (native/catenary.c, build_blocks and block_solve) on nodes of any size: an SPD
block-tridiagonal matrix with nodes of 2 to 8 DOFs, pinned DOFs among them, solved by the core's factor against a
dense LAPACK solve (numpy) of the same matrix."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from mbsuite.models.catenary.native_core import NativeFactor


def _block_tridiagonal(sizes: list[int], rng: np.random.Generator, far: bool = False) -> tuple:
    """A random SPD matrix on the free DOFs of nodes of `sizes` (padded vector: node I at offset[I] ..), coupled to
    their neighbours only (`far`: also node 0 to node 2), strictly diagonally dominant; about one DOF in seven
    pinned (removed). Returns S (CSR on the free DOFs), the node offsets and the padded index of each free DOF."""
    offset = np.concatenate([[0], np.cumsum(sizes)])
    n = int(offset[-1])
    A = np.zeros((n, n))
    for i, s in enumerate(sizes):
        a, b = offset[i], offset[i + 1]
        A[a:b, a:b] = rng.standard_normal((s, s))
        if i + 1 < len(sizes):
            A[b:offset[i + 2], a:b] = rng.standard_normal((sizes[i + 1], s))
    if far:
        A[offset[2], offset[0]] = 0.7
    A = np.tril(A) + np.tril(A, -1).T
    A += np.diag(np.sum(np.abs(A), axis=1) + 1.0)
    keep = [offset[0], offset[2]] if far else []  # the far coupling's DOFs stay free
    free = np.union1d(rng.choice(n, size=n - n // 7, replace=False), keep).astype(int)
    return sp.csr_matrix(A[np.ix_(free, free)]), offset, free


#: stretches of every size (2, 4, 6, 8) with every change of size between them, and single nodes
SIZES = [4, 4, 4, 6, 6, 6, 6, 4, 2, 2, 2, 8, 8, 8, 6, 4, 4, 2, 6, 8, 4, 6, 2, 4, 4, 4, 4, 8, 2, 6, 6]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_block_sweeps_solve_a_matrix_with_nodes_of_mixed_sizes(seed):
    """Every node size of a line (2 to 8 DOFs: one to four wires) in runs and alone, pinned DOFs padded: the block
    form is used and equals the dense solve (measured <= 5.9e-16 of the solution's largest entry over seeds 1-7;
    bound 1e-14, 17x). A wrong block offset, a wrong neighbour size or a missed coupling is an O(1) error."""
    rng = np.random.default_rng(seed)
    S, offset, free = _block_tridiagonal(SIZES, rng)
    fac = NativeFactor(S, offset, free)
    assert fac.blocked
    b = rng.standard_normal((S.shape[0], 3))
    for k in range(3):
        x = fac.solve(b[:, k])
        ref = np.linalg.solve(S.toarray(), b[:, k])
        assert np.max(np.abs(x - ref)) < 1e-14 * np.max(np.abs(ref))


@pytest.mark.parametrize("case", ["large node", "beyond the neighbours"])
def test_band_sweeps_take_what_the_blocks_cannot(case):
    """A node of 10 DOFs (more than the core's blocks hold) or a coupling beyond the neighbouring node: the core keeps
    the band sweeps, which solve the same matrix (measured <= 3.7e-16 relative to the dense solve; bound 1e-14)."""
    rng = np.random.default_rng(4)
    sizes = [4, 10, 4, 6] if case == "large node" else [4, 2, 6, 4, 6]
    S, offset, free = _block_tridiagonal(sizes, rng, far=case != "large node")
    fac = NativeFactor(S, offset, free)
    assert not fac.blocked
    b = rng.standard_normal(S.shape[0])
    ref = np.linalg.solve(S.toarray(), b)
    assert np.max(np.abs(fac.solve(b) - ref)) < 1e-14 * np.max(np.abs(ref))
