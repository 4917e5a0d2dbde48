"""Progress and cost of long work (`mbsuite.progress`): the plan said before the work with its run count counted by
hand, the estimate after the first run, the budget, the partial summary on an interrupt, --quiet, and the command
line's one-line warnings."""

from __future__ import annotations

import io
import json
import math
import subprocess
import sys

import pytest

from mbsuite import progress
from mbsuite.analysis import optimise, sensitivity
from mbsuite.analysis.sweep import run_sweep
from mbsuite.cli import main


def _square(p: dict) -> dict:
    return {"y": (p["x.a"] - 0.3) ** 2 + 0.1 * p["x.b"]}


def _twice(x: float) -> float:
    return 2 * x


def _lines(stream: io.StringIO) -> list[str]:
    return [ln for ln in stream.getvalue().splitlines() if ln.strip()]


def test_sweep_states_its_runs_and_counts_each_once():
    out = io.StringIO()
    with progress.study("sweep", stream=out, bar=False) as st:
        res = run_sweep(_twice, [1.0, 2.0, 3.0, 4.0, 5.0], workers=1)
    assert res == [2.0, 4.0, 6.0, 8.0, 10.0]
    lines = _lines(out)
    assert lines[0] == "mbsuite sweep: 5 runs, one at a time; time estimate after the first"
    assert lines[1].startswith("mbsuite sweep: first run finished after ") and lines[1].endswith("for 5 runs")
    assert len(lines) == 2
    assert st.last is not None and st.last.done == 5 and len(st.last.finished) == 5


def test_optimise_plan_counts_scipy_generations_and_reports_every_evaluation():
    out = io.StringIO()
    k, maxiter, popsize = 2, 3, 4  # scipy's population: max(5, popsize x factors) = 8 designs a generation
    with progress.study("optimise", stream=out, bar=False) as st:
        res = optimise.run(_square, ["x.a=0:1", "x.b=0:1"], objective="y", maxiter=maxiter, popsize=popsize, tol=1e-12,
                           workers=1)
    runs = (maxiter + 1) * max(5, popsize * k)
    assert _lines(out)[0] == f"mbsuite optimise: up to {runs} runs, one at a time; time estimate after the first"
    assert st.last.done == len(res.evaluations)  # every evaluation the study logs reached the plan, once
    assert len(res.evaluations) <= runs


def test_optimise_plan_counts_the_start_design_in_the_first_generation():
    """A start design is scipy's x0, a member of the first generation run once: the plan's count is the evaluations'
    (no "up to 13 runs" for 12 evaluations)."""
    out = io.StringIO()
    with progress.study("optimise", stream=out, bar=False):
        res = optimise.run(_square, ["x.a=0:1", "x.b=0:1"], objective="y", maxiter=1, popsize=3, tol=1e-12,
                           workers=1, start={"x.a": 0.5, "x.b": 0.5})
    assert len(res.evaluations) == 12 == optimise.plan(2, 1, 1, 3, True, 1)[1]  # 2 generations of 6 designs
    assert _lines(out)[0].startswith("mbsuite optimise: up to 12 runs")
    assert res.table().splitlines()[0].endswith("12 evaluations, seed 0")


def test_over_budget_in_the_first_generation_names_a_smaller_popsize():
    """2 factors, popsize 20: 40 designs a generation, 80 for --maxiter 1; a budget of 24 runs (measured: the first
    run 2.5 s, 60 s) fits two generations of 12 designs: --popsize 6 --maxiter 1."""
    plan = progress.Plan("optimise", 840, 1, upto=True, cheaper=optimise.cheaper(2, 1, 20, True))
    st = progress.Study("optimise", budget=60.0, stream=io.StringIO(), bar=False)
    st.start(plan)
    progress_time = plan.started + 2.5
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(progress.time, "perf_counter", lambda: progress_time)
        with pytest.raises(progress.OverBudget) as exc:
            st.update(1)
    assert "a cheaper study: --popsize 6 --maxiter 1" in str(exc.value)
    assert optimise.cheaper(2, 1, 20, True)(9) is None  # not even two generations of 5 designs


def test_sensitivity_plan_is_the_sample_size():
    out = io.StringIO()
    with progress.study("sensitivity", stream=out, bar=False) as st:
        res = sensitivity.run(_square, ["x.a=0:1", "x.b=0:1"], method="sobol", n=8, workers=1)
    assert len(res.samples) == 8 * (2 + 2)  # Saltelli without second order: n (k + 2)
    assert _lines(out)[0].startswith("mbsuite sensitivity: sobol sensitivity: 32 runs (n = 8 x 4), one at a time")
    assert st.last.done == 32


def test_over_budget_stops_with_yes_and_a_cheaper_setting_that_fits(monkeypatch):
    plan = progress.Plan("optimise", 210, 2, upto=True, cheaper=optimise.cheaper(2, 1, 5, False))
    st = progress.Study("optimise", budget=60.0, stream=io.StringIO(), bar=False)
    st.start(plan)
    monkeypatch.setattr(progress.time, "perf_counter", lambda: plan.started + 3.9)  # the first run took 3.9 s
    with pytest.raises(progress.OverBudget) as exc:
        st.update(1)
    text = str(exc.value)
    # 3.9 s x ceil(210 / 2) = 409.5 s; 60 s fit 15 rounds x 2 = 30 runs = 3 generations of 10: --maxiter 2
    assert "about 6.8 min for up to 210 runs" in text and "--yes" in text and "--maxiter 2" in text
    st.confirmed = True  # --yes: no stop
    plan.done = 0
    st.update(1)


def test_interrupt_keeps_the_finished_runs_in_a_partial_summary(tmp_path):
    def stop_at_third(x: float) -> float:
        if x == 3.0:
            raise KeyboardInterrupt
        return 2 * x

    with pytest.raises(KeyboardInterrupt), progress.study("sweep", out=str(tmp_path), stream=io.StringIO(),
                                                          bar=False) as st:
        run_sweep(stop_at_third, [1.0, 2.0, 3.0, 4.0], workers=1)
    said = st.keep_partial()
    data = json.loads((tmp_path / "partial_summary.json").read_text())
    assert data["finished_runs"] == 2 and data["planned_runs"] == 4
    assert [r["result"] for r in data["runs"]] == [2.0, 4.0]
    assert str(tmp_path / "partial_summary.json") in said


def test_nested_sweeps_are_not_runs_of_the_plan():
    def inner(x: float) -> float:
        return sum(run_sweep(_twice, [x, x], workers=1))

    out = io.StringIO()
    with progress.study("study", stream=out, bar=False) as st:
        assert run_sweep(inner, [1.0, 2.0, 3.0], workers=1) == [4.0, 8.0, 12.0]
    assert st.last.runs == 3 and st.last.done == 3
    assert _lines(out)[0].startswith("mbsuite study: sweep: 3 runs, one at a time")


def test_estimate_is_first_run_times_rounds():
    plan = progress.Plan("x", 7, 2)
    assert plan.estimate(3.0) == 3.0 * math.ceil(7 / 2)


def test_quiet_and_cli_lines(capsys, monkeypatch):
    monkeypatch.setenv("MBSUITE_PROGRESS", "1")  # the lines as on a terminal
    assert main(["sweep", "pantograph", "--vary", "input.frequency=2,4", "--workers", "1", "--quiet"]) == 0
    assert "runs" not in capsys.readouterr().err
    assert main(["sweep", "pantograph", "--vary", "input.frequency=2,4", "--workers", "1"]) == 0
    err = capsys.readouterr().err
    assert "mbsuite sweep: 2 runs, one at a time" in err


def test_budget_is_a_checked_input(capsys):
    assert main(["sweep", "pantograph", "--vary", "input.frequency=2,4", "--budget", "-1"]) == 2
    assert "--budget" in capsys.readouterr().err


def test_sensitivity_speed_conflicts_with_set_of_the_same_key(capsys):
    code = main(["sensitivity", "catenary/en50318", "--vary", "params.F0=100:140", "--speed", "250", "--set",
                 "input.speed=200"])
    assert code == 2
    err = capsys.readouterr().err
    assert "--speed" in err and "--set" in err


def test_warnings_are_one_line_each_once():
    code = ("import warnings\nfrom mbsuite.cli.output import one_line_warnings\nwith one_line_warnings():\n"
            "    for _ in range(3):\n        warnings.warn('a   warning\\n  over two lines', UserWarning)\n"
            "warnings.warn('after', UserWarning)\n")
    r = subprocess.run([sys.executable, "-W", "always", "-c", code], capture_output=True, text=True, check=True)
    lines = r.stderr.splitlines()
    assert lines[0] == "mbsuite: UserWarning: a warning over two lines"  # no source line, once
    assert "mbsuite" not in "".join(lines[1:]) and "after" in lines[1]  # Python's own format again afterwards


def test_weighted_estimate_scales_the_first_run_by_its_share_of_the_work():
    from mbsuite.analysis.errorestimate import cost
    from mbsuite.trust.estimate import Refinement

    ref = Refinement("params.element_length + solver.timestep", 2.0, 2.0, lambda sc, k: sc, "halved")
    w = tuple(cost(ref, k) for k in (0, -1, -2))
    assert w == (1.0, 0.25, 0.0625)  # mesh and step doubled: a quarter of the work per level
    plan = progress.Plan("error estimate", 3, 2, weights=w)
    # the 1/16 companion finished first after 1 s: the run is 16 s, the three on two workers at least 16 s
    assert plan.estimate(1.0, index=2) == 16.0
    plan = progress.Plan("error estimate", 3, 1, weights=w)
    assert plan.estimate(1.0, index=2) == pytest.approx(16.0 * (1 + 0.25 + 0.0625))


def test_a_sweep_inside_the_first_run_of_a_study_gives_its_estimate_and_budget(monkeypatch):
    """A study of 3 runs one at a time, each a sweep of 59 points one at a time: the first point after 5 s makes a
    run 59 x 5 = 295 s and the study 885 s, said and stopped over a 300 s budget before the study's first run ends."""
    out = io.StringIO()
    t0 = progress.time.perf_counter()
    with progress.study("freqresp", budget=300.0, stream=out, bar=False) as st, \
            progress.sweep_progress("study", 3, 1, None):  # the study's sweep: its runs are the plan's
        monkeypatch.setattr(progress.time, "perf_counter", lambda: t0)
        with progress.sweep_progress("frequency response", 59, 1, None) as report:
            monkeypatch.setattr(progress.time, "perf_counter", lambda: t0 + 5.0)
            with pytest.raises(progress.OverBudget) as exc:
                report(1)
    assert "about 4.9 min a run, 14.8 min for 3 runs" in _lines(out)[-1]
    assert "14.8 min" in str(exc.value) and "--yes" in str(exc.value)
    assert st.last.done == 0


def test_a_study_stopped_over_budget_keeps_its_finished_runs(tmp_path, capsys):
    """The budget stops a sweep after its first run: that run is in a partial summary under --out, and the one-line
    error says where."""
    code = main(["sweep", "pantograph", "--vary", "input.frequency=2,4,6,8", "--workers", "1", "--budget", "0.001",
                 "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "--yes" in err and "partial_summary.json" in err
    saved = json.loads((tmp_path / "partial_summary.json").read_text())
    assert saved["finished_runs"] >= 1 and saved["planned_runs"] == 4


def test_error_estimate_with_the_run_timed_is_judged_before_its_companions():
    """Refined companions after a run of 50 s: 16 + 4 times its work on two workers, at least the 16x one alone:
    800 s, said before any companion starts and over a 300 s budget stopped there (nothing of theirs has run)."""
    out = io.StringIO()
    st = progress.Study("catenary", budget=300.0, stream=out, bar=False)
    plan = progress.Plan("error estimate (refined companions)", 2, 2, detail="about 16 and 4 x the run's work",
                         weights=(16.0, 4.0), unit=50.0)
    assert plan.ahead() == 50.0 * max(20.0 / 2, 16.0)
    with pytest.raises(progress.OverBudget) as exc:
        st.start(plan)
    assert "about 13.3 min (the run took 50 s)" in _lines(out)[0]
    assert "about 13.3 min for 2 runs" in str(exc.value) and "--yes" in str(exc.value)
    assert st.plan is None and plan.done == 0
    st.confirmed = True  # --yes: the plan starts
    st.start(plan)
    assert st.plan is plan
    # coarse companions (1/4, 1/16) on two workers: the 1/4 one's time, 12.5 s, within the budget
    st2 = progress.Study("catenary", budget=300.0, stream=io.StringIO(), bar=False)
    st2.start(progress.Plan("error estimate (coarse companions)", 2, 2, weights=(0.25, 0.0625), unit=50.0))
    assert st2.plan.ahead() == pytest.approx(12.5)


@pytest.mark.parametrize("argv", [["catenary", "catenary/en50318"], ["run", "pantograph"]])
def test_error_estimate_over_budget_keeps_the_run_and_stops_before_its_companions(argv, tmp_path, capsys):
    """The run is printed and written (its summary.json says the estimate was not run), then exit 2 naming --yes."""
    code = main([*argv, "--error-estimate", "--budget", "0.001", "--out", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 2
    assert "above the budget" in err and "--yes" in err and len(err.strip().splitlines()) == 1
    assert (tmp_path / "summary.json").is_file() and "wrote" in out


@pytest.mark.parametrize("command", [["run"], ["sweep", "--vary", "params.F0=110,120"],
                                     ["sensitivity", "--vary", "params.F0=100:140"]])
def test_speed_means_input_speed_on_every_command(command, monkeypatch):
    """`--speed` sets input.speed wherever a scene has a speed (as on `catenary` and `optimise`); the command is
    stopped where its work starts, so nothing runs here."""
    from mbsuite.cli import sweep

    seen = {}

    def stop_at_run(scene, *a, **k):
        seen["speed"] = scene.to_dict()["input"]["speed"]
        raise KeyboardInterrupt

    def stop_at_points(fn, points, **k):
        seen["speed"] = points[0][0]["input"]["speed"]  # (the scene as a dict, the point's sections)
        raise KeyboardInterrupt

    monkeypatch.setattr("mbsuite.run", stop_at_run)
    monkeypatch.setattr("mbsuite.analysis.sensitivity.run", stop_at_run)
    monkeypatch.setattr(sweep, "run_sweep", stop_at_points)
    name, *rest = command
    assert main([name, "catenary/en50318", *rest, "--speed", "212.5"]) == 130
    assert seen["speed"] == 212.5
