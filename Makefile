# twin: two commands matter. `make demo` and `make test` both install what they need first.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test bench lint format install clean fuzz soak

# `make fuzz`: the file-input fuzz properties with many more cases (FUZZ_EXAMPLES per property).
FUZZ_EXAMPLES ?= 5000
# ... and the HTTP API fuzz (Schemathesis) with this many cases per operation.
FUZZ_API_EXAMPLES ?= 200

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e ".[test]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	PATH="$(abspath $(BIN)):$$PATH" bash scripts/demo.sh

# The browser test runs alone after the rest: SwiftShader renders its page on the CPU, and with
# both cores busy with other tests a frame could take longer than the test waits (and the
# spawn-to-page times the pieces test measures would measure the other tests).
BROWSER_TESTS = tests/twin_cli/view/test_view_browser.py tests/twin_cli/view/test_view_pieces_browser.py

test: $(STAMP)
	$(BIN)/python -m pytest -n 2 --dist loadgroup --timeout 300 -q $(addprefix --ignore=,$(BROWSER_TESTS))
	$(BIN)/python -m pytest --timeout 300 -q $(BROWSER_TESTS)

fuzz: $(STAMP)
	@start=$$(date +%s); \
	TWIN_FUZZ_EXAMPLES=$(FUZZ_EXAMPLES) TWIN_FUZZ_API_EXAMPLES=$(FUZZ_API_EXAMPLES) $(BIN)/python -m pytest tests/fuzz -q -p no:cacheprovider \
		--hypothesis-show-statistics; status=$$?; \
	seconds=$$(( $$(date +%s) - start )); \
	echo "fuzz: up to $$(( 3 * $(FUZZ_EXAMPLES) )) cases in $$seconds s"; exit $$status

bench: $(STAMP)
	$(BIN)/python -m benchmarks

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/lint-imports
	PYRIGHT_PYTHON_IGNORE_WARNINGS=1 $(BIN)/pyright converters/ twin_cli/world/

format: $(STAMP)
	$(BIN)/ruff check --fix .
	$(BIN)/ruff format .

clean:
	rm -rf $(VENV) build *.egg-info twin_out

# `make soak`: 4 clients drive one world for SOAK_MINUTES; fails on any error (not in `make test`).
SOAK_MINUTES ?= 10
soak: $(STAMP)
	$(BIN)/python -m benchmarks.soak --minutes $(SOAK_MINUTES)
