# mbsuite — set-up and entry points. `make demo` and `make test` work on a fresh machine.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
export MPLBACKEND ?= Agg

.PHONY: demo test test-slow lint bench mutants corpus docs clean

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

demo: $(STAMP)  ## the headline in ~1 min: pantograph frequency response, EN 50318 table; files in out/demo/
	$(BIN)/python scripts/demo.py --out out/demo

test: $(STAMP)  ## default suite (slow studies excluded)
	$(BIN)/python -m pytest -q

test-slow: $(STAMP)  ## long studies only
	$(BIN)/python -m pytest -q -m slow

lint: $(STAMP)
	$(BIN)/ruff check mbsuite tests scripts

bench: $(STAMP)  ## benchmarks (ratios measured side by side in one run; not tests)
	$(BIN)/python scripts/bench_core.py
	$(BIN)/python scripts/bench_paths.py
	$(BIN)/python scripts/bench_sweep.py

docs: $(STAMP)  ## the documentation site (API reference, model pages, gallery) -> out/site/; warnings are errors
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	$(BIN)/python scripts/build_docs.py

mutants: $(STAMP)  ## seeded physics defects, one at a time, against the default suite (tens of minutes)
	$(BIN)/python scripts/mutants.py --json out/mutants.json

corpus: $(STAMP)  ## the hostile robustness corpus: every outcome classified (about 15 minutes on 2 cores)
	$(BIN)/python scripts/robustness_corpus.py --workers 2 --json-out out/robustness_corpus.json

clean:
	rm -rf $(VENV) out .pytest_cache
