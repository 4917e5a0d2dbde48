"""The documentation build's figure cache (scripts/build_docs.py): the key of a gallery command changes when the
command or an input it reads changes, and not otherwise; a cached entry is reused without running its command, a
changed key or `--rebuild` runs it again. No mkdocs and no mbsuite command runs here: a fake repository and a fake
command stand in."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def bd():
    spec = importlib.util.spec_from_file_location("build_docs", ROOT / "scripts" / "build_docs.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["build_docs"] = mod
    spec.loader.exec_module(mod)
    yield mod
    sys.modules.pop("build_docs", None)


@pytest.fixture
def repo(tmp_path):
    """A fake checkout (not a git work tree): two model packages with scenes, and mbsuite/analysis."""
    for model in ("alpha", "beta"):
        d = tmp_path / "mbsuite" / "models" / model
        (d / "scenes").mkdir(parents=True)
        (d / "__init__.py").write_text(f"# {model}\n")
        (d / "scenes" / "one.toml").write_text(f'model = "{model}"\n[line]\nfile = "../lines/l.toml"\n')
        (d / "scenes" / "two.toml").write_text(f'model = "{model}"\n')
        (d / "lines").mkdir()
        (d / "lines" / "l.toml").write_text("spans = [1, 2]\n")
    (tmp_path / "mbsuite" / "analysis").mkdir()
    (tmp_path / "mbsuite" / "analysis" / "study.py").write_text("X = 1\n")
    (tmp_path / "mbsuite" / "engines").mkdir()
    (tmp_path / "mbsuite" / "engines" / "core.py").write_text("Y = 1\n")
    return tmp_path


CMD = "mbsuite run alpha/one --speed 250"


def test_key_is_stable(bd, repo):
    assert bd.cache_key(CMD, repo) == bd.cache_key(CMD, repo)
    assert len(bd.cache_key(CMD, repo)) == 64


def test_key_changes_with_the_command(bd, repo):
    assert bd.cache_key(CMD, repo) != bd.cache_key(CMD.replace("250", "300"), repo)
    assert bd.cache_key(CMD, repo) != bd.cache_key("mbsuite run alpha/two --speed 250", repo)


@pytest.mark.parametrize("changed", ["alpha/scenes/one.toml", "alpha/lines/l.toml", "alpha/__init__.py"])
def test_key_changes_with_an_input_it_reads(bd, repo, changed):
    before = bd.cache_key(CMD, repo)
    f = repo / "mbsuite" / "models" / changed
    f.write_text(f.read_text() + "# edited\n")
    assert bd.cache_key(CMD, repo) != before


def test_key_changes_with_the_analysis_package(bd, repo):
    before = bd.cache_key(CMD, repo)
    (repo / "mbsuite" / "analysis" / "study.py").write_text("X = 2\n")
    assert bd.cache_key(CMD, repo) != before


def test_key_ignores_what_the_command_does_not_read(bd, repo):
    """Another model's scene or code, the shared code outside the key (documented: use --rebuild) and the model's own
    documentation."""
    before = bd.cache_key(CMD, repo)
    for f in ("models/beta/scenes/one.toml", "models/beta/__init__.py", "engines/core.py", "models/alpha/README.md"):
        (repo / "mbsuite" / f).write_text("# edited\n")
    assert bd.cache_key(CMD, repo) == before


def test_key_follows_a_model_the_package_names(bd, repo):
    """alpha's code naming the model "beta" (a registry look-up, say) puts beta's files into alpha's keys."""
    (repo / "mbsuite" / "models" / "alpha" / "under.py").write_text('SPEC = get_model("beta")\n')
    before = bd.cache_key(CMD, repo)
    (repo / "mbsuite" / "models" / "beta" / "__init__.py").write_text("# edited\n")
    assert bd.cache_key(CMD, repo) != before


def test_key_of_a_command_reading_another_entry_follows_that_entry(bd, repo):
    cmd = "mbsuite compare out/docs-figures/gallery_0 out/docs-figures/gallery_1"
    assert bd.cache_key(cmd, repo, {0: "a", 1: "b"}) != bd.cache_key(cmd, repo, {0: "a", 1: "c"})
    assert bd.cache_key(cmd, repo, {0: "a", 1: "b", 2: "x"}) == bd.cache_key(cmd, repo, {0: "a", 1: "b", 2: "y"})


def test_the_gallery_keys_are_computed(bd):
    keys = bd._keys()
    assert len(keys) == len(bd.GALLERY) and len(set(keys)) == len(keys)


class FakeCommand:
    """Stands in for `_run`: writes the figure into a subdirectory of --out and counts its calls."""

    def __init__(self):
        self.calls = 0

    def __call__(self, cmd, d):
        self.calls += 1
        (d / "sub").mkdir(parents=True)
        (d / "sub" / "fig.png").write_bytes(b"png %d" % self.calls)
        (d / "summary.json").write_text("{}")


def test_an_entry_is_run_once_then_reused(bd, tmp_path):
    cache, run = tmp_path / "cache", FakeCommand()
    meta = bd._entry("mbsuite run alpha", ["fig.png"], tmp_path / "out" / "g0", "k1", cache, run=run)
    assert run.calls == 1 and not meta["reused"]
    stored = json.loads((cache / "k1" / "meta.json").read_text())
    assert stored["command"] == "mbsuite run alpha" and stored["key"] == "k1"
    assert {"cpu_seconds", "wall_seconds", "date"} <= set(stored)
    assert (cache / "k1" / "fig.png").read_bytes() == b"png 1"
    assert (cache / "k1" / "out" / "summary.json").is_file()  # the whole --out directory, for later entries

    again = bd._entry("mbsuite run alpha", ["fig.png"], tmp_path / "out" / "g0", "k1", cache, run=run)
    assert run.calls == 1 and again["reused"] and again["cpu_seconds"] == stored["cpu_seconds"]


def test_a_reused_entry_restores_its_output_directory(bd, tmp_path):
    cache, run = tmp_path / "cache", FakeCommand()
    bd._entry("mbsuite run alpha", ["fig.png"], tmp_path / "a", "k1", cache, run=run)
    bd._entry("mbsuite run alpha", ["fig.png"], tmp_path / "b", "k1", cache, run=run)
    assert run.calls == 1 and (tmp_path / "b" / "summary.json").is_file()


def test_a_changed_key_or_rebuild_runs_again(bd, tmp_path):
    cache, run = tmp_path / "cache", FakeCommand()
    d = tmp_path / "out" / "g0"
    bd._entry("mbsuite run alpha", ["fig.png"], d, "k1", cache, run=run)
    bd._entry("mbsuite run alpha --x", ["fig.png"], d, "k2", cache, run=run)
    assert run.calls == 2 and (cache / "k1").is_dir() and (cache / "k2").is_dir()
    meta = bd._entry("mbsuite run alpha", ["fig.png"], d, "k1", cache, rebuild=True, run=run)
    assert run.calls == 3 and not meta["reused"] and (cache / "k1" / "fig.png").read_bytes() == b"png 3"


def test_an_incomplete_entry_is_not_reused(bd, tmp_path):
    cache, run = tmp_path / "cache", FakeCommand()
    bd._entry("mbsuite run alpha", ["fig.png"], tmp_path / "g", "k1", cache, run=run)
    (cache / "k1" / "fig.png").unlink()
    bd._entry("mbsuite run alpha", ["fig.png"], tmp_path / "g", "k1", cache, run=run)
    assert run.calls == 2


def test_a_missing_figure_is_an_error_and_caches_nothing(bd, tmp_path):
    cache, run = tmp_path / "cache", FakeCommand()
    with pytest.raises(SystemExit, match="wrote no other.png"):
        bd._entry("mbsuite run alpha", ["other.png"], tmp_path / "g", "k1", cache, run=run)
    assert bd._cached(cache, "k1", ["other.png"]) is None


def test_the_gallery_page_shows_the_command_and_its_cpu_time(bd, tmp_path, monkeypatch):
    monkeypatch.setattr(bd, "DOCS", tmp_path)
    monkeypatch.setattr(bd, "GALLERY", [("T", "mbsuite run alpha", ["fig.png"], "what"),
                                        ("U", "mbsuite run beta", ["fig.png"], "more")])
    bd._gallery_page([{"cpu_seconds": 12.345, "date": "2026-11-28T20:00:00+00:00"}, None])
    page = (tmp_path / "gallery.md").read_text()
    assert "mbsuite run alpha --out DIR" in page and "CPU time: 12.3 s (made 2026-11-28)" in page
    assert page.count("CPU time: ") == 1 and "![T](gallery/00_fig.png)" in page


class FakeStudy(FakeCommand):
    """Stands in for `_run` on a study entry: reads the `--store FILE` it is given, computes (appends a claim and a
    result record per point) only the points the store lacks, and draws the figure from the results."""

    POINTS = ("p1", "p2", "p3")

    def __init__(self):
        super().__init__()
        self.computed = 0

    def __call__(self, cmd, d):
        words = cmd.split()
        assert words.count("--store") == 1
        store = Path(words[words.index("--store") + 1])
        text = store.read_text() if store.is_file() else ""
        have = {json.loads(x)["body"]["key"] for x in text.splitlines() if '"type":"result"' in x}
        lines = [] if text else ['{"body":{"type":"header","format":"mbsuite-sweep-store","version":1},"sha256":"h"}']
        for p in self.POINTS:
            if p not in have:
                self.computed += 1
                lines.append(f'{{"body":{{"type":"claim","key":"{p}","owner":"o"}},"sha256":"c"}}')
                lines.append(f'{{"body":{{"type":"result","key":"{p}","result":1}},"sha256":"r"}}')
        with store.open("a") as f:
            f.writelines(x + "\n" for x in lines)
        super().__call__(cmd, d)


def _study(bd, tmp_path, run, key="k1", cache="cache", rebuild=False):
    return bd._entry("mbsuite optimise alpha/one", ["fig.png"], tmp_path / "out" / "g0", key, tmp_path / cache,
                     rebuild, run=run, store=tmp_path / "stores" / "study.jsonl", label="entry 0",
                     work=tmp_path / "work" / "study.jsonl")


def test_a_study_writes_its_store_and_manifest(bd, tmp_path):
    (tmp_path / "stores").mkdir()
    run = FakeStudy()
    meta = _study(bd, tmp_path, run)
    assert run.computed == 3 and meta["store"].endswith("study.jsonl") and "drawn_cpu_seconds" not in meta
    store = tmp_path / "stores" / "study.jsonl"
    lines = store.read_text().splitlines()
    assert len(lines) == 4 and '"type":"header"' in lines[0] and not any('"claim"' in x for x in lines)
    man = json.loads((tmp_path / "stores" / "study.json").read_text())
    assert man["key"] == "k1" and man["command"] == "mbsuite optimise alpha/one" and man["records"] == 3
    assert man["bytes"] == store.stat().st_size and man["cpu_seconds"] == meta["cpu_seconds"]
    assert bd._valid_store(store, "k1") == man and bd._valid_store(store, "k2") is None


def test_a_valid_store_is_used_on_a_fresh_checkout(bd, tmp_path, capsys):
    """No figure cache (a fresh clone): the figure is drawn from the committed results, nothing is computed, the
    committed store stays as it is and the entry shows the study's CPU time."""
    (tmp_path / "stores").mkdir()
    _study(bd, tmp_path, FakeStudy())
    store = tmp_path / "stores" / "study.jsonl"
    before, man = store.read_bytes(), json.loads((tmp_path / "stores" / "study.json").read_text())
    man["cpu_seconds"] = 1234.5
    (tmp_path / "stores" / "study.json").write_text(json.dumps(man))
    (tmp_path / "work" / "study.jsonl").unlink()
    run = FakeStudy()
    meta = _study(bd, tmp_path, run, cache="fresh-cache")
    assert run.calls == 1 and run.computed == 0 and not meta["reused"]
    assert meta["cpu_seconds"] == 1234.5 and meta["date"] == man["date"] and "drawn_cpu_seconds" in meta
    assert store.read_bytes() == before
    assert "recomputing" not in capsys.readouterr().err
    again = _study(bd, tmp_path, run, cache="fresh-cache")
    assert run.calls == 1 and again["reused"] and again["cpu_seconds"] == 1234.5


def test_a_stale_store_is_discarded_and_recomputed(bd, tmp_path, capsys):
    (tmp_path / "stores").mkdir()
    _study(bd, tmp_path, FakeStudy())
    man = json.loads((tmp_path / "stores" / "study.json").read_text())
    man["wall_seconds"] = 600
    (tmp_path / "stores" / "study.json").write_text(json.dumps(man))
    run = FakeStudy()
    meta = _study(bd, tmp_path, run, key="k2")
    assert run.computed == 3 and "drawn_cpu_seconds" not in meta  # nothing of the old store served
    assert "entry 0: inputs changed, recomputing (about 10 min)" in capsys.readouterr().err
    assert json.loads((tmp_path / "stores" / "study.json").read_text())["key"] == "k2"
    assert bd._valid_store(tmp_path / "stores" / "study.jsonl", "k2") is not None


def test_a_damaged_store_or_rebuild_recomputes(bd, tmp_path, capsys):
    (tmp_path / "stores").mkdir()
    _study(bd, tmp_path, FakeStudy())
    store = tmp_path / "stores" / "study.jsonl"
    store.write_text(store.read_text().replace('"result":1', '"result":2'))
    run = FakeStudy()
    _study(bd, tmp_path, run, cache="other")  # the figure is not cached there
    assert run.computed == 3 and "stored results damaged" in capsys.readouterr().err
    run = FakeStudy()
    _study(bd, tmp_path, run, rebuild=True)
    assert run.computed == 3 and "--rebuild" in capsys.readouterr().err


def test_a_cached_figure_without_a_valid_store_is_made_again(bd, tmp_path):
    """The committed store must hold what the figure shows, or a fresh clone could not draw it."""
    (tmp_path / "stores").mkdir()
    _study(bd, tmp_path, FakeStudy())
    (tmp_path / "stores" / "study.jsonl").unlink()
    run = FakeStudy()
    meta = _study(bd, tmp_path, run)
    assert run.calls == 1 and not meta["reused"] and (tmp_path / "stores" / "study.json").is_file()


def test_an_interrupted_computation_resumes_from_its_work_store(bd, tmp_path, capsys):
    (tmp_path / "stores").mkdir()
    work = tmp_path / "work" / "study.jsonl"

    def interrupted(cmd, d):
        FakeStudy.__call__(FakeStudy(), cmd, d)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _study(bd, tmp_path, interrupted)
    assert work.is_file() and not (tmp_path / "stores" / "study.json").exists()
    run = FakeStudy()
    _study(bd, tmp_path, run)
    assert run.computed == 0 and "resuming from the 3 points" in capsys.readouterr().err
    with pytest.raises(KeyboardInterrupt):
        _study(bd, tmp_path, interrupted, key="k3")
    run = FakeStudy()
    _study(bd, tmp_path, run, key="k4")  # another key: the work store's points are not the ones wanted
    assert run.computed == 3


def test_the_gallery_page_of_a_study_says_where_its_results_are(bd, tmp_path, monkeypatch):
    monkeypatch.setattr(bd, "DOCS", tmp_path)
    monkeypatch.setattr(bd, "GALLERY", [("T", "mbsuite optimise alpha", ["fig.png"], "what")])
    bd._gallery_page([{"cpu_seconds": 300.0, "date": "2026-11-28T20:00:00+00:00", "store": "docs/s/t.jsonl"}])
    page = (tmp_path / "gallery.md").read_text()
    assert "CPU time: 300.0 s (computed 2026-11-28; the figure is drawn from the study's stored results, " \
           "`docs/s/t.jsonl`)" in page


def test_the_studies_are_gallery_entries(bd):
    assert bd.STUDIES <= {title for title, *_ in bd.GALLERY}
    assert len({bd._slug(t) for t in bd.STUDIES}) == len(bd.STUDIES)
