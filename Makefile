# mbsuite — set-up and entry points. `make demo` and `make test` work on a fresh machine.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# the versions the suite last passed with (`make lock`), and the lowest versions pyproject.toml allows
TESTED := constraints/tested.txt
LOWEST := constraints/lowest.txt
LOW_VENV := .venv-lowest
LOW_STAMP := $(LOW_VENV)/.installed
export MPLBACKEND ?= Agg

.PHONY: demo test test-slow test-perturbed test-lowest lock lint bench mutants corpus docs clean

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): $(BIN)/python pyproject.toml $(TESTED)
	$(BIN)/python -m pip install --quiet -c $(TESTED) -e ".[dev]"
	touch $(STAMP)

# a venv of its own, rebuilt whole when the bounds change, so that nothing newer is left over from an earlier set
$(LOW_STAMP): pyproject.toml $(LOWEST)
	rm -rf $(LOW_VENV)
	$(PY) -m venv $(LOW_VENV)
	$(LOW_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(LOW_VENV)/bin/python -m pip install --quiet -c $(LOWEST) -e ".[test]"
	touch $(LOW_STAMP)

demo: $(STAMP)  ## the headline in ~1 min: pantograph frequency response, EN 50318 table; files in out/demo/
	$(BIN)/python scripts/demo.py --out out/demo

test: $(STAMP)  ## default suite (slow studies excluded)
	$(BIN)/python -m pytest -q -n auto --dist worksteal

test-slow: $(STAMP)  ## long studies only
	$(BIN)/python -m pytest -q -m slow

# the tests that read digit-sensitive quantities (marker `rounding`), again with every input perturbed by seeded relative
# draws of 1e-12 ... 1e-10: another machine's rounding, emulated (tests/conftest.py, docs/reproducibility.md)
PERTURB_SEEDS ?= 1 2 3 4 5 6
test-perturbed: $(STAMP)  ## the `rounding` tests under seeded 1e-12...1e-10 input perturbations, one run per seed
	@status=0; for s in $(PERTURB_SEEDS); do \
	  $(BIN)/python -m pytest -q -n auto --dist worksteal --perturb 1e-12:1e-10 --perturb-seed $$s || status=1; \
	done; exit $$status

test-lowest: $(LOW_STAMP)  ## default suite at the lowest versions pyproject.toml allows, in .venv-lowest
	$(LOW_VENV)/bin/python -m pip list --format=freeze | grep -iE '^(numpy|scipy|matplotlib|distributed|tqdm|mujoco|pin|pytest|hypothesis|pandas)=='
	$(LOW_VENV)/bin/python -m pytest -q -n auto --dist worksteal

lock:  ## constraints/tested.txt <- the versions installed in .venv (after `make test` passed there)
	@test -f $(STAMP) || { echo "make lock: no installed .venv; run make test first" >&2; exit 1; }
	{ echo "# Versions make test last passed with, written by make lock from .venv (docs/dependencies.md)"; \
	  $(BIN)/python -m pip freeze --exclude-editable; } > $(TESTED).tmp
	mv $(TESTED).tmp $(TESTED)

lint: $(STAMP)
	$(BIN)/ruff check mbsuite tests scripts

bench: $(STAMP)  ## benchmarks (ratios measured side by side in one run; not tests)
	$(BIN)/python scripts/bench_core.py
	$(BIN)/python scripts/bench_paths.py
	$(BIN)/python scripts/bench_sweep.py

DOCS_FLAGS ?=
docs: $(STAMP)  ## the documentation site -> out/site/ (figures cached in out/gallery-cache, studies stored in docs/gallery-stores; DOCS_FLAGS=--rebuild)
	$(BIN)/python -m pip install --quiet -c $(TESTED) -e ".[docs]"
	$(BIN)/python scripts/build_docs.py $(DOCS_FLAGS)

mutants: $(STAMP)  ## seeded physics defects, one at a time: each caught by a physics assertion? (an hour or more)
	$(BIN)/python scripts/mutants.py --json out/mutants.json --doc docs/mutations.md

corpus: $(STAMP)  ## the hostile robustness corpus: every outcome classified (about 15 minutes on 2 cores)
	$(BIN)/python scripts/robustness_corpus.py --workers 2 --json-out out/robustness_corpus.json

clean:
	rm -rf $(VENV) $(LOW_VENV) .native-cache .native-cache-lowest out .pytest_cache
