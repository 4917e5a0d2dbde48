"""The overlap of two tension sections (model README, "Overlaps and routes"): a line of several contact wires, each
over its own x-range, one pantograph head in contact with every contact wire under it (`lines.overlap`, `lines.route`,
the scene `catenary/en50318_overlap`).

Against sources that do not use the code under test: the static state against the overlap's geometry solved by hand
(string statics of each contact wire held at its design heights, the messengers as strings on their supports'
springs under the droppers' tensions); the energy balance of the undamped passage through the overlap; a route of
one section equal to the simple line bit for bit; the compiled loop against the core's stages driven from Python (the
oracle of `test_compiled_loop.py`); the statistics converging in element length and time step (slow)."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.config import CriticalSpeedWarning
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.line import Clamp, Dropper, Line, Wire
from mbsuite.models.catenary.lines import OverlapParams, overlap, route, section, simple
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.train import simulate_train
from mbsuite.scenes import load_scene

#: the overlap scene's line: A over 0-480 m, B over 300-780 m
P_SCENE = CatenaryParams(n_spans=13, x_end=720.0, window_start=300.0, window_end=480.0)
#: a short overlap for passages: sections of 4 spans sharing 3 (A 0-240 m, B 60-300 m; they cross at 150 m)
P_SHORT = CatenaryParams(n_spans=5, x_end=280.0, window_start=60.0, window_end=240.0,
                         windows=[[0.0, 60.0], [60.0, 240.0], [240.0, 280.0]])
SHORT = OverlapParams(spans=4, overlap_spans=3)


def _with(p: CatenaryParams, o: OverlapParams | None = None, **kw) -> CatenaryParams:
    p = dataclasses.replace(p, **kw)
    return dataclasses.replace(p, line=overlap(p, o))


def _design(x: np.ndarray, pts: list[tuple[float, float]]) -> np.ndarray:
    """The design heights of the scene by hand: linear between the stated points."""
    px, pz = np.array(pts).T
    return np.interp(x, px, pz)


A_HEIGHTS = [(0.0, 0.0), (360.0, 0.0), (420.0, 0.10), (480.0, 0.50)]
B_HEIGHTS = [(300.0, 0.50), (360.0, 0.10), (420.0, 0.0), (780.0, 0.0)]


def _hand_section(p: CatenaryParams, x0: float, x1: float, heights) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One section's static state by hand, both wires strings (EI = 0): the contact wire held at its design heights
    at the droppers, the steady arms (interior supports) and its pinned ends carries its weight between the holds;
    a hold's reaction is rho g (its tributary length) + T (slope on its left - slope on its right). The droppers'
    reactions load the messenger, a string of tension H pinned at the section's ends and on springs k at its interior
    supports: in each span y = y_a + (y_b - y_a)(x - a)/L - M(x)/H with M the simply supported moment of the span's
    loads; at each interior support -k y_s + H (slope right - slope left) = 0, a tridiagonal system for the support
    heights. Returns the droppers' x, their tensions and the messenger's height at them."""
    L = p.span_length
    sx = np.arange(x0, x1 + 1e-9, L)
    dx = np.array([s + d for s in sx[:-1] for d in p.dropper_positions])
    hold = np.unique(np.concatenate([sx, dx]))
    z = _design(hold, heights)
    rho_g, T = p.cw_mass * p.g, p.cw_tension
    slope = np.diff(z) / np.diff(hold)
    trib = np.diff(hold)
    R = rho_g * 0.5 * (np.concatenate([[0.0], trib]) + np.concatenate([trib, [0.0]]))
    R[1:-1] += T * (slope[:-1] - slope[1:])
    Td = R[np.searchsorted(hold, dx)]
    H, q, k = p.mw_tension, p.mw_mass * p.g, p.k_messenger_support
    n = sx.size

    def span_reactions(i: int) -> tuple[float, float]:
        a, b = sx[i], sx[i + 1]
        m = (dx > a) & (dx < b)
        return (q * L / 2 + float(np.sum(Td[m] * (b - dx[m]) / L)), q * L / 2 + float(np.sum(Td[m] * (dx[m] - a) / L)))

    reac = [span_reactions(i) for i in range(n - 1)]
    A = np.zeros((n, n))
    rhs = np.zeros(n)
    A[0, 0] = A[-1, -1] = 1.0  # pinned ends
    for s in range(1, n - 1):
        A[s, s] = -k - 2 * H / L
        A[s, s - 1] = A[s, s + 1] = H / L
        rhs[s] = reac[s][0] + reac[s - 1][1]
    ys = np.linalg.solve(A, rhs)
    ymw = np.zeros(dx.size)
    for i in range(n - 1):
        a, b = sx[i], sx[i + 1]
        m = (dx > a) & (dx < b)
        Ra = reac[i][0]
        for j in np.nonzero(m)[0]:
            xj = dx[j]
            M = Ra * (xj - a) - q * (xj - a) ** 2 / 2 - float(np.sum(Td[m & (dx < xj)] * (xj - dx[m & (dx < xj)])))
            ymw[j] = ys[i] + (ys[i + 1] - ys[i]) * (xj - a) / L - M / H
    return dx, Td, ymw


def test_static_state_against_the_overlap_solved_by_hand():
    """Each contact wire at its design heights at every dropper and steady arm (and its pinned ends), exactly; the
    two crossing at 390 m at +0.05 m; the dropper tensions and the dropper lengths (messenger height - contact-wire
    design height, from the system height) against the strings solved by hand (`_hand_section`) with both wires'
    EI = 0. The C1 elements round the strings' kinks, first order in h (0.57 N and 0.12 mm at 0.5 m, 0.28 N and
    0.061 mm at 0.25 m, halving again at 0.125 m: measured); Richardson-extrapolated from 0.5 and 0.25 m the FE is
    within 6.9e-3 N and 1.3e-6 m of the hand solution (bounds 0.021 N and 4e-6 m, 3x; tensions 69.5-86.1 N). The
    wires of A and B do not touch: each section hangs from its own messenger, no spring joins them."""
    fes = {h: assemble(_with(P_SCENE, cw_EI=0.0, mw_EI=0.0, element_length=h)) for h in (0.5, 0.25)}
    got: dict[tuple[float, str], tuple[np.ndarray, np.ndarray]] = {}
    for h, fe in fes.items():
        line = fe.line
        assert [w.name for w in line.contacts] == ["contact_a", "contact_b"]
        cw = {w.name: c for c, w in enumerate(line.wires)}
        at = {round(float(x), 9): i for i, x in enumerate(fe.x)}
        for name, x0, x1, heights in (("a", 0.0, 480.0, A_HEIGHTS), ("b", 300.0, 780.0, B_HEIGHTS)):
            c, m = cw[f"contact_{name}"], cw[f"messenger_{name}"]
            held = [s.x for s in line.supports if x0 <= s.x <= x1] + [d.x for d in line.droppers
                                                                      if d.lower == f"contact_{name}"]
            for x in held:  # the design heights, exactly (steady arms, droppers, pinned ends)
                z = float(_design(np.array(x), heights))
                assert fe.w0_full[fe.slot[c, at[round(x, 9)]]] == pytest.approx(z, abs=1e-12)
            mine = [j for j, d in enumerate(line.droppers) if d.lower == f"contact_{name}"]
            dx = np.array([line.droppers[j].x for j in mine])
            up = np.array([fe.w0_full[fe.slot[m, at[round(x, 9)]]] for x in dx])
            got[(h, name)] = (fe.T0[mine], up - _design(dx, heights))  # the dropper length from the system height
        i390 = at[390.0]
        assert fe.w0_full[fe.slot[cw["contact_a"], i390]] == pytest.approx(0.05, abs=1e-12)
        assert fe.w0_full[fe.slot[cw["contact_b"], i390]] == pytest.approx(0.05, abs=1e-12)
        for d in line.droppers:  # each section hangs from its own messenger
            assert d.upper[-2:] == d.lower[-2:]
    p = fes[0.5].params
    for name, x0, x1, heights in (("a", 0.0, 480.0, A_HEIGHTS), ("b", 300.0, 780.0, B_HEIGHTS)):
        dx, Td, ymw = _hand_section(p, x0, x1, heights)
        (t5, l5), (t25, l25) = got[(0.5, name)], got[(0.25, name)]
        assert np.max(np.abs(t25 - Td)) < 0.6 * np.max(np.abs(t5 - Td))  # first order: it halves
        assert np.max(np.abs(2 * t25 - t5 - Td)) < 0.021
        assert np.max(np.abs(2 * l25 - l5 - (ymw - _design(dx, heights)))) < 4e-6


def test_overlapping_contact_wires_must_not_touch_and_new_inputs_are_checked():
    """Joined by a dropper or a clamp, at the same design height over an interval, a heights profile that is not a
    contact wire's, does not start at x0 or end at x1, is not increasing or not finite; a contact wire that starts
    past the previous ones' end or lies inside them; windows outside the run or malformed: each a ParameterError
    naming it."""
    p = dataclasses.replace(P_SHORT)
    good = overlap(p, SHORT)
    with pytest.raises(ParameterError, match="joined by droppers or clamps through other wires"):
        dataclasses.replace(good, droppers=(*good.droppers, Dropper(100.0, "messenger_a", "contact_b", 1e5)))
    with pytest.raises(ParameterError, match=r"joined by the dropper\(s\) or clamp\(s\) at x = 100 m"):
        dataclasses.replace(good, clamps=(Clamp(100.0, "contact_a", "contact_b", 1e5),))
    flat = tuple(dataclasses.replace(w, heights=()) if w.role == "contact" else w for w in good.wires)
    with pytest.raises(ParameterError, match="same design height from x = 60 to 65 m"):
        Line(flat, good.supports, good.droppers)
    cw = good.wires[0]
    for heights, what in (([(0.0, 0.0), (100.0, 0.1)], "the first at x0"),
                          ([(0.0, 0.0), (240.0, np.nan)], r"heights\[1\]\[1\] = nan .* valid: \[-10, 10\] m"),
                          ([(0.0, 0.0), (120.0, 0.0), (100.0, 0.1), (240.0, 0.0)], "x increasing"),
                          ([(0.0, 0.0), (240.0, 99.0)], r"heights\[1\]\[1\] = 99.0 .* valid: \[-10, 10\] m")):
        with pytest.raises(ParameterError, match=what):
            dataclasses.replace(cw, heights=heights)
    with pytest.raises(ParameterError, match="is for a contact wire"):
        dataclasses.replace(good.wires[2], heights=[(0.0, 0.0), (240.0, 0.0)])
    far = Wire("contact_c", "contact", 1.35, 2e4, 195.0, 320.0, 400.0)
    with pytest.raises(ParameterError, match="past the end of the contact wires before it"):
        Line((*good.wires, far), good.supports, good.droppers)
    inside = Wire("contact_c", "contact", 1.35, 2e4, 195.0, 100.0, 200.0)
    with pytest.raises(ParameterError, match="lies inside the contact wires before it"):
        Line((*good.wires, inside), good.supports, good.droppers)
    for ws, what in (([[0.0, 400.0]], "inside the run"), ([[50.0, 40.0]], "below end"), ([[1.0]], "pair"),
                     ("0, 60", "list"), ([[np.nan, 60.0]], "finite"), ([[0.0, np.inf]], "finite"),
                     ([[True, 60.0]], "pair of numbers")):
        with pytest.raises(ParameterError, match=what):
            dataclasses.replace(p, windows=ws)
    with pytest.raises(SceneError, match="list of lists"):
        load_scene("catenary/en50318_overlap").replace(params={"windows": [1.0, 2.0]}).build_params()


def test_a_route_of_one_section_is_the_simple_line_bit_for_bit():
    """A route of one EN 50318 section (`lines.route`, `lines.section`: wires named contact_a, messenger_a) runs the
    simple line's passage exactly: every record and statistic equal (0.0)."""
    p = CatenaryParams(n_spans=4, x_end=200.0, window_start=60.0, window_end=180.0)
    one = route([section(p, 4, "a")], name="one section")
    assert [w.name for w in one.wires] == ["contact_a", "messenger_a"]
    a = simulate(p, 300.0, 2e-4)
    b = simulate(dataclasses.replace(p, line=one), 300.0, 2e-4)
    c = simulate(dataclasses.replace(p, line=simple(p)), 300.0, 2e-4)
    for r in (b, c):
        for k in ("force", "head", "wire", "uplift"):
            assert np.array_equal(getattr(a.result, k), getattr(r.result, k)), k
        assert all(a.stats[k] == r.stats[k] for k in ("Fm", "sigma", "max", "min", "uplift_mm", "loss_pct"))


def test_compiled_loop_equals_the_stage_loop_through_the_overlap():
    """The passage through the short overlap in the compiled loop (one head, a contact point per contact wire, the
    head's force their sum, all in C) against the core's stages driven from Python with the secant coupling
    (`train._Secant`, the oracle): measured bit-equal; bound 1e-9 N, 1e-12 m. The head meets both wires: each carries
    force in the overlap, neither outside its x-range, and the head's force is their sum."""
    p = _with(P_SHORT, SHORT)
    a = simulate_train(p, 300.0, 2e-4, ["reference2mass"], [])
    b = simulate_train(p, 300.0, 2e-4, ["reference2mass"], [], stepwise=True)
    assert a.timing["native_loop"] and not b.timing["native_loop"]
    ra, rb = a.results[0], b.results[0]
    assert np.max(np.abs(ra.force - rb.force)) < 1e-9 and np.max(np.abs(ra.head - rb.head)) < 1e-12
    wa, wb = ra.wires["contact_a"], ra.wires["contact_b"]
    assert np.array_equal(ra.force, wa["force"] + wb["force"])
    assert np.all(wa["force"][ra.x > 240.0] == 0.0) and np.all(wb["force"][ra.x < 60.0] == 0.0)
    both = (ra.x > 60.0) & (ra.x < 240.0)
    assert np.max(wa["force"][both]) > 50.0 and np.max(wb["force"][both]) > 50.0
    assert a.stats[0]["windows"]["60-240"]["wires"]["contact_b"]["x_first_contact"] > 60.0


#: a short route of three sections: 4 spans each, 2 shared (A 0-240 m, B 120-360 m, C 240-480 m)
P_ROUTE = CatenaryParams(n_spans=8, x_end=400.0, window_start=120.0, window_end=240.0,
                         windows=[[0.0, 120.0], [120.0, 240.0], [240.0, 360.0], [360.0, 400.0]])
ROUTE = OverlapParams(sections=3, spans=4, overlap_spans=2)


def test_a_route_steps_only_the_sections_in_play_and_its_pantographs_see_no_difference():
    """The short three-section route under two pantographs 60 m apart, stepped three ways (`step_sections`): every
    section always ("all"), each from the step the leading pantograph reaches it ("reached") and, further, only until
    every pantograph has passed its end ("in play", the default). Sections hang from their own wires: nothing but a
    pantograph joins them, so a section not yet reached is exactly static (its steady arms' uplift 0.0 in the run
    that steps it) and one both pantographs have left moves nothing they meet. Measured: both pantographs' forces,
    head and wire heights bit-equal in the three runs (asserted equal); the uplift records of "reached" equal to
    "all"; those of "in play" equal up to the time the trailing contact point passed the section's end (from x(t)
    = x_start - s + V t, computed here) and NaN from there on, the statistics reading the stepped part."""
    p = _with(P_ROUTE, ROUTE)
    runs = {m: simulate_train(dataclasses.replace(p, step_sections=m), 250.0, 2e-4,
                              ["reference2mass", "reference2mass"], [60.0]) for m in ("all", "reached", "in play")}
    a = runs["all"]
    for m in ("reached", "in play"):
        for ra, rb in zip(a.results, runs[m].results, strict=True):
            for key in ("force", "head", "wire", "x"):
                assert np.array_equal(getattr(ra, key), getattr(rb, key)), (m, key)
    for ra, rb in zip(a.results, runs["reached"].results, strict=True):
        assert np.array_equal(ra.uplift, rb.uplift)
    fe = assemble(p)
    comp = dict(zip([w.name for w in p.line.wires], p.line.wire_components(), strict=True))
    si, ci = fe.arms
    arm_comp = np.array([comp[p.line.contacts[c].name] for c in ci])
    lead = a.results[0]
    V, dt = 250.0 / 3.6, 2e-4
    for w in p.line.contacts:
        mine = (arm_comp == comp[w.name]) & (fe.arm_cw >= 0)
        before = lead.x < w.x0 - V * dt  # the leading head not yet on this section: its arms exactly static
        assert np.all(lead.uplift[np.ix_(before, mine)] == 0.0) and np.any(lead.uplift[:, mine] != 0.0)
        t_left = (w.x1 - (p.x_start - 60.0)) / V  # the trailing contact point passes the section's end
        rin = runs["in play"].results[0]
        gone = np.isnan(rin.uplift[:, mine]).all(axis=1)
        if t_left < lead.t[-1] - dt:
            first = int(np.argmax(gone))
            assert abs(lead.t[first] - t_left) <= dt + 1e-9 and np.all(gone[first:]) and not np.any(gone[:first])
            assert np.array_equal(rin.uplift[:first][:, mine], lead.uplift[:first][:, mine])
        else:
            assert not np.any(gone)
    assert runs["in play"].stats[0]["windows"]["0-120"]["uplift_mm"] > 0.0


def test_a_section_entered_in_the_running_plane_is_stepped_from_its_first_contact():
    """Two sections whose coming contact wire starts in the running plane (B at 0 from its anchor at 120 m, A rising
    from 0 there to +0.5 m at its anchor at 240 m: they meet at 120 m only): the head presses on B from the step it
    reaches it. The passage stepping only the sections in play against the one stepping all: forces bit-equal
    (asserted equal), and B carries force within 1 m of its anchor (a section stepped late would be frozen there)."""
    p = dataclasses.replace(P_ROUTE, n_spans=6, x_end=340.0, windows=[])
    ha = [(0.0, 0.0), (120.0, 0.0), (180.0, 0.1), (240.0, 0.5)]
    line = route([section(p, 4, "a", ha), (120.0, section(p, 4, "b", [(0.0, 0.0), (240.0, 0.0)]))], name="flat")
    p = dataclasses.replace(p, line=line)
    runs = {m: simulate_train(dataclasses.replace(p, step_sections=m), 250.0, 2e-4, ["reference2mass"], [])
            for m in ("all", "in play")}
    a, b = (runs[m].results[0] for m in ("all", "in play"))
    assert np.array_equal(a.force, b.force) and np.array_equal(a.head, b.head)
    fb = a.wires["contact_b"]["force"]
    assert np.any(fb[(a.x > 120.0) & (a.x < 121.0)] > 1.0)


def test_energy_balance_through_the_overlap_closes():
    """Undamped, weightless overlap at 300 km/h (linear droppers: without weight the droppers of a straight stretch
    carry nothing in the static state): the total energy (catenary with the exact dropper law, pantograph,
    both contact springs) changes only by the work the imposed horizontal motion feeds in through both sloping
    wires (their design heights' slope included), -sum_k f_k V d(w0 + u)_k/dx, through the hand-over from A to B.
    Measured 4.7e-4 of the energy exchanged (131 J) at dt 1e-4 s (bound 1.5e-3, 3x)."""
    p = _with(P_SHORT, SHORT, zeta=0.0, c1=0.0, c2=0.0, g=0.0, x_end=260.0, windows=[])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CriticalSpeedWarning)
        r = simulate_train(p, 300.0, 1e-4, ["reference2mass"], [], dropper_law="linear", record_energy=5)
    E = r.energy
    total = E["catenary"] + E["pantograph"] + E["contact"]
    work = np.concatenate([[0.0], np.cumsum(0.5 * (E["drive_power"][1:] + E["drive_power"][:-1])
                                            * np.diff(r.energy_t))])
    scale = np.max(np.abs(total - total[0]))
    w = r.results[0].wires
    assert scale > 5.0 and np.any(w["contact_a"]["force"] > 0) and np.any(w["contact_b"]["force"] > 0)
    err = np.max(np.abs(total - total[0] - work)) / scale
    assert err < 1.5e-3


def test_shipped_scene_loads_with_its_windows_and_line():
    """The scene `catenary/en50318_overlap`: the overlap line of the EN 50318 data (two contact wires, 144 droppers,
    the supports of both sections merged: 14), its three windows and the overlap as the headline window."""
    p = load_scene("catenary/en50318_overlap").build_params()
    assert p.windows == [[120.0, 300.0], [300.0, 480.0], [480.0, 660.0]]
    assert (p.window_start, p.window_end, p.x_start, p.x_end) == (300.0, 480.0, 0.0, 720.0)
    assert [(w.name, w.x0, w.x1) for w in p.line.contacts] == [("contact_a", 0.0, 480.0), ("contact_b", 300.0, 780.0)]
    assert len(p.line.droppers) == 144 and len(p.line.supports) == 14
    assert p.line.contacts[0].heights == tuple(A_HEIGHTS) and p.line.contacts[1].heights == tuple(B_HEIGHTS)


def _toml(line: Line) -> str:
    """`line` written as a line file (every wire, support and dropper as a table; `linefile` reads it)."""
    out = [f'name = "{line.name}"']
    for w in line.wires:
        out += ["[[wires]]", f'name = "{w.name}"', f'role = "{w.role}"', f"mass = {w.mass!r}",
                f"tension = {w.tension!r}", f"EI = {w.EI!r}", f"x0 = {w.x0!r}", f"x1 = {w.x1!r}"]
        if w.heights:
            out.append(f"heights = {[list(q) for q in w.heights]!r}")
    for s in line.supports:
        out += ["[[supports]]", f"x = {s.x!r}"] + [f"k_{k} = {v!r}" for k, v in s.k.items()]
    for d in line.droppers:
        out += ["[[droppers]]", f"x = {d.x!r}", f'upper = "{d.upper}"', f'lower = "{d.lower}"', f"k = {d.k!r}"]
    return "\n".join(out) + "\n"


def test_an_overlap_written_as_a_line_file_is_the_built_line(tmp_path):
    """The overlap written out as a line file (two contact wires, their `heights`, each section's supports and
    droppers) reads back as the line `lines.overlap` builds (equal as data), assembles to the same static state bit
    for bit, and a scene naming it loads; a line file with the second contact wire joined to the first is refused
    naming the file."""
    from mbsuite.models.catenary.linefile import read_line_file

    built = overlap(P_SHORT, SHORT)
    path = tmp_path / "overlap.toml"
    path.write_text(_toml(built))
    line, irr = read_line_file(path)
    assert irr is None and line == built
    p = dataclasses.replace(P_SHORT, windows=[])
    a, b = assemble(dataclasses.replace(p, line=built)), assemble(dataclasses.replace(p, line=line))
    assert np.array_equal(a.w0_full, b.w0_full) and np.array_equal(a.T0, b.T0)
    scene = tmp_path / "scene.toml"
    scene.write_text('model = "catenary"\n[line]\nfile = "overlap.toml"\n[params]\nx_end = 280.0\n'
                     'window_start = 60.0\nwindow_end = 240.0\nwindows = [[60.0, 240.0]]\n[input]\nspeed = 250.0\n')
    assert load_scene(str(scene)).build_params().line == built
    bad = tmp_path / "bad.toml"
    bad.write_text(_toml(built) + '[[droppers]]\nx = 100.0\nupper = "messenger_a"\nlower = "contact_b"\nk = 1e5\n')
    with pytest.raises(SceneError, match=r"bad.toml.*'contact_a' and 'contact_b' overlap on \[60.0, 240.0\] m and "
                                         "are joined"):
        read_line_file(bad)


@pytest.mark.slow
def test_contact_force_through_the_transition_span_converges_in_element_length_and_time_step():
    """The short overlap at 300 km/h, the statistics of the transition span [120, 180] m (the wires cross at 150 m)
    and each contact wire's own force there, with element length and time step halved together from the shipped
    0.5 m / 2e-4 s twice. Measured level-to-level changes: sigma 0.067 then 0.0065 N, max 0.12 then 0.018 N, min 0.058
    then 0.0070 N, wire B's max 0.10 then 0.011 N (each change about a tenth of the one before); the shipped level
    is within 0.14 N of the finest on every statistic (bound 0.5 N, 3.5x; the declared accuracy is 1 N) and the two
    finer levels within 0.018 N (bound 0.06 N, 3.3x). ~40 s CPU."""
    levels = []
    for h, dt in ((0.5, 2e-4), (0.25, 1e-4), (0.125, 5e-5)):
        p = _with(P_SHORT, SHORT, element_length=h, windows=[[120.0, 180.0]])
        s = simulate_train(p, 300.0, dt, ["reference2mass"], []).stats[0]["windows"]["120-180"]
        levels.append({**{k: s[k] for k in ("Fm", "sigma", "stat_max", "stat_min", "max", "min")},
                       **{f"{n}_{k}": s["wires"][n][k] for n in ("contact_a", "contact_b") for k in ("Fm", "max")}})
    for k in levels[0]:
        assert abs(levels[0][k] - levels[2][k]) < 0.5, k
        assert abs(levels[1][k] - levels[2][k]) < 0.06, k
    for k in ("sigma", "max", "min", "contact_b_max"):
        assert abs(levels[1][k] - levels[2][k]) < 0.5 * abs(levels[0][k] - levels[1][k]), k
