# The two commands a fresh machine needs: `make run` and `make test`.
# Each creates .venv when missing and installs what it needs first.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

CHROMIUM := /usr/bin/chromium

.PHONY: run test lint bench docs install clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

install: $(STAMP)

# The studio's end-to-end test drives Debian's chromium (not a Playwright-downloaded browser).
$(CHROMIUM):
	@if [ "$$(id -u)" = 0 ]; then \
		echo "installing Debian's chromium for the browser tests"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; \
	else \
		echo "error: the browser tests need Debian's chromium at $(CHROMIUM);" \
			"run 'sudo apt-get install chromium' (make test installs it itself only as root)" >&2; \
		exit 1; \
	fi

## make run: plan, verify and plot the bundled hand-drawn spiral into out/demo
run: $(STAMP)
	$(BIN)/skyquill demo --out out/demo

## make test: the whole test suite (unit, property-based, paper reproductions)
test: $(STAMP) $(CHROMIUM)
	$(BIN)/python -m pytest -n 2 -q

## make docs: the documentation site (mkdocs.yml) into site/; `.venv/bin/mkdocs serve` to browse it
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 DISABLE_MKDOCS_2_WARNING=true $(BIN)/mkdocs build --strict

lint: $(STAMP)
	$(BIN)/ruff check src tests bench examples tools
	$(BIN)/ruff format --check src tests bench examples tools
	$(BIN)/mypy

bench: $(STAMP)
	$(BIN)/python bench/engine.py
	$(BIN)/python bench/sim.py
	$(BIN)/python bench/resegment.py
	$(BIN)/python bench/calligraphy.py
	$(BIN)/python bench/paper000_figs.py
	$(BIN)/python bench/coverage_lp.py
	$(BIN)/python bench/coverage.py
	$(BIN)/python bench/painting.py
	$(BIN)/python bench/cones.py
	$(BIN)/python bench/resegment_cones.py
	$(BIN)/python bench/regression.py

clean:
	rm -rf $(VENV) out site .pytest_cache .mypy_cache .ruff_cache
