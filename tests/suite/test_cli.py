"""CLI: `mbsuite hardcases`, `mbsuite workprecision`, and --executor/--scheduler/--store on sweeps."""

from __future__ import annotations

import json

from mbsuite import hardcases
from mbsuite.cli import main


def test_hardcases_listing_json(capsys):
    assert main(["hardcases", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["counts"]["total"] == len(hardcases.registry()) == len(data["cases"])
    assert sum(data["counts"]["by_model"].values()) == len(hardcases.registry())
    assert {"name", "hard", "scene", "asserts"} <= set(data["cases"][0])


def test_hardcases_run_one_and_model_filter(capsys):
    assert main(["hardcases", "--run", "--name", "coupler_ey_to_zero", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    (case,) = data["cases"]
    assert case["passed"] and all(c["ok"] for c in case["checks"]) and data["counts"]["passed"] == 1
    assert main(["hardcases", "--model", "nosuch"]) == 2
    assert "no hard cases" in capsys.readouterr().err


def test_workprecision_writes_table_csv_png(tmp_path, capsys):
    out = tmp_path / "wp"
    assert main(["workprecision", "rotational/coupled_clutches", "--quick", "--repeats", "1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "cheapest setting" in text and "event-exact DOP853" in text
    assert (out / "workprecision.csv").stat().st_size > 0 and (out / "workprecision.png").stat().st_size > 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["results"]["rows"] and summary["scene"]["model"] == "rotational"
    assert main(["workprecision", "rotational/coupled_clutches", "--repeats", "0"]) == 2


def _kinds(lines: list[str]) -> list[str]:
    """The record types of a sweep store's lines (header, claim, result)."""
    return [json.loads(x)["body"]["type"] for x in lines]


def test_freqresp_store_resumes_and_dask_needs_scheduler(tmp_path, capsys):
    store = tmp_path / "fr.jsonl"
    argv = ["freqresp", "pantograph", "--methods", "mujoco", "--f-min", "4", "--f-max", "4.5", "--workers", "1",
            "--store", str(store), "--json"]
    assert main(argv) == 0
    first = json.loads(capsys.readouterr().out)
    lines = store.read_text().splitlines()
    assert _kinds(lines).count("result") == 4  # one result per (frequency, method): 2 frequencies x (with, without
    # Coulomb friction)
    assert main(argv) == 0  # everything is in the store: nothing recomputed, same answer
    again = json.loads(capsys.readouterr().out)
    assert store.read_text().splitlines() == lines
    assert again["response"] == first["response"]
    assert main(["freqresp", "pantograph", "--executor", "dask"]) == 2
    assert "scheduler" in capsys.readouterr().err


def test_sweep_command_grid_store_and_errors(tmp_path, capsys):
    store = tmp_path / "s.jsonl"
    argv = ["sweep", "iftomm/fourbar", "--vary", "input.rate=4,6", "--vary", "solver.duration=0.5",
            "--signals", "input_angle", "--workers", "2", "--store", str(store), "--json"]
    assert main(argv) == 0
    data = json.loads(capsys.readouterr().out)
    pts = data["points"]
    assert [p["values"]["input.rate"] for p in pts] == [4.0, 6.0]
    # a faster start turns the crank further in the same time
    assert pts[1]["signals"]["input_angle"]["max"] > pts[0]["signals"]["input_angle"]["max"]
    assert _kinds(store.read_text().splitlines()).count("result") == 2
    assert main(["sweep", "iftomm/fourbar", "--vary", "rate=1,2"]) == 2
    assert "SECTION.KEY" in capsys.readouterr().err
    assert main(["sweep", "iftomm/fourbar", "--vary", "params.nosuch=1"]) == 2
    assert "unknown parameter" in capsys.readouterr().err


def test_list_shows_each_models_paths_and_groups(capsys):
    from mbsuite import model_specs
    from mbsuite.cli import build_parser

    assert main(["list", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for name, spec in model_specs().items():
        paths = data[name]["paths"]
        assert list(paths) == list(spec.engines) == data[name]["engines"]
        assert all(paths[k] == {"label": p.label, "what": p.what} for k, p in spec.paths.items())
    assert main(["list"]) == 0
    text = capsys.readouterr().out
    assert all(f"path {k}" in text and p.what[:20] in text for k, p in model_specs()["iftomm"].paths.items())
    groups = build_parser().parse_args(["list"]).cli_groups  # what each model's register() named
    assert groups["pantograph"] == "pantograph" and groups["coupler"] == "coupler"
    assert all(f"mbsuite {g} ..." in data[m]["analyses"] for m, g in groups.items())


def test_engine_override_takes_a_path_key_or_label_and_names_the_flag(capsys):
    from argparse import Namespace

    from mbsuite.cli.options import load

    for engine in ("reference", "pinocchio"):  # the path's key or its label
        assert load(Namespace(scene="iftomm/fourbar", engine=engine)).solver.engine == "reference"
    assert main(["run", "iftomm/fourbar", "--engine", "bullet"]) == 2
    err = capsys.readouterr().err
    assert "--engine 'bullet'" in err and "'mujoco'" in err and "'pinocchio'" in err
