VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test bench bench-layered lint clean

$(STAMP): pyproject.toml
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev]'
	touch $(STAMP)

run: $(STAMP)
	$(VENV)/bin/plantmech inverse examples/sugarcane_seeder.toml --out out/sugarcane_seeder --verify
	$(VENV)/bin/plantmech forward examples/sugarcane_table4.toml --out out/sugarcane_table4
	$(VENV)/bin/plantmech forward examples/rice_transplanter.toml --out out/rice_transplanter

test: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(PY) -m pytest

bench: $(STAMP)
	$(PY) benchmarks/bench.py

bench-layered: $(STAMP)
	$(PY) benchmarks/bench.py --layered

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks

clean:
	rm -rf out .pytest_cache
