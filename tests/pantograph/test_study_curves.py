"""A `--vary` study keeps what each point computed: the frequency response's curves (long CSV, one overlay figure per
output) equal, value for value, the single `freqresp` run at each varied value (run independently: the oracle); the
modes study prints one row per varied value and one column per mode's frequency and damping, equal to the single
`modes` runs; every column of the study's tables names its unit."""

from __future__ import annotations

import csv
import json
import re

from mbsuite.cli import main
from mbsuite.models.pantograph.freq_grid import FR_SIGNALS

UNIT = re.compile(r".+ \[[^\]]+\]$")  # `name [unit]`


def _rows(path) -> list[list[str]]:
    return list(csv.reader(path.open()))


def test_freqresp_study_keeps_every_curve_equal_to_the_single_runs(tmp_path, capsys):
    out = tmp_path / "study"
    kh = (1500, 3000)
    assert main(["freqresp", "pantograph", "--vary", f"params.kh={kh[0]},{kh[1]}", "--methods", "linear",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "peaks_hz:" in text and "linear.F1[0] [Hz]" in text and "study_curves.csv" in text
    rows = _rows(out / "study_curves.csv")
    assert rows[0] == ["params.kh [N m/rad]", "output", "frequency [Hz]", "amplitude [m/m]", "phase [deg]", "method"]
    body = rows[1:]
    for k in kh:
        assert main(["freqresp", "pantograph", "--set", f"params.kh={k}", "--methods", "linear", "--json"]) == 0
        single = json.loads(capsys.readouterr().out)
        freqs = single["frequencies_hz"]
        for s in FR_SIGNALS:
            mine = [r for r in body if float(r[0]) == k and r[1] == s and r[5] == "linear"]
            assert [float(r[2]) for r in mine] == freqs
            assert [float(r[3]) for r in mine] == single["response"]["linear"][s]["amplitude"]  # bit-equal
            assert [float(r[4]) for r in mine] == single["response"]["linear"][s]["phase_deg"]
    assert len(body) == len(kh) * len(FR_SIGNALS) * len(freqs)
    for s in FR_SIGNALS:
        assert (out / f"study_curves_{s}.png").stat().st_size > 10_000
    study = _rows(out / "study.csv")
    assert all(UNIT.match(h) for h in study[0]), [h for h in study[0] if not UNIT.match(h)]
    assert "peaks_hz.linear.F1[0] [Hz]" in study[0] and "amplitude_input_m [m]" in study[0]
    assert not any(h.startswith(("response", "frequencies_hz")) for h in study[0])  # the curves are not numbers
    summary = json.loads((out / "summary.json").read_text())["results"]
    assert all(summary["units"].values()), [q for q, u in summary["units"].items() if not u]
    assert [c["output"] for c in summary["points"][0]["curves"]] == list(FR_SIGNALS)


def test_modes_study_is_a_wide_table_equal_to_single_runs(tmp_path, capsys):
    out = tmp_path / "modes"
    assert main(["modes", "pantograph", "--vary", "params.mh=10,16", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    lines = text.splitlines()
    head = next(ln for ln in lines if ln.split()[:2] == ["params.mh", "[kg]"])
    assert "f_n[1] [Hz]" in head and "zeta[1] [1]" in head and "quantity" not in head
    block = lines[lines.index("reference:") + 3:lines.index("reference:") + 5]  # one row per varied value
    assert [float(b.split()[0]) for b in block] == [10, 16]
    study = _rows(out / "study.csv")
    assert all(UNIT.match(h) for h in study[0]), [h for h in study[0] if not UNIT.match(h)]
    col = {h: i for i, h in enumerate(study[0])}
    assert len(study) == 3
    for row, mh in zip(study[1:], (10, 16), strict=True):
        assert float(row[col["params.mh [kg]"]]) == mh
        assert main(["modes", "pantograph", "--set", f"params.mh={mh}", "--json"]) == 0
        single = json.loads(capsys.readouterr().out)
        for path in ("reference", "mujoco"):
            for i, mode in enumerate(single[path]):
                assert float(row[col[f"{path}[{i}].f_n [Hz]"]]) == mode["f_n"]
                assert float(row[col[f"{path}[{i}].zeta [1]"]]) == mode["zeta"]
        f_n = float(row[col["reference[3].f_n [Hz]"]])
        assert f"{f_n:.6g}" in next(b for b in block if float(b.split()[0]) == mh)
