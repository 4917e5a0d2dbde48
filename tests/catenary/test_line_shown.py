"""The line a passage ran is the line its figures, tables and summary.json show: the marks (`marks.line_marks`: the
line's own supports, droppers and stitch wires), the name, the default statistics window on the line's supports
(`marks.default_window`), the warning for a window off the supports, and the summary that reruns it bit for bit."""

from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path

import matplotlib
import pytest
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
from mbsuite.models.catenary.plots import SUPPORT_STYLE, draw_line_marks
from mbsuite.scenes import load_scene, scene_from_dict

matplotlib.use("Agg")
LINES = Path(__file__).resolve().parents[2] / "mbsuite" / "models" / "catenary" / "lines"
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
    assert m["stitch"] == []
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
