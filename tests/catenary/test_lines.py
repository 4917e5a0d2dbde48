"""Lines other than the EN 50318 simple line: the line file, the scene's [line] section, the stitched and compound
builders (`line.py`, `lines.py`, `linefile.py`, `irregularity.py`). The independent checks of their FE (static
deflection against finite differences, wave speeds, reductions, presag by hand) are `test_line_checks.py`'s."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from mbsuite.cli import main as cli_main
from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.catenary import lines
from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.linefile import read_line_file
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.scenes import load_scene, scene_from_dict

LINES = Path(__file__).resolve().parents[2] / "mbsuite" / "models" / "catenary" / "lines"
SHORT = {"n_spans": 3, "x_end": 150.0, "window_start": 60.0, "window_end": 120.0}


def _scene(line: dict, params: dict | None = None) -> object:
    return scene_from_dict({"model": "catenary", "line": line, "params": params or {},
                            "input": {"type": "passage", "speed": 250.0}})


def test_the_en50318_line_file_is_the_default_line():
    """The shipped line file of the EN 50318 line assembles to the default scene's matrices and static state
    exactly (the file's numbers are CatenaryParams()' written out)."""
    line, irr = read_line_file(LINES / "en50318.toml")
    assert irr is None
    a = assemble(CatenaryParams())
    b = assemble(CatenaryParams(line=line))
    for k in ("x", "T0", "support_preload", "k_drop", "w0_full"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    for k in ("M", "K0", "Kd"):
        assert (getattr(a, k) != getattr(b, k)).nnz == 0, k


def test_a_passage_on_the_simple_line_given_as_a_line_equals_the_default_bit_for_bit():
    """`lines.simple(p)` passed as `p.line` runs the same passage as no line at all (measured: every statistic and
    every force sample identical, 0.0 difference, on the full EN 50318 scene at 250 and 300 km/h; here 3 spans)."""
    p = CatenaryParams(**SHORT)
    a = simulate(p, 250.0, 2e-4)
    b = simulate(dataclasses.replace(p, line=lines.simple(p)), 250.0, 2e-4)
    assert np.array_equal(a.result.force, b.result.force)
    assert a.stats == b.stats


@pytest.mark.slow
@pytest.mark.parametrize("speed", [250.0, 300.0])
def test_the_en50318_scene_on_its_line_file_is_unchanged(speed):
    """The default scene and the same scene on `lines/en50318.toml` ([line] file = ...): every statistic within
    1e-9 N (measured 0.0: the same arithmetic)."""
    a = simulate(CatenaryParams(), speed, 2e-4)
    b = simulate(CatenaryParams(line=read_line_file(LINES / "en50318.toml")[0]), speed, 2e-4)
    for k, v in a.stats.items():
        if isinstance(v, float):
            assert abs(b.stats[k] - v) <= 1e-9, k
    assert np.max(np.abs(a.result.force - b.result.force)) <= 1e-9


def test_stitch_wires_even_out_the_contact_wire_stiffness_along_a_span():
    """What the stitched catenary is for (Eppinger 1984, Ch. 1, Figure 1-1c): the contact wire's static receptance
    varies less along a span than on the simple line. Measured on the middle span of 5 (receptance at every node):
    (max - min) / mean 0.78 simple against 0.36 stitched; the support's receptance rises from 0.50 to 0.79 of the
    span's largest. Bounds: the variation at most 0.7 of the simple line's, the support's share 1.3 times."""
    p = CatenaryParams(n_spans=5, x_end=300.0, window_start=120.0, window_end=240.0)

    def receptance(line):
        fe = assemble(dataclasses.replace(p, line=line))
        K = (fe.K0 + fe.Kd).tocsc()
        nodes = np.nonzero((fe.x >= 120.0) & (fe.x <= 180.0))[0]
        dofs = fe.cw_dof[nodes, 0]
        from scipy.sparse.linalg import splu

        lu = splu(K)
        r = np.array([lu.solve(np.eye(fe.n)[:, d])[d] for d in dofs])
        return r

    simple, stitched = receptance(lines.simple(p)), receptance(lines.stitched(p))
    var = [(r.max() - r.min()) / r.mean() for r in (simple, stitched)]
    assert var[1] < 0.7 * var[0], var
    assert stitched[0] / stitched.max() > 1.3 * simple[0] / simple.max()


def test_the_stitched_line_follows_the_fixed_scene():
    """`catenary/en50318_stitched` is the stitched scene fixed in the model README: stitch wires over x_s +- 9 m at
    the nine interior supports (0.31 kg/m, 3.5 kN, EI 10), clamped to the messenger at both ends by 1e7 N/m springs,
    the droppers at x_s +- 5 m on the stitch wire, the messenger at 12.5 kN between the clamps, 16 kN elsewhere."""
    p = load_scene("catenary/en50318_stitched").build_params()
    line = p.line
    st = [w for w in line.wires if w.role == "stitch"]
    assert [(w.x0, w.x1) for w in st] == [(x - 9.0, x + 9.0) for x in range(60, 600, 60)]
    assert all((w.mass, w.tension, w.EI, w.ends) == (0.31, 3500.0, 10.0, ("free", "free")) for w in st)
    mw = line.wire("messenger")
    assert mw.tension == 16000.0
    assert mw.tension_segments == tuple((x - 9.0, x + 9.0, 12500.0) for x in range(60, 600, 60))
    assert sorted((c.x, c.k) for c in line.clamps) == sorted((x + s * 9.0, 1e7) for x in range(60, 600, 60)
                                                             for s in (-1, 1))
    on_stitch = sorted(d.x for d in line.droppers if d.upper.startswith("stitch"))
    assert on_stitch == sorted(x + s * 5.0 for x in range(60, 600, 60) for s in (-1, 1))
    assert {d.x for d in line.droppers if d.upper == "messenger"} >= {5.0, 595.0}
    assert len(line.droppers) == 90


def test_line_section_errors_name_the_culprit(tmp_path):
    with pytest.raises(SceneError, match=r"unknown key\(s\) \['kinds'\]"):
        _scene({"kinds": "stitched"})
    with pytest.raises(SceneError, match="kind = 'spiral'"):
        _scene({"kind": "spiral"})
    with pytest.raises(SceneError, match=r"\[line.stitch\] is read only with kind = 'stitched'"):
        _scene({"kind": "simple", "stitch": {"tension": 3000.0}})
    with pytest.raises(SceneError, match="stitch"):
        _scene({"kind": "stitched", "stitch": {"tension": -1.0}})
    with pytest.raises(SceneError, match="presag"):
        _scene({"kind": "simple", "presag": 0.2})
    with pytest.raises(SceneError, match=r"\[params\] \['cw_tension'\] describe the simple line"):
        _scene({"file": str(LINES / "en50318.toml")}, {"cw_tension": 21000.0})
    with pytest.raises(SceneError, match="seed"):
        _scene({"kind": "simple", "irregularity": {"rms": 0.001, "wavelength_min": 1.0, "wavelength_max": 10.0}})
    with pytest.raises(SceneError, match="dx"):
        _scene({"kind": "simple", "irregularity": {"seed": 1, "rms": 0.001, "wavelength_min": 0.2,
                                                   "wavelength_max": 10.0, "dx": 0.1}})
    with pytest.raises((SceneError, ParameterError), match="dropper_offset"):
        _scene({"kind": "stitched", "stitch": {"dropper_offset": 6.0}}).build_params()


def test_a_scene_names_a_line_file_relative_to_its_folder(tmp_path):
    """`[line] file = "..."` is read relative to the scene file's folder; the scene's positions are checked against
    the file's length (a 180 m line: x_end = 150 m is valid, 200 m is not)."""
    (tmp_path / "lines").mkdir()
    line = lines.simple(CatenaryParams(n_spans=3, x_end=150.0, window_start=60.0, window_end=120.0))
    body = ["[[wires]]\nname = 'contact'\nrole = 'contact'\nmass = 1.35\ntension = 20000.0\nEI = 195.0\nx0 = 0.0\n"
            "x1 = 180.0\n", "[[wires]]\nname = 'messenger'\nrole = 'messenger'\nmass = 1.07\ntension = 16000.0\n"
            "EI = 131.7\nx0 = 0.0\nx1 = 180.0\n"]
    body += [f"[[supports]]\nx = {s.x}\n" + "".join(f"k_{w} = {k!r}\n" for w, k in s.k.items())  # ends: anchors
             for s in line.supports]
    (tmp_path / "lines" / "short.toml").write_text("droppers_file = 'd.csv'\n" + "\n".join(body))
    (tmp_path / "lines" / "d.csv").write_text("x,upper,lower,k\n" + "".join(
        f"{d.x},messenger,contact,100000\n" for d in line.droppers))
    scene = tmp_path / "s.toml"
    scene.write_text("model = 'catenary'\n[line]\nfile = 'lines/short.toml'\n[params]\nx_end = 150.0\n"
                     "window_start = 60.0\nwindow_end = 120.0\n[input]\ntype = 'passage'\nspeed = 250.0\n")
    p = load_scene(scene).build_params()
    assert p.length == 180.0 and len(p.line.droppers) == 27
    fe_file, fe_built = assemble(p), assemble(dataclasses.replace(p, line=line))
    assert np.array_equal(fe_file.T0, fe_built.T0)
    scene.write_text(scene.read_text().replace("x_end = 150.0", "x_end = 200.0"))
    with pytest.raises(ParameterError, match=r"x_end = 200.0 m.*<= 180 m \(the line's length\)"):
        load_scene(scene)


def test_mbsuite_catenary_runs_a_line_file(tmp_path, capsys):
    """`mbsuite catenary FILE` with a line file: the default scene on that line, the line's default window (here the
    3-span EN 50318 line, 180 m: 60-120 m, its middle span) and the run on to the middle of the span after it (150 m,
    beyond 0.7 L = 126 m)."""
    src = (LINES / "en50318.toml").read_text()
    keep = [b for b in src.split("\n\n") if "x = " not in b or float(b.split("x = ")[1].split("\n")[0]) <= 180.0]
    text = "\n\n".join(keep).replace("x1 = 600.0", "x1 = 180.0")
    text = text.replace("x = 180.0\nk_contact = 300.0\nk_messenger = 50000.0", "x = 180.0")  # now the anchors
    f = tmp_path / "three.toml"
    f.write_text(text)
    assert cli_main(["catenary", str(f), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    p = CatenaryParams(n_spans=3, x_end=150.0, window_start=60.0, window_end=120.0)
    direct = simulate(p, 250.0, 2e-4)
    stats = out["runs"]["slack"]["statistics"]
    assert abs(stats["sigma"] - direct.stats["sigma"]) <= 1e-9


def test_two_droppers_on_one_point_of_a_wire_are_refused():
    """The static state holds the lower wire once per point: two droppers there would each take the whole reaction
    (found by the independent checks: both at 86 N, the messenger 81 mm lower)."""
    p = CatenaryParams(**SHORT)
    base = lines.simple(p)
    with pytest.raises(ParameterError, match=r"two droppers hang wire 'contact' at x = 30.0 m"):
        dataclasses.replace(base, droppers=(*base.droppers, lines.Dropper(30.0, "messenger", "contact", 1e5)))


def test_an_edited_profile_file_is_read_again(tmp_path):
    """An irregularity profile is rebuilt when its file changes (the cache keys on the file's stamp, not its name)."""
    from mbsuite.models.catenary import irregularity

    f = tmp_path / "r.csv"
    f.write_text("x,r\n0,0\n10,0.001\n20,0\n")
    assert irregularity.build({"file": str(f)}, 20.0)(10.0) == pytest.approx(0.001)
    f.write_text("x,r\n0,0\n10,0.005\n20,0\n30,0\n")
    assert irregularity.build({"file": str(f)}, 20.0)(10.0) == pytest.approx(0.005)
