# The two commands of the README: `make demo` and `make test`. Each sets everything up first.
VENV ?= .venv
BIN := $(VENV)/bin
export VENV

.PHONY: setup demo test lint typecheck unit benchmark clean

setup:
	@bash scripts/setup.sh

demo: setup
	$(BIN)/earl check --verbose examples/pick_and_place/system.earl
	$(BIN)/earl fmt examples/pick_and_place/system.earl

test: setup
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/ruff format --check src tests benchmarks
	$(BIN)/mypy
	$(BIN)/pytest

benchmark: setup
	$(BIN)/python benchmarks/run.py

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache build src/*.egg-info
