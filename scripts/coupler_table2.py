"""Eq (15), rank, condition numbers and free-motion screws of the single coupler vs the paper's Table 2.

    .venv/bin/python scripts/coupler_table2.py
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from mbsuite.models.coupler import analysis
from mbsuite.models.coupler.jacobian import EQ15, paper_eq15_layout, single_jacobian
from mbsuite.models.coupler.params import CouplerParams
from mbsuite.results import format_table


def main() -> None:
    np.set_printoptions(precision=4, suppress=True)
    for g in (math.radians(17.0), 0.297):
        J = single_jacobian(CouplerParams(gamma=g, e_y=0.0))
        diff = np.max(np.abs(paper_eq15_layout(J) - EQ15))
        print(f"gamma = {g:.5f}: max |J(paper layout) - Eq 15| = {diff:.2e}")
    rows, screws = [], []
    for ey in (0.0, 0.05, 0.1):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", analysis.SingularityWarning)
            d = analysis.jacobian_report(CouplerParams(e_y=ey)).data
        rows.append([ey, d["rank"], np.array2string(d["singular_values"], precision=5), d["cond"],
                     d["cond_closed_form"], analysis.TABLE2[ey][3]])
        for basis in ("principal_screws", "zero_pitch_screws", "svd_basis_screws"):
            for i, s in enumerate(d[basis] or []):
                screws.append([ey, basis.replace("_screws", ""), f"S{i + 1}", np.array2string(s["axis"], precision=4),
                               np.array2string(s["point"], precision=4), s["pitch"]])
        if "paper_basis_angle" in d:
            print(f"e_y = {ey}: Table 2's pitch +-{analysis.TABLE2[ey][2]} = zero-pitch pair turned by theta = "
                  f"{d['paper_basis_angle']:.4f} rad (axis distance d = {d['zero_pitch_axis_distance']:.4f})")
    print(format_table(["e_y", "rank", "singular values", "chi ours", "R cos2g/e_y", "chi paper"], rows, ".6g"))
    print(format_table(["e_y", "basis", "screw", "axis", "point", "pitch"], screws, ".4g"))


if __name__ == "__main__":
    main()
