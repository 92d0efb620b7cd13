# The two commands of the README: `make demo` and `make test`. Each sets everything up first.
VENV ?= .venv
BIN := $(VENV)/bin
export VENV

.PHONY: setup demo test lint typecheck unit benchmark clean

setup:
	@bash scripts/setup.sh

# The manual's §3 example, end to end: check it, run it against MuJoCo in virtual time, write a
# trace (Foxglove), a plot, a picture and the document; the last line says whether the box was placed.
DEMO_OUT ?= demo-output
demo: setup
	$(BIN)/earl check --verbose examples/pick_and_place
	$(BIN)/earl doc examples/pick_and_place -o $(DEMO_OUT)/site
	EARL_SIM_OUTPUT=$(DEMO_OUT) $(BIN)/earl run examples/pick_and_place --no-progress \
		--trace $(DEMO_OUT)/pick_and_place.mcap --plot $(DEMO_OUT)/pick_and_place.png

test: setup
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/ruff format --check src tests benchmarks
	$(BIN)/mypy
	$(BIN)/pytest

benchmark: setup
	$(BIN)/python benchmarks/run.py

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache build src/*.egg-info
