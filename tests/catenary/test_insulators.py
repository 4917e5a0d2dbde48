"""Section insulators (`line.SectionInsulator`: a mass spread over a length of a wire and the bending stiffness it
adds there) against hand solutions: the static sag of a string under its own and the insulator's weight, the weight
balance of the EN 50318 line, the modes of a wire stiffened over its whole length, the tabulated point-load defect
against a refined beam, the compiled core's defect and passage against the Python path's, the report's insulator
block recomputed from the run's records, bad input, and a line without insulators unchanged bit for bit."""

from __future__ import annotations

import copy
import dataclasses
import hashlib
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.signal import butter, sosfiltfilt

from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.catenary import lines, train
from mbsuite.models.catenary import point_correction as pcm
from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.config import PassageConfig
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.hermite_beam import beam_stiffness, hermite, tensioned_beam_compliance
from mbsuite.models.catenary.line import Line, SectionInsulator, Support, Wire
from mbsuite.models.catenary.linefile import EXAMPLE, line_from_dict
from mbsuite.models.catenary.native_core import NativeCore
from mbsuite.models.catenary.pantographs import TwoMassPantograph
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.reports import report, train_report
from mbsuite.models.catenary.sim import CoupledSimulation

#: the doc example's insulator (example values, not a standard's): 2.0 m, 12 kg, 2000 N m^2 on the contact wire
INS = {"length": 2.0, "mass": 12.0, "EI": 2000.0}
#: a 3-span EN 50318 line, 300 km/h runs over 0-140 m, the insulator at mid-span 2 (x = 90 m, on [89, 91] m)
P3 = CatenaryParams(n_spans=3, element_length=0.5, x_end=140.0, window_start=60.0, window_end=120.0)


def _p3_insulated() -> CatenaryParams:
    line = lines.with_insulators(lines.simple(P3), [SectionInsulator(90.0, "contact", **INS)])
    return dataclasses.replace(P3, line=line)


def _one_wire(L: float, mass: float, T: float, EI: float, insulators=()) -> Line:
    """A contact wire alone over [0, L], pinned at both ends (supports there only)."""
    return Line((Wire("contact", "contact", mass, T, EI, 0.0, L),), (Support(0.0), Support(L)),
                insulators=tuple(insulators))


def _params(line: Line, h: float = 0.5) -> CatenaryParams:
    L = line.length
    return CatenaryParams(line=line, element_length=h, x_end=L, window_start=0.25 * L, window_end=0.75 * L)


# --- (a) statics ----------------------------------------------------------------------------------------------------
def test_a_string_carries_the_insulators_weight_as_statics_predicts():
    """A string (EI = 0, T = 20 kN, 1.35 kg/m, 50 m pinned) with a 4 m, 12 kg insulator (mass only) centred at 20 m:
    T w'' = q(x) (the wire's weight plus 3 kg/m over [18, 22] m), w = 0 at the ends, whose solution is piecewise
    quadratic, in the Hermite space: the FE's static sag at every node equals the hand solution (Green's function of
    the string integrated in closed form) to rounding. Measured 2.5e-15 m of a 0.27 m sag; bound 1e-14 m."""
    L, T, rho, g = 50.0, 20000.0, 1.35, 9.81
    a, b, m = 18.0, 22.0, 12.0
    fe = assemble(_params(_one_wire(L, rho, T, 0.0, [SectionInsulator(20.0, "contact", 4.0, m, 0.0)])))
    x, w = fe.x, fe.w0_full[fe.slot[0]]
    q2 = m / (b - a) * g
    left = x / L * (L * (b - a) - (b * b - a * a) / 2)
    right = (L - x) / L * (b * b - a * a) / 2
    inside = (L - x) * (x * x - a * a) / (2 * L) + x * (L * (b - x) - (b * b - x * x) / 2) / L
    hand = -rho * g / (2 * T) * x * (L - x) - q2 / T * np.where(x <= a, left, np.where(x >= b, right, inside))
    assert np.max(np.abs(w - hand)) < 1e-14 and np.min(w) < -0.25


def test_droppers_and_steady_arms_carry_the_insulators_weight():
    """The EN 50318 line (600 m) with the insulator at 310 m: the dropper tensions plus the steady arms' pre-loads
    equal the contact wire's weight plus the insulator's (statics), and the insulator adds exactly its weight to
    them. Measured 3.4e-16, 3.7e-16 and 2.2e-15 relative; bound 1e-9 relative. The dropper inside it (310.5 m)
    and the next one (305 m) take 102 % of its weight (the neighbouring droppers and the steady arm give some back)."""
    p = CatenaryParams(element_length=0.5)
    ins = lines.with_insulators(lines.simple(p), [SectionInsulator(310.0, "contact", **INS)])
    f0, f1 = assemble(p), assemble(dataclasses.replace(p, line=ins))
    held0 = f0.T0.sum() + f0.support_preload.sum()
    held1 = f1.T0.sum() + f1.support_preload.sum()
    weight = p.cw_mass * p.g * p.length
    assert abs(held0 - weight) < 1e-9 * weight
    assert abs(held1 - (weight + INS["mass"] * p.g)) < 1e-9 * weight
    assert abs((held1 - held0) - INS["mass"] * p.g) < 1e-9 * INS["mass"] * p.g
    dT = f1.T0 - f0.T0
    near = np.argsort([abs(d.x - 310.0) for d in ins.droppers])[:2]
    assert 0.95 < dT[near].sum() / (INS["mass"] * p.g) < 1.05


# --- (b) modes ------------------------------------------------------------------------------------------------------
def test_a_full_length_insulator_is_a_heavier_stiffer_wire():
    """A pinned 60 m contact wire with an insulator over its whole length (m = 12 kg, EI 2000 N m^2) has the
    matrices of a wire of rho + m/L and EI + EI_add bit for bit, and its first modes are the closed form of the
    simply supported tensioned beam, f_n = n/(2L) sqrt(T/rho') sqrt(1 + EI' (n pi/L)^2 / T). Measured for n = 1..5:
    <= 1.6e-9 relative (n = 5; 3.0e-11 to 7.7e-11 for n = 1..3: the FE's discretisation, 0.5 m elements); bound
    5e-9."""
    L, T, rho, EI = 60.0, 20000.0, 1.35, 195.0
    line = _one_wire(L, rho, T, EI, [SectionInsulator(L / 2, "contact", L, INS["mass"], INS["EI"])])
    heavy = _one_wire(L, rho + INS["mass"] / L, T, EI + INS["EI"])
    a, b = assemble(_params(line)), assemble(_params(heavy))
    for k in ("M", "K0"):
        ma, mb = getattr(a, k), getattr(b, k)
        assert np.array_equal(ma.indptr, mb.indptr) and np.array_equal(ma.indices, mb.indices)
        assert np.array_equal(ma.data, mb.data), k
    lam = sla.eigh(a.K0.toarray(), a.M.toarray(), eigvals_only=True, subset_by_index=[0, 4])
    f_fe = np.sqrt(lam) / (2 * np.pi)
    n = np.arange(1, 6)
    rho2, EI2 = rho + INS["mass"] / L, EI + INS["EI"]
    f_cf = n / (2 * L) * np.sqrt(T / rho2) * np.sqrt(1 + EI2 * (n * np.pi / L) ** 2 / T)
    assert np.max(np.abs(f_fe / f_cf - 1)) < 5e-9


# --- (c) the tabulated point-load defect ----------------------------------------------------------------------------
def _hermite_Q(h: np.ndarray, e: int, T: float, EI: np.ndarray) -> np.ndarray:
    """The Hermite compliance of element e's DOFs on a pinned beam of elements h (EI each), assembled here."""
    n = 2 * (h.size + 1)
    K = np.zeros((n, n))
    for i, (hi, c) in enumerate(zip(h, EI, strict=True)):
        K[2 * i:2 * i + 4, 2 * i:2 * i + 4] += beam_stiffness(c, T, hi)
    for d in (0, n - 2):
        K[d, :] = K[:, d] = 0.0
        K[d, d] = 1.0
    rhs = np.zeros((n, 4))
    rhs[2 * e:2 * e + 4] = np.eye(4)
    rhs[[0, n - 2]] = 0.0
    return np.linalg.solve(K, rhs)[2 * e:2 * e + 4]


def test_the_refined_reference_beam_is_exact_where_the_closed_form_holds():
    """The refined reference beam (each element in `REFINE` = 24 Hermite sub-elements) of a uniform beam against the
    closed form `tensioned_beam_compliance` at every sub-node of its 17 elements of 0.5 m: the contact wire (EI 195),
    the insulated wire (2195) and the messenger (131.7 N m^2, 16 kN). Measured <= 5.4e-12 m/N, 1e-7 of
    the contact spring's compliance; bound 2e-11 m/N."""
    h = np.full(2 * pcm.REF_ELEMENTS + 1, 0.5)
    xi = np.arange(pcm.REFINE + 1) / pcm.REFINE
    for T, EI in ((20000.0, 195.0), (20000.0, 2195.0), (16000.0, 131.7)):
        for e in range(h.size):
            c = pcm.refined_compliance(h, e, T, np.full(h.size, EI), xi)
            ex = np.array([tensioned_beam_compliance(0.5 * (e + v), 0.5 * h.size, T, EI) for v in xi])
            assert np.max(np.abs(c - ex)) < 2e-11, (T, EI, e)


def test_the_tabulated_defect_interpolates_the_refined_beam():
    """The EN 50318 line with the insulator at 310 m: every entry whose reference beam holds an insulated element is
    tabulated (ref L < 0), the others keep the closed form, equal bit for bit to the line without the insulator's
    (same elements: its ends are nodes of that mesh). At the off-sample points xi = 1/24, 3/24, ..., 23/24 the
    interpolated defect against the refined reference (48 sub-elements here, the Hermite part assembled here):
    measured <= 1.5e-11 m/N (the 24 against 48 sub-elements' refinement 3.6e-12 included) of defects 2.3e-8 to
    5.7e-7 m/N (7 samples, a degree-6 fit, measured 2.0e-8 next to an insulator's end, hence 13); bound 5e-11 m/N."""
    p = CatenaryParams(element_length=0.5)
    ins = lines.with_insulators(lines.simple(p), [SectionInsulator(310.0, "contact", **INS)])
    f0, f1 = assemble(p), assemble(dataclasses.replace(p, line=ins))
    assert np.array_equal(f0.x, f1.x)
    pc, pc0 = f1.contact, f0.contact
    tab = pc.ref[pc.sig, 1] < 0
    EIe = ins.beam_properties(ins.contact, 0.5 * (f1.x[:-1] + f1.x[1:]))[0]
    m = pcm.REF_ELEMENTS
    stiff = np.nonzero(EIe != 195.0)[0]
    assert np.array_equal(stiff, np.arange(618, 622))
    assert np.array_equal(np.nonzero(tab)[0], np.arange(618 - m, 622 + m))
    xo = np.arange(1, 24, 2) / 24
    for e in np.nonzero(~tab)[0][::7]:  # untouched: the closed form bit for bit
        assert pc.defect(e, 0.37) == pc0.defect(e, 0.37)
    assert np.array_equal(pc.nodal()[:600], pc0.nodal()[:600])
    worst = 0.0
    for e in np.nonzero(tab)[0]:
        lo, hi = e - m, e + m + 1
        h = np.diff(f1.x)[lo:hi]
        ex = pcm.refined_compliance(h, m, 20000.0, EIe[lo:hi], xo, 48)
        Q = _hermite_Q(h, m, 20000.0, EIe[lo:hi])
        ref = np.array([ex[i] - hermite(v, h[m]) @ Q @ hermite(v, h[m]) for i, v in enumerate(xo)])
        got = np.array([pc.defect(e, v) for v in xo])
        worst = max(worst, float(np.max(np.abs(got - ref))))
        assert np.all(ref > 1e-8)
    assert worst < 5e-11


# --- (d) the compiled core against the Python path ------------------------------------------------------------------
def test_the_cores_defect_and_passage_equal_the_python_paths_with_an_insulator():
    """The compiled core's point_defect (through `NativeCore.place`) equals `PointCorrection.defect` bit for bit at
    2001 points over 80-100 m (1000 of them in tabulated entries), and a passage over 80-100 m at 300 km/h on the
    compiled core equals the readable Python path (measured force 2.0e-10 N of 0-263 N, heights and uplifts
    4.2e-15 m; the bounds of test_native.py, 3e-9 N and 5e-13 m)."""
    p = _p3_insulated()
    fe = assemble(p)
    pan = TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0)
    sim = CoupledSimulation(fe, pan, 300 / 3.6, 1e-4)
    core = NativeCore(sim, 1, np.array([0.0]), np.array([140.0]))
    core.present[0] = 1
    ntab = 0
    for xp in np.linspace(80.0, 100.0, 2001):
        core.place(0, xp)
        e = int(core.elem[0])
        xi = (xp - fe.x[e]) / (fe.x[e + 1] - fe.x[e])
        ntab += bool(fe.contact.ref[fe.contact.sig[e], 1] < 0)
        assert fe.contact_defect(e, xi) == core.cbc[0], xp
    assert ntab >= 900
    a = CoupledSimulation(fe, pan, 300 / 3.6, 1e-4).run(80.0, 100.0, native=False)
    b = CoupledSimulation(fe, TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0), 300 / 3.6,
                          1e-4).run(80.0, 100.0, native=True)
    assert b.stats["native"]
    assert np.max(np.abs(a.force - b.force)) < 3e-9
    for k in ("head", "wire", "uplift"):
        assert np.max(np.abs(getattr(a, k) - getattr(b, k))) < 5e-13, k


def test_the_compiled_loop_steps_a_train_over_an_insulator_as_the_stage_loop():
    """Two 2-mass pantographs 15 m apart over the insulator (70-110 m, 300 km/h): the compiled loop
    (`mbs_cat_run`) against the core's stages driven from Python (`stepwise`). Measured bit-equal (bound 1e-9 N and
    1e-12 m, the overlap's test); each pantograph's statistics carry its own insulator block, the train's table
    shows both (the trailing one loses the wire there: 27.8 % of its samples)."""
    p = dataclasses.replace(_p3_insulated(), x_start=70.0, x_end=110.0, window_start=80.0, window_end=100.0)
    cfg = PassageConfig(p, 300.0, 1e-4, ("reference2mass",) * 2, (15.0,), "slack", "unilateral", "reference", None)
    a, b = train.run_passage(cfg, stepwise=True), train.run_passage(cfg)
    assert b.timing["native_loop"] and not a.timing["native_loop"]
    for ra, rb in zip(a.results, b.results, strict=True):
        assert np.max(np.abs(ra.force - rb.force)) < 1e-9 and np.max(np.abs(ra.wire - rb.wire)) < 1e-12
    ins = [s["insulators"]["contact@90"] for s in b.stats]
    assert ins[0]["n_samples"] == ins[1]["n_samples"] > 200 and ins[1]["loss_pct"] > ins[0]["loss_pct"]
    table = train_report(b).table
    assert table.count("contact@90") == 2 and f"{ins[1]['Fm']:.2f}" in table


# --- (e) the report ---------------------------------------------------------------------------------------------------
def test_the_reports_insulator_block_is_the_runs_records_on_the_insulator():
    """A passage at 300 km/h (compiled loop) over the 3-span line with the insulator on [89, 91] m: the statistics'
    insulator block equals the force record restricted to the head on [89, 91] m, filtered here independently
    (4th-order Butterworth at 20 Hz, forwards and backwards); the report's table has the block and its JSON the
    numbers. Measured: Fm 136.82, max 161.52, min 91.44 N (filtered), raw 40.48-245.14 N, no loss, 121 samples;
    values equal to 1e-9 N (the filter's rounding)."""
    p = _p3_insulated()
    run = simulate(p, 300.0, 2e-4)
    r = run.result
    d = run.stats["insulators"]["contact@90"]
    on = (r.x >= 89.0) & (r.x <= 91.0)
    ff = sosfiltfilt(butter(4, 20.0, fs=1 / 2e-4, output="sos"), r.force)
    assert d["n_samples"] == on.sum() > 100 and d["x_range"] == [89.0, 91.0]
    for k, v in (("Fm", ff[on].mean()), ("max", ff[on].max()), ("min", ff[on].min()), ("raw_max", r.force[on].max()),
                 ("raw_min", r.force[on].min()), ("loss_pct", 100.0 * np.mean(r.force[on] <= 0.0))):
        assert abs(d[k] - v) < 1e-9, k
    assert d["n_losses"] == 0 and d["raw_min"] > 0
    rep = report(run)
    assert "insulators:" in rep.table and "contact@90" in rep.table and f"{d['Fm']:.2f}" in rep.table
    assert rep.data["runs"]["slack"]["insulators"]["contact@90"]["Fm"] == d["Fm"]
    # a line without insulators has no block
    assert "insulators" not in simulate(P3, 300.0, 2e-4).stats


# --- (f) bad input --------------------------------------------------------------------------------------------------
def test_bad_insulators_are_refused_naming_them():
    """Off its wire, overlapping another, a negative mass, no length, an unknown wire, a missing design quantity; in a
    line file an unknown key, a missing value and a bad value (the line file's SceneError, as its other tables)."""
    base = lines.simple(P3)
    with pytest.raises(ParameterError, match=r"insulator at x = 179.5 m .* lies off wire 'contact'"):
        lines.with_insulators(base, [SectionInsulator(179.5, "contact", **INS)])
    with pytest.raises(ParameterError, match=r"insulators at x = 90.0 m .* and x = 91.0 m .* overlap"):
        lines.with_insulators(base, [SectionInsulator(x, "contact", **INS) for x in (90.0, 91.0)])
    lines.with_insulators(base, [SectionInsulator(x, "contact", **INS) for x in (90.0, 92.0)])  # touching: fine
    with pytest.raises(ParameterError, match=r"insulator at x = 90.0 m mass = -1.0 is invalid; valid: \[0, "):
        SectionInsulator(90.0, "contact", 2.0, -1.0, 2000.0)
    with pytest.raises(ParameterError, match=r"insulator at x = 90.0 m length = 0.0 is invalid; valid: \(0, "):
        SectionInsulator(90.0, "contact", 0.0, 12.0, 2000.0)
    with pytest.raises(ParameterError, match="names wire 'dropper'"):
        lines.with_insulators(base, [SectionInsulator(90.0, "dropper", **INS)])
    with pytest.raises(TypeError):  # no defaults for its design quantities
        SectionInsulator(90.0, "contact", 2.0, 12.0)  # type: ignore[call-arg]
    for change, match in ((lambda r: r.update(colour=1), r"insulators\[0\]: unknown key\(s\) \['colour'\]"),
                          (lambda r: r.pop("EI"), r"insulators\[0\]: EI missing"),
                          (lambda r: r.update(mass=-1.0), r"mass = -1.0 in ex.toml insulators\[0\] is invalid")):
        d = copy.deepcopy(EXAMPLE)
        change(d["insulators"][0])
        with pytest.raises(SceneError, match=match):
            line_from_dict(d, Path("."), "ex.toml")
    assert line_from_dict(EXAMPLE, Path("."), "ex.toml").insulators == (SectionInsulator(70.0, "contact", **INS),)


# --- (g) a line without insulators ------------------------------------------------------------------------------------
def _digest(fe) -> str:
    h = hashlib.sha256()
    for m in (fe.M, fe.K0, fe.Kd):
        for a in (m.data, m.indices, m.indptr):
            h.update(np.ascontiguousarray(a).tobytes())
    for pc in fe.contacts:
        for a in (pc.sig, pc.Q, pc.ref, pc.Tk):
            h.update(np.ascontiguousarray(a).tobytes())
    h.update(fe.k_drop.tobytes())
    h.update(fe.x.tobytes())
    return h.hexdigest()


def test_a_line_without_insulators_is_unchanged_bit_for_bit():
    """The EN 50318 line's matrices, point-load tables and dropper stiffnesses as before insulators existed (the
    digest computed on commit 164a571), and an insulator of no mass and no stiffness whose ends are nodes changes
    nothing (the stiffened grouping and the tables' windows give the same numbers)."""
    p = CatenaryParams(element_length=0.5)
    f0 = assemble(p)
    assert _digest(f0) == "fe642f7bfdc7f5e8dba224005ed0ba64343df902fe130819deb76cdc3c756397"
    ins = lines.with_insulators(lines.simple(p), [SectionInsulator(310.0, "contact", 2.0, 0.0, 0.0)])
    assert _digest(assemble(dataclasses.replace(p, line=ins))) == _digest(f0)


def test_a_scenes_line_section_adds_insulators_to_a_route():
    """`[[line.insulators]]` (and `[[line.masses]]`) in a scene's `[line]` section join the line of any kind: the
    shipped route with its section insulator in B's middle span carries it on B's contact wire, its ends nodes of the
    mesh; a row naming no wire of the line, or with an unknown key, is a SceneError naming it."""
    from mbsuite.scenes import load_scene

    scene = load_scene("catenary/en50318_route_insulator")
    p = scene.build_params()
    assert p.line.insulators == (SectionInsulator(x=750.0, wire="contact_b", length=2.0, mass=8.0, EI=2000.0),)
    keys = p.line.key_points()
    assert np.any(np.isclose(keys, 749.0)) and np.any(np.isclose(keys, 751.0))
    line = dict(scene.sections["line"])
    row = {"x": 750.0, "wire": "contact_x", "length": 2.0, "mass": 8.0, "EI": 2000.0}
    with pytest.raises(SceneError, match="contact_x"):
        scene.replace(line={**line, "insulators": [row]}).build_params()
    with pytest.raises(SceneError, match="colour"):
        scene.replace(line={**line, "insulators": [{**row, "wire": "contact_b", "colour": 1}]})


def test_marks_and_a_partial_run_of_an_insulator():
    """The figures' marks hold each insulator on a contact wire by its extent (`marks.line_marks`), and the report
    says when the run starts or ends on an insulator (its numbers then cover the part run only)."""
    from mbsuite.models.catenary.marks import line_marks
    from mbsuite.scenes import load_scene

    p = load_scene("catenary/en50318_route_insulator").build_params()
    assert line_marks(p.line)["insulators"] == [(749.0, 751.0, "contact_b")]
    assert line_marks(p.line, (0.0, 700.0))["insulators"] == []
    from mbsuite.models.catenary.stats import insulator_statistics

    x = np.linspace(700.0, 750.0, 501)
    f = np.full_like(x, 100.0)
    st = insulator_statistics(x / 69.4, x, f, f, 1e-3, p)
    assert st["contact_b@750"]["whole"] is False and st["contact_b@750"]["n_samples"] == 11


def test_a_dropper_hung_upside_down_is_named():
    """One dropper of the simple line hung the wrong way round (the messenger from the contact wire): the static
    state cannot order the wires, and the error names that dropper and the others' direction."""
    p = CatenaryParams(n_spans=2, x_end=100.0, window_start=20.0, window_end=100.0)
    line = lines.simple(p)
    d = line.droppers[3]
    bad = dataclasses.replace(line, droppers=(*line.droppers[:3], dataclasses.replace(d, upper=d.lower, lower=d.upper),
                                              *line.droppers[4:]))
    with pytest.raises(ParameterError, match=rf"dropper\(s\) at x = {d.x:g} m hang wire 'messenger' from 'contact'.*"
                                             "upside down"):
        assemble(dataclasses.replace(p, line=bad))
