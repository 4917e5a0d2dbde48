"""Every figure a sensitivity study reports (`mbsuite.analysis.sensitivity`, `mbsuite sensitivity`) against a case
computed by hand in the test: Morris mu*, mu, sigma, the confidence half-width of mu* and the ranking of a function
whose elementary effects are known in closed form (linear terms and one interaction); Sobol S1, ST and their
confidence intervals of a function whose variance decomposition is known (two linear terms, their product, a dummy);
the ranked table the study prints, `sensitivity.csv`, `evaluations.csv` and `summary.json` equal to the returned
object and to the hand numbers. The command line runs on the catenary scene with its passage replaced by an analytic
evaluator (`designspace.scene_outputs` monkeypatched: the study's arithmetic is what is checked, not the passage)."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from mbsuite.analysis import designspace, sensitivity
from mbsuite.analysis.designspace import Factor
from mbsuite.analysis.sweep import SweepOptions
from mbsuite.cli import main

Z95, Z90 = 1.959963984540054, 1.6448536269514722  # standard normal quantiles of 0.975 and 0.95

# --------------------------------------------------------------------------------------------------------- Morris

MORRIS_FACTORS = [Factor("x", "a", 0.0, 2.0), Factor("x", "b", 1.0, 3.0), Factor("x", "c", -1.0, 1.0),
                  Factor("x", "d", 0.0, 10.0)]


def screening(point):
    """y = 5 a + 1.5 a (b - 1) + 0.5 b - 10 c (+ 0 d)."""
    a, b, c = point["x.a"], point["x.b"], point["x.c"]
    return {"y": 5.0 * a + 1.5 * a * (b - 1.0) + 0.5 * b - 10.0 * c + 0.0 * point["x.d"]}


def hand_effects(samples: np.ndarray, factors, levels: int) -> list[list[float]]:
    """The elementary effects of `screening` in closed form: y is linear in each factor alone, so the effect of a step
    in factor j (a change of the output over the factor's whole range, per unit of the normalised step) is
    (hi - lo) dy/dx_j at the other factors' values of that step: a: 2 (5 + 1.5 (b - 1)), b: 2 (0.5 + 1.5 a), c:
    2 (-10), d: 0. Also checks the sample is Morris' (one factor moves per step, by levels / (2 (levels - 1)) of its
    range)."""
    k = len(factors)
    step = levels / (2.0 * (levels - 1))
    ranges = np.array([f.hi - f.lo for f in factors])
    traj = samples.reshape(-1, k + 1, k)
    ee: list[list[float]] = [[] for _ in range(k)]
    for t in traj:
        for x0, x1 in zip(t[:-1], t[1:], strict=True):
            moved = np.flatnonzero(x1 != x0)
            assert moved.size == 1, "a Morris step moves one factor"
            j = int(moved[0])
            assert abs(x1[j] - x0[j]) / ranges[j] == pytest.approx(step, rel=1e-12)
            a, b = x0[0], x0[1]
            slope = (5.0 + 1.5 * (b - 1.0), 0.5 + 1.5 * a, -10.0, 0.0)[j]
            ee[j].append(ranges[j] * slope)
    return ee


def test_morris_effects_and_ranking_equal_the_closed_form():
    """Hand case: the elementary effects of `screening` (`hand_effects`) at the study's own trajectories. Their sets
    are known: a: 2 (5 + 1.5 (b - 1)) with b on the 4-level grid {1, 5/3, 7/3, 3}, i.e. {10, 12, 14, 16}; b: 2 (0.5 +
    1.5 a), a in {0, 2/3, 4/3, 2}, i.e. {1, 3, 5, 7}; c: -20; d: 0. mu = mean, mu* = mean |.|, sigma = the sample
    standard deviation (ddof 1, SALib's definition). Ranking by mu*: c (20) > a (10..16) > b (1..7) > d (0), whatever
    the sample. Tolerance 1e-9 relative: the effects are exact up to round-off of sums of a few dozen numbers.
    mu*'s half-width: the bootstrap standard deviation of a mean of r values is the population standard deviation
    (ddof 0) / sqrt(r), times z(0.975); 10 % relative: SALib draws 1000 resamples, whose standard deviation has a
    relative standard error 1/sqrt(2 x 999) = 2.2 %. c and d: every effect equal, half-width exactly 0."""
    n, levels = 20, 4
    res = sensitivity.run(screening, MORRIS_FACTORS, method="morris", n=n, seed=7, levels=levels, workers=1,
                          progress=False)
    assert res.samples.shape == (n * 5, 4) and len(res.evaluations) == n * 5
    ee = hand_effects(res.samples, MORRIS_FACTORS, levels)
    assert all(len(e) == n for e in ee)
    assert set(np.round(ee[0], 9)) <= {10.0, 12.0, 14.0, 16.0} and set(np.round(ee[1], 9)) <= {1.0, 3.0, 5.0, 7.0}
    assert len(set(np.round(ee[0], 9))) > 1 and len(set(np.round(ee[1], 9))) > 1  # the interaction is sampled
    ind = res.indices["y"]
    for j in range(4):
        e = np.array(ee[j])
        assert ind["mu"][j] == pytest.approx(e.mean(), rel=1e-9, abs=1e-12)
        assert ind["mu_star"][j] == pytest.approx(np.abs(e).mean(), rel=1e-9, abs=1e-12)
        assert ind["sigma"][j] == pytest.approx(e.std(ddof=1), rel=1e-9, abs=1e-12)
        assert ind["mu_star_conf"][j] == pytest.approx(Z95 * np.abs(e).std(ddof=0) / math.sqrt(n), rel=0.10,
                                                       abs=1e-12)
    assert ind["mu"][2] == pytest.approx(-20.0) and ind["mu_star"][2] == pytest.approx(20.0)
    assert ind["sigma"][2] == pytest.approx(0.0, abs=1e-12) and ind["mu_star_conf"][2] == pytest.approx(0, abs=1e-12)
    assert ind["mu_star"][3] == 0.0 and ind["mu_star_conf"][3] == 0.0
    assert [r["factor"] for r in res.ranking("y")] == ["x.c", "x.a", "x.b", "x.d"]


def test_morris_half_width_scales_with_the_confidence_level():
    """Hand case: the same seeded bootstrap at another confidence level is the same resampled mu* spread times
    another normal quantile, so the 90 % half-width is z(0.95) / z(0.975) = 0.83923 of the 95 % one (1e-12: the
    resamples are identical, only the quantile changes); mu*, mu, sigma do not depend on it."""
    kw = dict(method="morris", n=12, seed=3, workers=1, progress=False)
    r95 = sensitivity.run(screening, MORRIS_FACTORS, conf_level=0.95, **kw)
    r90 = sensitivity.run(screening, MORRIS_FACTORS, conf_level=0.90, **kw)
    for j in range(2):  # a and b: effects that differ, a half-width above 0
        assert r90.indices["y"]["mu_star_conf"][j] == pytest.approx(
            r95.indices["y"]["mu_star_conf"][j] * Z90 / Z95, rel=1e-12)
    for name in ("mu", "mu_star", "sigma"):
        assert r90.indices["y"][name] == r95.indices["y"][name]


def _table_blocks(text: str) -> dict[str, list[list[str]]]:
    """The rows of each output's block of a printed sensitivity table: {output: [[rank, factor, ...], ...]}."""
    blocks = {}
    for block in text.split("\n\n")[1:]:
        lines = block.splitlines()
        blocks[lines[0].split(" [")[0]] = [ln.split() for ln in lines[3:]]
    return blocks


def test_morris_table_csv_and_json_equal_the_hand_numbers(tmp_path):
    """The printed table (rank, factor, mu*, +-, mu, sigma at 4 significant digits), `sensitivity.csv` (one row per
    output and factor, ranked, every index), `evaluations.csv` (the points and y) and `summary.json` (indices,
    ranking) give the numbers of the returned object (CSV and JSON: exactly, they are written with repr) and of the
    hand case (`hand_effects`; the table to its 4 digits, 5e-4 relative)."""
    res = sensitivity.run(screening, MORRIS_FACTORS, method="morris", n=10, seed=11, workers=1, progress=False)
    ee = hand_effects(res.samples, MORRIS_FACTORS, 4)
    labels = [f.label for f in MORRIS_FACTORS]
    hand = {labels[j]: {"mu_star": float(np.mean(np.abs(ee[j]))), "mu": float(np.mean(ee[j])),
                        "sigma": float(np.std(ee[j], ddof=1))} for j in range(4)}
    order = ["x.c", "x.a", "x.b", "x.d"]
    rows = _table_blocks(res.table())["y"]
    assert [r[1] for r in rows] == order and [r[0] for r in rows] == ["1", "2", "3", "4"]
    for r in rows:
        h = hand[r[1]]
        for col, name in ((2, "mu_star"), (4, "mu"), (5, "sigma")):
            assert float(r[col]) == pytest.approx(h[name], rel=5e-4, abs=1e-9), (r, name)
    files = res.report().save(tmp_path, None)
    assert {p.name for p in files} >= {"sensitivity.csv", "evaluations.csv", "sensitivity.png", "summary.json"}
    with (tmp_path / "sensitivity.csv").open() as fh:
        table = list(csv.DictReader(fh))
    assert [r["factor"] for r in table] == order and [int(r["rank"]) for r in table] == [1, 2, 3, 4]
    for r in table:
        j = labels.index(r["factor"])
        for name in ("mu", "mu_star", "sigma", "mu_star_conf"):
            assert float(r[name]) == res.indices["y"][name][j]
        for name in ("mu", "mu_star", "sigma"):
            assert float(r[name]) == pytest.approx(hand[r["factor"]][name], rel=1e-9, abs=1e-12)
    with (tmp_path / "evaluations.csv").open() as fh:
        ev = list(csv.DictReader(fh))
    assert len(ev) == len(res.samples)
    for row, x in zip(ev, res.samples, strict=True):
        assert [float(row[k]) for k in labels] == list(x)
        a, b, c, _ = x
        assert float(row["y"]) == pytest.approx(5 * a + 1.5 * a * (b - 1) + 0.5 * b - 10 * c, rel=1e-12, abs=1e-12)
    data = json.loads((tmp_path / "summary.json").read_text())["results"]
    assert data["indices"] == res.indices and data["evaluations_count"] == 50
    assert [r["factor"] for r in data["ranking"]["y"]] == order
    for r in data["ranking"]["y"]:
        assert r["mu_star"] == pytest.approx(hand[r["factor"]]["mu_star"], rel=1e-9, abs=1e-12)


# ---------------------------------------------------------------------------------------------------------- Sobol

SOBOL_FACTORS = [Factor("x", "x1", 1.0, 3.0), Factor("x", "x2", -1.0, 1.0), Factor("x", "x3", 0.0, 5.0)]
#: y = 4 u + 2 x2 + 3 u x2 with u = x1 - 2 and x2 uniform on [-1, 1] (variance 1/3 each, u x2: 1/9), x3 a dummy:
#: V1 = 16/3, V2 = 4/3, V12 = 1, V = 23/3
S1_HAND = [16 / 23, 4 / 23, 0.0]
ST_HAND = [19 / 23, 7 / 23, 0.0]


def interaction(point):
    """y = 4 (x1 - 2) + 2 x2 + 3 (x1 - 2) x2 (+ 0 x3)."""
    u, x2 = point["x.x1"] - 2.0, point["x.x2"]
    return {"y": 4.0 * u + 2.0 * x2 + 3.0 * u * x2 + 0.0 * point["x.x3"]}


def test_sobol_closed_form_of_the_hand_function():
    """The closed form above, checked by quadrature (a 2001-point midpoint grid on the two live factors: variance
    of the conditional means and of the whole, to 1e-5) so that the hand case is not only algebra."""
    m = 2001
    u = (np.arange(m) + 0.5) / m * 2.0 - 1.0  # midpoints of [-1, 1], for x1 - 2 and for x2
    y = 4 * u[:, None] + 2 * u[None, :] + 3 * u[:, None] * u[None, :]
    v = y.var()
    assert [y.mean(axis=1).var() / v, y.mean(axis=0).var() / v] == pytest.approx(S1_HAND[:2], abs=1e-5)
    assert [1 - y.mean(axis=0).var() / v, 1 - y.mean(axis=1).var() / v] == pytest.approx(ST_HAND[:2], abs=1e-5)


def test_sobol_indices_and_their_intervals_contain_the_closed_form():
    """Hand case: S1 = 16/23, 4/23, 0 and ST = 19/23, 7/23, 0 (the interaction's share 3/23 = ST - S1 of both live
    factors). At n = 1024 (5120 runs) each reported 95 % interval S +- half-width contains the analytic value (over
    seeds 0-9 at n = 256 and 1024 all 40 intervals of the live factors did); the dummy x3 has S1 = ST = 0 and zero
    half-widths exactly (f(A) = f(AB) on every row). Ranking by ST: x1, x2, x3."""
    res = sensitivity.run(interaction, SOBOL_FACTORS, method="sobol", n=1024, seed=1, workers=1, progress=False,
                          options=SweepOptions(max_points=6000))
    assert len(res.evaluations) == 1024 * (3 + 2)
    ind = res.indices["y"]
    for name, hand in (("S1", S1_HAND), ("ST", ST_HAND)):
        for j in range(2):
            assert abs(ind[name][j] - hand[j]) <= ind[f"{name}_conf"][j], (name, j, ind[name][j], hand[j])
            assert ind[f"{name}_conf"][j] < 0.1  # an interval that says something
        assert ind[name][2] == 0.0 and ind[f"{name}_conf"][2] == 0.0
    for j in range(2):
        gap, width = ind["ST"][j] - ind["S1"][j], ind["ST_conf"][j] + ind["S1_conf"][j]
        assert abs(gap - 3 / 23) <= width
    assert [r["factor"] for r in res.ranking("y")] == ["x.x1", "x.x2", "x.x3"]


def test_sobol_interval_shrinks_like_one_over_root_n():
    """Hand case: a bootstrap half-width of a Monte Carlo mean falls as 1/sqrt(n), so 16 times the base sample
    gives a quarter of the width. Tolerance 20 %: over seeds 0-7 the ratio of each live index's half-width at n = 256
    and 4096 lay in 3.63-4.45 (the bootstrap's own spread and the finite-sample correlation of the estimators)."""
    widths = {}
    for n in (128, 2048):
        res = sensitivity.run(interaction, SOBOL_FACTORS, method="sobol", n=n, seed=2, workers=1, progress=False,
                              options=SweepOptions(max_points=20000))
        ind = res.indices["y"]
        widths[n] = np.array([ind["S1_conf"][0], ind["S1_conf"][1], ind["ST_conf"][0], ind["ST_conf"][1]])
    assert widths[128] / widths[2048] == pytest.approx([4.0] * 4, rel=0.2)


@pytest.mark.slow
def test_sobol_interval_coverage_over_seeds():
    """Hand case as above: over 20 seeds at n = 256 the four 95 % intervals of the live factors contain the analytic
    values at least 72 times in 80 (90 %; were the intervals exact 95 % ones, the count would be binomial(80, 0.95)
    and fall below 72 with probability 1.8 %; measured: 80 of 80, SALib's bootstrap intervals are conservative here)."""
    hits = 0
    for seed in range(20):
        ind = sensitivity.run(interaction, SOBOL_FACTORS, method="sobol", n=256, seed=seed, workers=1,
                              progress=False).indices["y"]
        hits += sum(abs(ind[k][j] - h[j]) <= ind[f"{k}_conf"][j] for k, h in (("S1", S1_HAND), ("ST", ST_HAND))
                    for j in range(2))
    assert hits >= 72


def test_sobol_table_and_csv_equal_the_returned_indices(tmp_path):
    """The printed table (rank, factor, ST, +-, S1, +- at 4 significant digits, ranked by ST) and
    `sensitivity.csv` give the returned indices (CSV exactly), and those are the hand values within their intervals;
    `evaluations.csv` holds n (k + 2) rows, each y equal to the hand function at its point."""
    res = sensitivity.run(interaction, SOBOL_FACTORS, method="sobol", n=512, seed=4, workers=1, progress=False)
    ind = res.indices["y"]
    rows = _table_blocks(res.table())["y"]
    assert [r[1] for r in rows] == ["x.x1", "x.x2", "x.x3"]
    for r in rows:
        j = int(r[1][-1]) - 1
        assert [float(v) for v in r[2:6]] == pytest.approx(
            [ind["ST"][j], ind["ST_conf"][j], ind["S1"][j], ind["S1_conf"][j]], rel=5e-4, abs=1e-12)
        assert abs(float(r[2]) - ST_HAND[j]) <= float(r[3]) + 5e-4
    res.write(tmp_path)
    with (tmp_path / "sensitivity.csv").open() as fh:
        table = list(csv.DictReader(fh))
    assert [r["factor"] for r in table] == ["x.x1", "x.x2", "x.x3"]
    for r in table:
        j = int(r["factor"][-1]) - 1
        assert all(float(r[k]) == ind[k][j] for k in ("S1", "S1_conf", "ST", "ST_conf"))
    with (tmp_path / "evaluations.csv").open() as fh:
        ev = list(csv.DictReader(fh))
    assert len(ev) == 512 * 5
    for row in ev[::97]:
        u, x2 = float(row["x.x1"]) - 2, float(row["x.x2"])
        assert float(row["y"]) == pytest.approx(4 * u + 2 * x2 + 3 * u * x2, rel=1e-12, abs=1e-12)


# ----------------------------------------------------------------------------------- the command line, on a scene

def analytic_passage(scene_dict, point):
    """Stands in for a catenary passage (`designspace.scene_outputs`): Fm = F0 - 0.05 c2, sigma = 0.2 F0 + 0.15 c2,
    N (F0, c2 from the point, else the scene's declared defaults 120 N and 90 N s/m)."""
    params = scene_dict.get("params") or {}
    f0 = point.get("params.F0", params.get("F0", 120.0))
    c2 = point.get("params.c2", params.get("c2", 90.0))
    return {"Fm": f0 - 0.05 * c2, "sigma": 0.2 * f0 + 0.15 * c2}


def test_sensitivity_command_prints_and_writes_the_hand_ranking(tmp_path, capsys, monkeypatch):
    """`mbsuite sensitivity catenary/en50318 --vary params.F0=100:140 --vary params.c2=50:130 --method morris` with
    the analytic passage: linear outputs, so every effect is the coefficient times the range: Fm: F0 40 N, c2 -4 N;
    sigma: F0 8 N, c2 12 N (sigma 0, half-width 0). The two outputs rank the factors in opposite orders, and the
    printed table, `sensitivity.csv` and `summary.json` (and `--json`) say so with those numbers (1e-9: sums of equal
    effects)."""
    monkeypatch.setattr(designspace, "scene_outputs", analytic_passage)
    out = tmp_path / "sens"
    argv = ["sensitivity", "catenary/en50318", "--vary", "params.F0=100:140", "--vary", "params.c2=50:130",
            "--method", "morris", "--n", "5", "--seed", "2", "--workers", "1", "--out", str(out)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    hand = {"Fm": {"params.F0": 40.0, "params.c2": -4.0}, "sigma": {"params.F0": 8.0, "params.c2": 12.0}}
    order = {"Fm": ["params.F0", "params.c2"], "sigma": ["params.c2", "params.F0"]}
    blocks = _table_blocks(text.split("\nwrote ")[0])
    assert set(blocks) == {"Fm", "sigma"}
    for o, rows in blocks.items():
        assert [r[1] for r in rows] == order[o]
        for r in rows:
            mu = hand[o][r[1]]
            assert [float(v) for v in r[2:6]] == pytest.approx([abs(mu), 0.0, mu, 0.0], abs=1e-9)
    with (out / "sensitivity.csv").open() as fh:
        table = list(csv.DictReader(fh))
    assert [(r["output"], r["factor"]) for r in table] == [(o, f) for o in ("Fm", "sigma") for f in order[o]]
    for r in table:
        assert float(r["mu"]) == pytest.approx(hand[r["output"]][r["factor"]], abs=1e-9)
        assert float(r["mu_star"]) == pytest.approx(abs(hand[r["output"]][r["factor"]]), abs=1e-9)
        assert r["unit"] == "N"  # the unit of the row's mu*, mu, sigma: the output's
    # the units: of every index column in the table, of the factors (their declared keys) and outputs in the CSV
    assert text.split("\n\n")[1].splitlines()[1].split()[2:] == ["mu*", "[N]", "+-", "[N]", "mu", "[N]", "sigma",
                                                                 "[N]"]
    with (out / "evaluations.csv").open() as fh:
        assert next(csv.reader(fh)) == ["params.F0 [N]", "params.c2 [N s/m]", "Fm [N]", "sigma [N]"]
    data = json.loads((out / "summary.json").read_text())["results"]
    assert data["units"]["sigma"] == "N" and data["evaluations_count"] == 5 * 3
    for o in ("Fm", "sigma"):
        assert [r["factor"] for r in data["ranking"][o]] == order[o]
    for e in data["evaluations"]:
        assert e["outputs"] == analytic_passage({}, e["point"])
    assert main([*argv[:-2], "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ranking"] == data["ranking"]
