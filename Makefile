# vrlib: every result, the report and the tests from one Makefile.
#   make all      set up .venv (first use), regenerate every chapter result, build the report
#   make test     set up .venv (first use), run the test suite (MPI tests included)
# The chapter scripts are tracked like any build rule: a script re-runs only when it, the
# library, or the results it reads have changed.

SHELL := /bin/bash
.SHELLFLAGS := -eu -o pipefail -c
.DEFAULT_GOAL := all
.DELETE_ON_ERROR:
.SECONDEXPANSION:

PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
PY := $(VENV)/bin/python
INSTALLED := $(VENV)/.installed

# Sizes of the chapter experiments: default (minutes on 2 cores) or full (thesis scale).
PROFILE ?= default
export VRLIB_PROFILE := $(PROFILE)
# numba's cache is invalidated when a kernel's own file changes, not when a helper it calls
# from another file does: one cache per version of the kernel sources, so none goes stale.
export NUMBA_CACHE_DIR := $(CURDIR)/build/numba/$(shell cat vrlib/_kernels/*.py | sha1sum | cut -c1-12)
# numba's default OpenMP layer kills a child forked after a parallel call; workqueue does not.
export NUMBA_THREADING_LAYER := workqueue
export MPLBACKEND := Agg
export VTK_DEFAULT_OPENGL_WINDOW := vtkEGLRenderWindow
export PYTHONHASHSEED := 0

LIBRARY := $(shell find vrlib data_gen -name '*.py' -not -path '*/__pycache__/*')
CHAPTER_COMMON := $(wildcard chapters/*.py)
RUNS := $(wildcard chapters/*/run_*.py)
PLOTS := $(wildcard chapters/*/fig_*.py chapters/*/tab_*.py)
stamp = $(patsubst chapters/%.py,build/stamps/%.done,$(1))
RESULTS := $(call stamp,$(RUNS) $(PLOTS))
DOCS := $(shell find docs -type f -not -path 'docs/_build/*')
REPORT := build/report/html/index.html
VERDICTS := build/results/claims/verdicts.json

.PHONY: all venv bytecode results report report-check test test-all bench lint clean distclean

all: results report

venv: $(INSTALLED)

# The pinned stack (constraints.txt pins every package) is installed by uv, which downloads
# and unpacks in parallel: a fresh install with bytecode took 27 to 37 s on a 2-core Intel
# Xeon where pip took 69 to 80 s (the same 101 packages and versions; no caches, alternated,
# 2026-11-29). pip installs uv first (pinned too), and installs the stack itself where uv
# cannot be had or fails. Then compileall on both cores, without the packages' own tests
# and the installers' files. Compiled up front, because where PYTHONDONTWRITEBYTECODE is set
# (this project's machines) Python never writes what it compiles: every process compiled
# every module it imported from source, 1 to 2 s each (`make test` from a fresh clone,
# alternated with the Makefile before: 4 min 10-12 s -> 3 min 34-51 s, install included; a
# `vrlib render` command 0.9 s).
$(INSTALLED): pyproject.toml constraints.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -c constraints.txt uv && \
		$(PY) -m uv pip install --quiet --python $(PY) -c constraints.txt -e '.[all]' || \
		$(PY) -m pip install --quiet --disable-pip-version-check --no-compile \
			-c constraints.txt -e '.[all]'
	$(PY) -m compileall -q -j 0 -x '/site-packages/(pip|setuptools|uv)/|/tests?/' \
		$$($(PY) -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])') >/dev/null
	@touch $@

# The project's own bytecode, for its processes (test workers, MPI ranks, the command line,
# chapter scripts): only files changed since the last call are compiled (0.2 s when none is).
bytecode: $(INSTALLED)
	@$(PY) -m compileall -q -j 0 vrlib data_gen tests chapters benchmarks docs >/dev/null

results: bytecode $(RESULTS) $(VERDICTS)

# The report's verdict on each thesis claim comes from its claim tests (tests/claims): each
# test is marked as supporting, refuting or going beyond a claim. A failing test is recorded,
# not hidden: its claim's verdict changes.
# docs/claim_tables.py turns the verdicts into the report's claim tables (figures/claims/).
$(VERDICTS): $(wildcard tests/claims/*.py) tests/claim_verdicts.py docs/claim_tables.py \
		$(LIBRARY) $(INSTALLED)
	@mkdir -p $(@D)
	VRLIB_VERDICTS=$@ $(PY) -m pytest -q tests/claims || echo "claim tests failed: see the verdicts"
	@test -s $@
	$(PY) -m docs.claim_tables $@ figures/claims

# run_* scripts compute and write build/results/<chapter>/...; chapters/<chapter>/_*.py are
# helpers shared by a chapter's scripts.
build/stamps/%.done: chapters/%.py $(LIBRARY) $(CHAPTER_COMMON) $(INSTALLED) \
		$$(wildcard chapters/$$(dir $$*)_*.py)
	@mkdir -p $(@D)
	@echo "[chapters] $*"
	$(PY) -m chapters.$(subst /,.,$*)
	@touch $@

# fig_* and tab_* scripts also read what the run_* scripts of their chapter wrote.
$(call stamp,$(PLOTS)): build/stamps/%.done: \
		$$(call stamp,$$(wildcard chapters/$$(dir $$*)run_*.py))

report: $(REPORT)

# Built into a fresh folder and swapped in whole: never a half-written report.
$(REPORT): $(DOCS) $(RESULTS) $(VERDICTS) $(LIBRARY) $(INSTALLED)
	@rm -rf build/report/html.tmp
	$(PY) -m sphinx -W --keep-going -q -b html -d build/report/doctrees docs build/report/html.tmp
	@rm -rf build/report/html && mv build/report/html.tmp build/report/html
	@echo "report: $(REPORT)"

# Every report page rendered in headless Chromium (installed from Debian if missing): fails on
# a blank page or a broken image.
report-check: $(REPORT)
	@command -v chromium >/dev/null 2>&1 || (apt-get update -qq && apt-get install -y -qq \
		chromium >/dev/null) || (echo "report-check needs chromium (apt-get install chromium)"; \
		exit 1)
	$(PY) docs/report_check.py build/report/html

# Two workers (pytest-xdist): the suite's time goes mostly into compiling kernels, which two
# processes do side by side; test ids are the same in every process, as xdist needs. Whole
# files to a worker (--dist loadfile): a file's tests need the same kernels, and handed out
# test by test both workers compiled them at once (empty kernel cache, this machine: 297 ->
# 226 s).
test: bytecode
	$(PY) -m pytest -m "not slow" -n 2 --dist loadfile

# Everything, slow checks included, then the kernels' comparisons with their naive twins again
# with the JIT off, so that the numba kernels also run (and agree) as plain Python.
test-all: bytecode
	HYPOTHESIS_PROFILE=thorough $(PY) -m pytest
	NUMBA_DISABLE_JIT=1 $(PY) -m pytest -m "not slow" tests \
		-k "naive_twin or bricks or test_filters or test_transfer or test_skipping"

bench: bytecode
	@dpkg -s libvolpack1-dev >/dev/null 2>&1 || (apt-get update -qq && apt-get install -y -qq \
		libvolpack1 libvolpack1-dev >/dev/null) || echo "VolPack could not be installed: its comparisons are skipped"
	$(PY) -m pytest benchmarks --benchmark-enable --benchmark-only --benchmark-columns=min,median,max,rounds
	@for script in benchmarks/bench_*.py; do [ -e "$$script" ] || continue; \
		echo "== $$script"; $(PY) "$$script"; done

lint: $(INSTALLED)
	$(PY) -m ruff check .

clean:
	rm -rf build figures docs/_build
	find . -name __pycache__ -type d -not -path './.venv/*' -prune -exec rm -rf {} +

distclean: clean
	rm -rf $(VENV)
