"""The line a passage ran is the line its figures, tables and summary.json show: the marks (`marks.line_marks`: the
line's own supports, droppers and stitch wires), the name, the default statistics window on the line's supports
(`marks.default_window`), the warning for a window off the supports, and the summary that reruns it bit for bit."""

from __future__ import annotations

import hashlib
import json
import tomllib
import warnings
from pathlib import Path
from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest
from matplotlib.collections import PathCollection
from matplotlib.figure import Figure

from mbsuite.cli import main as cli_main
from mbsuite.errors import ParameterError
from mbsuite.models.catenary.linefile import read_line_file
from mbsuite.models.catenary.marks import (
    REFERENCE_LINE,
    WindowOffSupportWarning,
    default_window,
    line_label,
    line_marks,
)
from mbsuite.models.catenary.mesh import line_of
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.passage import CoupledResult
from mbsuite.models.catenary.plots import (
    SUPPORT_STYLE,
    WIRE_COLOURS,
    draw_line_marks,
    force_uplift_figure,
    marks_legend,
    train_figure,
)
from mbsuite.scenes import load_scene, scene_from_dict

matplotlib.use("Agg")
LINES = Path(__file__).resolve().parents[2] / "mbsuite" / "models" / "catenary" / "lines"
SCENES = LINES.parent / "scenes"
SPAN, N = 55.0, 8
DROPS = (5.0, 15.0, 27.5, 40.0, 50.0)


def _line_55(tmp_path: Path) -> Path:
    """A line file of eight 55 m spans (the format of lines/example_section.toml: wires in the TOML, the supports and
    droppers in CSV tables)."""
    L = SPAN * N
    (tmp_path / "sup.csv").write_text("x,k_contact,k_messenger\n" + "".join(
        f"{k * SPAN},{0.0 if k in (0, N) else 300.0},{0.0 if k in (0, N) else 50000.0}\n" for k in range(N + 1)))
    (tmp_path / "drop.csv").write_text("x,upper,lower,k\n" + "".join(
        f"{k * SPAN + d},messenger,contact,100000.0\n" for k in range(N) for d in DROPS))
    f = tmp_path / "span55.toml"
    f.write_text(f'name = "55 m spans"\nsupports_file = "sup.csv"\ndroppers_file = "drop.csv"\n\n'
                 f'[[wires]]\nname = "contact"\nrole = "contact"\nmass = 1.35\ntension = 20000.0\nEI = 195.0\n'
                 f'x0 = 0.0\nx1 = {L}\n\n'
                 f'[[wires]]\nname = "messenger"\nrole = "messenger"\nmass = 1.07\ntension = 16000.0\nEI = 131.7\n'
                 f'x0 = 0.0\nx1 = {L}\n')
    return f


def test_marks_are_the_reference_lines_supports_and_droppers():
    p = CatenaryParams()
    m = line_marks(line_of(p), (p.x_start, p.x_end))
    assert m["supports"] == [60.0 * k for k in range(8)]
    assert m["droppers"] == [60.0 * s + d for s in range(7) for d in p.dropper_positions]
    assert m["stitch"] == [] and m["overlaps"] == [] and m["anchors"] == []  # its ends at 0 and 420 m: the line's
    assert line_label(p) == REFERENCE_LINE
    assert line_label(CatenaryParams(n_spans=14)) == "EN 50318 line of 14 spans"
    assert line_label(CatenaryParams(span_length=55.0, n_spans=8, x_end=400, dropper_positions=list(DROPS))) == (
        "simple line, 8 spans of 55 m")


def test_marks_are_a_55m_line_files_supports_and_droppers(tmp_path):
    line, _ = read_line_file(_line_55(tmp_path))
    m = line_marks(line, (0.0, 300.0))
    assert m["supports"] == [55.0 * k for k in range(6)]
    assert m["droppers"] == [55.0 * s + d for s in range(6) for d in DROPS if 55.0 * s + d <= 300.0]
    p = CatenaryParams(line=line, x_end=300.0, window_start=110.0, window_end=220.0)
    assert line_label(p) == "line '55 m spans'"
    # drawn: one grey line per support of the run, none at the reference line's 60 m
    fig = Figure()
    ax = fig.add_subplot()
    draw_line_marks([ax], p)
    drawn = sorted(ln.get_xdata()[0] for ln in ax.lines if ln.get_color() == SUPPORT_STYLE["color"])
    assert drawn == m["supports"]


def test_marks_of_stitch_wires_are_the_lines_own():
    line, _ = read_line_file(LINES / "example_section.toml")
    m = line_marks(line, (0.0, 200.0))
    assert m["supports"] == [0.0, 55.0, 115.0, 178.0]
    assert m["stitch"] == [(47.0, 63.0), (107.0, 123.0), (170.0, 186.0)]
    assert m["droppers"] == sorted({d.x for d in line.droppers if d.x <= 200.0})


def _overlap_scene() -> tuple[CatenaryParams, float, float, float]:
    """The overlap scene's params and, from its declared geometry ([line.overlap] spans, overlap_spans; the spans of
    [params] span_length, default 60 m), A's end, B's start and B's end (m)."""
    o = tomllib.loads((SCENES / "en50318_overlap.toml").read_text())["line"]["overlap"]
    p = load_scene("catenary/en50318_overlap").build_params()
    L = p.span_length
    a_end, b_start = o["spans"] * L, (o["spans"] - o["overlap_spans"]) * L
    return p, a_end, b_start, b_start + o["spans"] * L


def test_marks_of_an_overlap_are_its_shared_spans_and_anchors():
    """The overlap scene: section A over `spans` spans from 0, B over as many from the start of A's last
    `overlap_spans` (the scene's [line.overlap]): the overlap [300, 480] m where both contact wires are, the anchors
    B's start (300 m) and A's end (480 m); the line's own ends (0, B's end) are none; a stretch clips them."""
    p, a_end, b_start, b_end = _overlap_scene()
    assert (b_start, a_end) == (300.0, 480.0)
    line = line_of(p)
    m = line_marks(line, (p.x_start, p.x_end))
    assert m["overlaps"] == [(b_start, a_end)]
    assert m["anchors"] == [(b_start, "contact_b"), (a_end, "contact_a")]
    assert line_marks(line)["anchors"] == m["anchors"]  # not B's end at the line's end (780 m)
    assert line.length == b_end
    part = line_marks(line, (0.0, 400.0))
    assert part["overlaps"] == [(b_start, 400.0)] and part["anchors"] == [(b_start, "contact_b")]
    assert line_marks(line, (500.0, 700.0))["overlaps"] == []
    assert marks_legend("x", m).replace("\n", " ") == (
        "x [m] (grey lines: supports; brown ticks: droppers; cyan hatching: overlap of two contact wires; triangles: "
        "anchors, contact_b at 300 m, contact_a at 480 m)")
    # the legend names only the marks present: no stitch wires on the reference line
    ref = line_marks(line_of(CatenaryParams()))
    assert marks_legend("x", ref) == "x [m] (grey lines: supports; brown ticks: droppers)"


def _route_run(p: CatenaryParams, law: str = "slack") -> SimpleNamespace:
    """A made-up passage through the overlap scene's line (the figure needs only its records): a steady arm of
    each contact wire at every support its x-range holds, named as `fe.arm_names` names them."""
    line = line_of(p)
    x = np.linspace(p.x_start, p.x_end, 721)
    arms = [(s.x, w.name) for s in line.supports for w in line.contacts if w.x0 <= s.x <= w.x1]
    names = [f"{xs:g}_{w}" if sum(a == xs for a, _ in arms) > 1 else f"{xs:g}" for xs, w in arms]
    wires = {w.name: {"force": np.full_like(x, 50.0), "wire": np.full_like(x, 0.05),
                      "on": (x >= w.x0) & (x <= w.x1)} for w in line.contacts}
    z = np.zeros_like(x)
    res = CoupledResult(t=x / 70.0, x=x, force=z + 100.0, head=z, wire=z + 0.05, uplift=np.zeros((x.size, len(arms))),
                        n_slack=z, panto={}, support_x=np.array([a for a, _ in arms]), wires=wires,
                        support_names=names)
    return SimpleNamespace(params=p, result=res, filtered=res.force, dropper_law=law, is_reference=False,
                           engine="reference", pantograph="reference2mass", speed_kmh=250.0)


def test_the_force_figure_through_an_overlap_colours_each_wire_and_marks_the_overlap():
    """Each contact wire in its own colour (its force, its height, the uplift at its steady arms), the head's summed
    force in the dropper law's; the uplift legend "steady arm at 360 m (contact_a)"; no line at an anchor (pinned:
    no uplift); the overlap hatched and labelled, the anchors as triangles, all named in the x-axis label."""
    p, a_end, b_start, _ = _overlap_scene()
    fig = force_uplift_figure([_route_run(p)])
    ax_f, ax_h, ax_u = fig.axes
    colour = {"contact_a": WIRE_COLOURS[0], "contact_b": WIRE_COLOURS[1]}
    lines = {ln.get_label(): ln.get_color() for ax in fig.axes for ln in ax.lines
             if not ln.get_label().startswith("_")}
    assert lines["slack droppers: F on contact_a, unfiltered"] == colour["contact_a"]
    assert lines["slack droppers: contact_b"] == colour["contact_b"]
    assert lines["slack droppers: F (sum over the contact wires), 20 Hz low-pass"] == "tab:blue"
    uplift = [ln.get_label() for ln in ax_u.lines if not ln.get_label().startswith("_")]
    window = (300.0, 360.0, 420.0, 480.0)  # the supports of the window [300, 480] m
    assert uplift == [f"slack droppers: steady arm at {xs:g} m ({w})" for xs in window
                      for w in ("contact_a", "contact_b") if (xs, w) not in {(b_start, "contact_b"),
                                                                             (a_end, "contact_a")}]
    assert lines["slack droppers: steady arm at 360 m (contact_b)"] == colour["contact_b"]
    assert "overlap" in [t.get_text() for t in ax_f.texts]
    assert "triangles: anchors, contact_b at 300 m, contact_a at 480 m" in ax_u.get_xlabel().replace("\n", " ")
    assert "stitch" not in ax_u.get_xlabel()
    for ax in (ax_f, ax_h, ax_u):  # the overlap: one hatched span; the anchors: two triangles
        assert [pt.get_hatch() for pt in ax.patches].count("//") == 1
        assert sorted(float(c.get_offsets()[0][0]) for c in ax.collections if isinstance(c, PathCollection)) == [
            b_start, a_end]
    run = SimpleNamespace(params=p, results=[_route_run(p).result] * 2, filtered=[np.zeros(721)] * 2,
                          names=["a", "b"], speed_kmh=250.0)
    tf = train_figure(run, ["a", "b"])
    assert "cyan hatching: overlap" in tf.axes[1].get_xlabel()
    assert "overlap" in [t.get_text() for t in tf.axes[0].texts]


def test_the_default_window_follows_the_lines_supports(tmp_path):
    """The fifth to the seventh support where the line goes on past it: the EN 50318 line's 240-360 m (the
    parameters' default, so the shipped scenes are unchanged, the trains' lengthened line too), 220-330 m on 55 m
    spans; a scene with a line file and no window gets it."""
    assert default_window(line_of(CatenaryParams())) == (240.0, 360.0)
    for name in ("en50318", "en50318_stitched", "en50318_compound", "en50318_two_pantographs"):
        p = load_scene(f"catenary/{name}").build_params()
        assert (p.window_start, p.window_end) == (240.0, 360.0)
    f = _line_55(tmp_path)
    line, _ = read_line_file(f)
    assert default_window(line) == (220.0, 330.0)
    d = load_scene("catenary/example_line").to_dict()
    d["line"] = {"file": str(f)}
    d["params"] = {"x_start": 0.0, "x_end": 400.0}
    with warnings.catch_warnings():
        warnings.simplefilter("error", WindowOffSupportWarning)
        p = scene_from_dict(d).build_params()
    assert (p.window_start, p.window_end) == (220.0, 330.0)
    # a line of fewer than eight supports: the supports nearest 0.4 L and 0.6 L (6 spans: the middle two)
    short = CatenaryParams(n_spans=5, x_end=300.0, window_start=120.0, window_end=180.0)
    assert default_window(line_of(short)) == (120.0, 180.0)
    six = CatenaryParams(n_spans=6, x_end=300.0, window_start=60.0, window_end=120.0)
    assert default_window(line_of(six)) == (120.0, 240.0)


@pytest.mark.parametrize("n", [3, 4, 5, 6, 7, 8, 10, 14, 30])
def test_the_default_window_is_whole_spans_without_the_end_spans(n):
    """On a simple line of n 50 m spans (a scene setting no window, the run to its end): the window starts and ends
    on supports of the line, and the first and the last span lie outside it."""
    sc = load_scene("catenary/en50318").replace(params={"n_spans": n, "span_length": 50.0, "x_end": 50.0 * n,
                                                        "dropper_positions": [5.0, 25.0, 45.0]})
    with warnings.catch_warnings():
        warnings.simplefilter("error", WindowOffSupportWarning)
        p = sc.build_params()
    supports = [50.0 * k for k in range(n + 1)]
    assert p.window_start in supports and p.window_end in supports
    assert supports[1] <= p.window_start < p.window_end <= supports[-2]


def test_a_default_window_outside_the_run_names_the_rule():
    with pytest.raises(ParameterError, match=r"the default statistics window \[240, 360\] m of the line .*"
                                             r"params.window_end = 360.0 m lies beyond params.x_end = 300.0 m"):
        load_scene("catenary/en50318").replace(params={"x_end": 300.0})


def test_a_window_off_the_supports_is_warned(tmp_path):
    d = load_scene("catenary/example_line").to_dict()
    d["line"] = {"file": str(_line_55(tmp_path))}
    d["params"] = {"x_start": 0.0, "x_end": 400.0, "window_start": 240.0, "window_end": 330.0}
    with pytest.warns(WindowOffSupportWarning, match=r"window \[240, 330\] m on the line '55 m spans' starts at "
                                                     r"240 m between the supports at 220 m and 275 m: "):
        scene_from_dict(d).build_params()
    d["params"].update(window_start=220.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", WindowOffSupportWarning)
        scene_from_dict(d).build_params()


def test_summary_records_the_rerun_and_reruns_bit_for_bit(tmp_path, capsys):
    """summary.json of catenary/example_line: the window used, the line file's path and SHA-256, element length,
    time step and speed, no solver settings the catenary does not read; `mbsuite catenary summary.json` gives the
    same statistics bit for bit."""
    a, b = tmp_path / "a", tmp_path / "b"
    with warnings.catch_warnings():
        warnings.simplefilter("error", WindowOffSupportWarning)  # the shipped window lies on its supports
        assert cli_main(["catenary", "catenary/example_line", "--json", "--out", str(a)]) == 0
        first = json.loads(capsys.readouterr().out)
        s = json.loads((a / "summary.json").read_text())
        assert cli_main(["catenary", str(a / "summary.json"), "--json", "--out", str(b)]) == 0
        again = json.loads(capsys.readouterr().out)
    r = s["results"]
    f = LINES / "example_section.toml"
    assert r["window"] == [115.0, 354.0]  # the scene's window, on its supports
    assert r["line"]["file"] == str(f.resolve())
    assert r["line"]["sha256"] == hashlib.sha256(f.read_bytes()).hexdigest()
    assert r["line"]["name"] == "line 'example section'"
    assert (r["element_length"], r["timestep"], r["speed_kmh"]) == (0.5, 2e-4, 250.0)
    assert not {"integrator", "method", "rtol", "atol", "max_step"} & set(s["scene"]["solver"])
    assert {k: s["scene"]["params"][k] for k in ("window_start", "window_end", "element_length")} == {
        "window_start": 115.0, "window_end": 354.0, "element_length": 0.5}
    assert first["runs"]["slack"]["statistics"] == again["runs"]["slack"]["statistics"]
    assert (again["window"], again["line"]) == (r["window"], r["line"])


def test_a_line_file_run_alone_reruns_from_its_summary_and_a_changed_table_is_refused(tmp_path, capsys):
    """`mbsuite catenary LINE.toml` (the 55 m line): the window the line's default (on its supports, no warning), the
    run on to the middle of the next span; summary.json pins both in the scene's [params] and reruns bit for bit;
    after an edit of the droppers' table the rerun is refused naming it."""
    f = _line_55(tmp_path)
    a, b = tmp_path / "a", tmp_path / "b"
    with warnings.catch_warnings():
        warnings.simplefilter("error", WindowOffSupportWarning)
        assert cli_main(["catenary", str(f), "--json", "--out", str(a)]) == 0
        first = json.loads(capsys.readouterr().out)
        assert cli_main(["catenary", str(a / "summary.json"), "--json", "--out", str(b)]) == 0
        again = json.loads(capsys.readouterr().out)
    s = json.loads((a / "summary.json").read_text())
    assert first["window"] == [4 * SPAN, 6 * SPAN]
    assert first["x_range"] == [0.0, 6.5 * SPAN]  # past 0.7 L = 308 m: the middle of the span after the window
    assert {k: s["scene"]["params"][k] for k in ("x_start", "x_end", "window_start", "window_end")} == {
        "x_start": 0.0, "x_end": 6.5 * SPAN, "window_start": 4 * SPAN, "window_end": 6 * SPAN}
    assert s["results"]["line"]["files"] == {
        str(tmp_path / n): hashlib.sha256((tmp_path / n).read_bytes()).hexdigest() for n in ("sup.csv", "drop.csv")}
    assert first["runs"]["slack"]["statistics"] == again["runs"]["slack"]["statistics"]
    drop = tmp_path / "drop.csv"
    drop.write_text(drop.read_text().replace("100000.0", "90000.0", 1))
    assert cli_main(["catenary", str(a / "summary.json"), "--out", str(b)]) != 0
    err = capsys.readouterr().err
    assert "drop.csv" in err and "changed" in err


def test_the_quality_figure_names_the_line():
    from mbsuite.models.catenary.quality import QualityCriteria, assess, figure

    q = assess({"Fm": 100.0, "sigma": 20.0, "loss_pct": 0.0, "loss_events": [], "uplift_mm": 50.0}, 250.0,
               QualityCriteria(), 1.0)
    fig = figure([("p", q)], "line '55 m spans'")
    assert "on the line '55 m spans'" in fig.get_suptitle()
