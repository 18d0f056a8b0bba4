VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test test-quick bench bench-study bench-layered bench-design bench-pair lint clean fuzz docs

$(STAMP): pyproject.toml
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev]'
	touch $(STAMP)

# The main job on the bundled examples. The seeder's exit 4 is its design verdict ("not met",
# printed last with what fails: its gears cannot be cut, docs/manufacturability.md), not a
# failure of the run: make reports it and goes on. The published transplanter must end ok.
run: $(STAMP)
	$(VENV)/bin/plantmech design examples/sugarcane_seeder.toml --out out/sugarcane_seeder --force --quiet || test $$? -eq 4
	$(VENV)/bin/plantmech design examples/rice_transplanter.toml --out out/rice_transplanter --force --quiet

# The whole suite on both cores (pytest-xdist; each worker is handed one test at a time, the
# slow ones of tests/slow.txt first), the 20 slowest tests printed at the end.
PYTEST_XDIST := -n 2 --dist load --maxschedchunk 1
test: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(PY) -m pytest $(PYTEST_XDIST) --durations=20

# The quick loop for engineers: everything but the tests listed in tests/slow.txt and the
# wheel's install (tests/test_install.py, marked `install`). `make test` and CI still run
# everything.
test-quick: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(PY) -m pytest $(PYTEST_XDIST) -m "not slow and not install" --durations=10

bench: $(STAMP)
	$(PY) benchmarks/bench.py

# the Dask scaling alone: samples/s of the bundled tolerance studies on 1 and 2 workers
bench-study: $(STAMP)
	$(PY) benchmarks/bench.py --study-only --study-repeat 3

bench-layered: $(STAMP)
	$(PY) benchmarks/bench.py --layered

bench-design: $(STAMP)
	$(PY) benchmarks/bench.py --design

bench-pair: $(STAMP)
	$(PY) benchmarks/bench.py --pair --pair-runs 5

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks

clean:
	rm -rf out .pytest_cache

# Seeded fuzzer (tests/fuzzing.py): N mutated examples through inverse/forward/gears/optimize;
# writes out/fuzz/tally.json. CI runs its fixed-seed corpus in `make test`.
FUZZ_CASES ?= 10000
FUZZ_SEED ?= 0
fuzz: $(STAMP)
	$(PY) -m tests.fuzzing --cases $(FUZZ_CASES) --seed $(FUZZ_SEED) --out out/fuzz

docs: $(STAMP)
	$(PY) -m plantmech.design_reference > docs/design-file.md
