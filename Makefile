# gripsense — the two quick-start commands (see README.md)
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin

.PHONY: demo test test-fast test-under-load lint clean clean-cache browser examples

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.installed-all: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[all]'
	touch $@

$(VENV)/.installed-test: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[all,test]'
	touch $@ $(VENV)/.installed-all

demo: $(VENV)/.installed-all
	$(BIN)/gripsense demo

# headless Chromium for the report tests (Debian packages); installed when missing and root
browser:
	@if ! command -v chromium >/dev/null 2>&1 || ! command -v chromedriver >/dev/null 2>&1; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "installing chromium + chromium-driver (Debian) for the browser tests"; \
	    apt-get update -qq && apt-get install -y -qq chromium chromium-driver >/dev/null; \
	  else \
	    echo "note: no headless Chromium; the browser tests will say how to install it"; \
	  fi; \
	fi

# one worker per CPU; a file's tests stay on one worker (its fixtures are built once)
test: $(VENV)/.installed-test browser
	$(BIN)/python -m pytest -q -n auto --dist loadfile

# the full suite with two busy CPU hogs beside it: nothing in it may depend on timing or load
test-under-load: $(VENV)/.installed-test browser
	@$(BIN)/python -c 'while True: pass' & h1=$$!; \
	 $(BIN)/python -c 'while True: pass' & h2=$$!; \
	 trap 'kill $$h1 $$h2 2>/dev/null' EXIT INT TERM; \
	 $(BIN)/python -m pytest -q -n auto --dist loadfile

# the inner loop: everything but the end-to-end tests (`make test` is the full suite CI runs)
test-fast: $(VENV)/.installed-test
	$(BIN)/python -m pytest -q -n auto --dist loadfile -m "not slow"

lint: $(VENV)/.installed-test
	$(BIN)/ruff check src tests benchmarks examples
	$(BIN)/ruff format --check src tests benchmarks examples
	$(BIN)/mypy

# the examples gallery in full: figures into docs/examples/, notebooks regenerated from the
# scripts (the tests run both in a reduced form; tests/test_docs_numbers.py checks that a full
# run draws the tracked figures again and prints what docs/examples.md quotes). The figures
# carry no date (PNG; SOURCE_DATE_EPOCH for a format that embeds one): same run, same bytes
examples: $(VENV)/.installed-test
	@for f in examples/*.py; do echo "== $$f"; SOURCE_DATE_EPOCH=0 GRIPSENSE_EXAMPLES_OUT=docs/examples $(BIN)/python $$f || exit 1; done
	$(BIN)/jupytext --quiet --update --to ipynb examples/*.py

clean: clean-cache
	rm -rf $(VENV) demo-report build dist .pytest_cache

# numba's on-disk cache of a compiled function does not see edits to the functions it calls in
# other files (sim/integrate.py calls sim/dynamics.py): after editing those, drop it
clean-cache:
	find src -name '*.nbi' -delete -o -name '*.nbc' -delete
