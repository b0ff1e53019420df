# Two commands for a fresh machine with Python >= 3.11 and pip:
#   make run    create .venv if missing, install, run the main job on the built-in default
#   make test   same environment, run the (fast) test suite and the linter
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= flatcontact-run
# two workers (the 2-core machine), one test file per worker at a time: a module's fixtures
# are built once; `make test PYTEST_ARGS=` runs the suite in one process
PYTEST_ARGS ?= -n 2 --dist loadfile

.PHONY: run test test-all lint bench readme clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

run: $(STAMP)
	$(BIN)/flatcontact run --out $(OUT)

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/python -m pytest -q $(PYTEST_ARGS)

test-all: $(STAMP)
	$(BIN)/python -m pytest -q -m "" $(PYTEST_ARGS)

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks

bench: $(STAMP)
	$(BIN)/python -m benchmarks

# the README's run and test figures from benchmarks/run_record.json
readme: $(STAMP)
	$(BIN)/python -m benchmarks.readme_block

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache
