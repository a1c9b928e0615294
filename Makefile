# singcheck — set-up, tests and the bundled example.  `make help` lists the targets.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
ROBOT  ?= robots/orthoglide.yaml
TRAJ   ?= trajectories/heart1.yaml
# wait (up to 10 min) for another apt (unattended upgrades) to release its lock, not fail
APT    := apt-get -o DPkg::Lock::Timeout=600

.PHONY: help setup cas browser test test-fast lint docs demo examples bench clean

help:
	@echo "make setup      install Singular, Macaulay2 and Chromium (apt), create $(VENV), install singcheck"
	@echo "make demo       set up, then certify the paper's Orthoglide on heart 1"
	@echo "make examples   set up, then certify every bundled trajectory"
	@echo "make test       set up, then run the whole test suite (slow tests included)"
	@echo "make test-fast  the suite without the tests marked slow"
	@echo "make lint       ruff"
	@echo "make docs       build the documentation site into site/ (strict: a broken link fails)"
	@echo "make bench      benchmark singcheck against sampling; writes bench/results.json"

setup: cas browser $(VENV)/.installed

# The external CAS backends (Debian packages). Skipped when both are already installed.
cas:
	@if command -v Singular >/dev/null && command -v M2 >/dev/null; then :; else \
	  echo "installing Singular and Macaulay2 (Debian packages singular, macaulay2)"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO $(APT) update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO $(APT) install -y -qq singular macaulay2 >/dev/null; fi

# Headless Chromium (Debian package chromium): the tests open the HTML figures page in it.
browser:
	@if command -v chromium >/dev/null; then :; else \
	  echo "installing Chromium (Debian package chromium)"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO $(APT) update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO $(APT) install -y -qq chromium >/dev/null; fi

# Debian's python3 lacks ensurepip until python3-venv is installed: install it when we can.
$(VENV)/.installed: pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "singcheck needs Python >= 3.11"'
	@$(PYTHON) -m venv $(VENV) 2>/dev/null || { \
	  echo "python3 -m venv failed: installing Debian's python3-venv"; \
	  rm -rf $(VENV); \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO $(APT) update -qq && $$SUDO $(APT) install -y -qq python3-venv && \
	  $(PYTHON) -m venv $(VENV); }
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test,bench,plot,html,dask,docs]'
	@touch $@

test: setup
	$(BIN)/python -m pytest -q

test-fast: setup
	$(BIN)/python -m pytest -q -m 'not slow'

lint: setup
	$(BIN)/ruff check singcheck tests

# The documentation site (MkDocs, Material theme) from docs/ into site/; --strict turns
# every warning (a broken link or anchor, a missing page or figure) into a failure.
docs: setup
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir site

# heart 1 crosses a singularity: exit status 1 is the expected, proven answer.
demo: setup
	$(BIN)/singcheck run $(ROBOT) $(TRAJ) || [ $$? -eq 1 ]

examples: setup
	$(BIN)/singcheck run robots/orthoglide.yaml trajectories/heart1.yaml trajectories/heart2.yaml trajectories/helix.yaml || [ $$? -eq 1 ]

clean:
	rm -rf $(VENV) *.egg-info .pytest_cache .ruff_cache site

# singcheck against the sampling check, side by side, one process; writes bench/results.json
bench: setup
	$(BIN)/python bench/bench.py
