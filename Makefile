# nctwin — reproducibility package for five NC-machining papers.
#
#   make reproduce   set up .venv and LinuxCNC, execute every notebook, build the book (HTML); one line per
#                    step, "[k/N] ... (last run ...)", with the step's duration from the last run
#   make test        what CI runs (.ci/run): LinuxCNC, lint, unit tests, nbval (and that it leaves
#                    results/ as it found it), book, browser check
#
# Everything runs through .venv/bin/... explicitly; nothing needs `source activate`.
# Only PyPI (pip), Debian (apt) and npm are used; nothing is downloaded while notebooks run.

SHELL := /bin/bash
.SHELLFLAGS := -eu -o pipefail -c
.DEFAULT_GOAL := help
.NOTPARALLEL:
.SUFFIXES:

PYTHON_BOOTSTRAP ?= python3.11
VENV            := .venv
PY              := $(VENV)/bin/python
VENV_STAMP      := $(VENV)/.nctwin-requirements.sha256
MATHJAX_VERSION := 3.2.2
MATHJAX_DIR     := book/_vendor/mathjax
NPM_CACHE       := build/npm
CHROMIUM        ?= /usr/bin/chromium
HTML_DIR        := book/_build/html
# Processes of the unit tests that do not run LinuxCNC (pytest-xdist); CI has 2 cores.
TEST_WORKERS    ?= 2

# Source notebooks and the executed copies the book renders (committed).
NOTEBOOKS := $(sort $(wildcard notebooks/*.ipynb))
EXECUTED  := $(patsubst notebooks/%,book/notebooks/%,$(NOTEBOOKS))

# Same inputs, same outputs: fixed hashing, no GUI backend, fixed time zone, and the venv's own
# Jupyter kernel (the kernelspec installed with --sys-prefix wins over any user-level one).
export PYTHONHASHSEED := 0
export MPLBACKEND := Agg
export TZ := UTC
export JUPYTER_PREFER_ENV_PATH := 1
export PYDEVD_DISABLE_FILE_VALIDATION := 1
export PIP_DISABLE_PIP_VERSION_CHECK := 1
# Plain logs: no ANSI colour codes from pytest, ruff, pip or IPython tracebacks.
export NO_COLOR := 1
export TERM := dumb

# Same numbers on every x86-64 CPU with AVX2: numpy, OpenBLAS, torch (ATen, MKL, oneDNN) pick
# their kernels by CPU, and AVX-512 kernels round differently from AVX2 ones (trained networks
# then differ in every digit). Pinning all of them to the AVX2 paths makes an AVX-512 machine
# compute what an AVX2 one does; on an AVX2-only AMD EPYC, MKL_CBWR still changed the last bits
# of trained networks, so checkpoint keys include these pins (nctwin.learn.train.KERNEL_PINS).
ifeq ($(shell uname -m),x86_64)
export NPY_DISABLE_CPU_FEATURES := X86_V4 AVX512_ICL AVX512_SPR
export OPENBLAS_CORETYPE := Haswell
export ATEN_CPU_CAPABILITY := avx2
export MKL_CBWR := AVX2
export ONEDNN_MAX_CPU_ISA := AVX2
endif

.PHONY: help venv mathjax chromium notebooks book reproduce test lint unit nbval browser bench \
        clean distclean linuxcnc record calibrate lab chapter chapter-runs FORCE

help:
	@echo "make reproduce   venv -> mathjax -> linuxcnc -> notebooks (papermill) -> book; prints the HTML path"
	@echo "make test        venv, linuxcnc, ruff, pytest (tests/), nbval on book/notebooks, book build, browser check"
	@echo "make venv        create/refresh .venv from requirements.txt (skipped when up to date)"
	@echo "make mathjax     local MathJax $(MATHJAX_VERSION) (npm) into $(MATHJAX_DIR)"
	@echo "make chromium    install Debian chromium if $(CHROMIUM) is missing"
	@echo "make linuxcnc    install LinuxCNC (uspace) + libfaketime and the RTAPI_UID user, if missing"
	@echo "make record      re-record data/recordings/linuxcnc/ on LinuxCNC (needs make linuxcnc)"
	@echo "make calibrate   fit linuxcnc_sim's [control.fir] to its recordings, into its profile file"
	@echo "make notebooks   execute notebooks/*.ipynb into book/notebooks/ (cwd = repo root)"
	@echo "make lab         open notebooks/ in JupyterLab with the project's kernel; prints the URL"
	@echo "make chapter NB=<chapter> PROGRAM=<file>   one chapter on your program, into build/chapter/"
	@echo "make book        jupyter-book build book -W (offline)"
	@echo "make bench       run every benchmarks/*.py (JSON lines on stdout)"
	@echo "make clean       remove book/_build, build/, book/_vendor/ (keeps results/, data/cache/)"
	@echo "make distclean   clean + remove .venv"

# The kernelspec carries the settings above that fix the numbers (hash seed, time zone, the CPU
# kernels), so that a notebook run outside make (papermill, JupyterLab, an editor) computes what
# make computes and finds the networks make trained.
KERNEL_ENV := PYTHONHASHSEED TZ NPY_DISABLE_CPU_FEATURES OPENBLAS_CORETYPE ATEN_CPU_CAPABILITY \
  MKL_CBWR ONEDNN_MAX_CPU_ISA
KERNEL_ENV_PY := import json, os, sys; \
  p = os.path.join(sys.prefix, "share", "jupyter", "kernels", "python3", "kernel.json"); \
  k = json.load(open(p)); k["env"] = {n: os.environ[n] for n in sys.argv[1:] if n in os.environ}; \
  open(p, "w").write(json.dumps(k, indent=1) + "\n")

# ---------------------------------------------------------------------------------------------
# venv: reused without calling pip while the hash of requirements.txt + pyproject.toml matches.
# PIP_NOISE drops pip's warnings about empty local index folders on the project's machines.
PIP_NOISE := { grep -v "^WARNING: Location 'file:" || true; }
venv:
	@hash=$$(cat requirements.txt pyproject.toml | sha256sum | cut -d' ' -f1); \
	if [ -x $(PY) ] && $(PY) -c '' 2>/dev/null && [ "$$(cat $(VENV_STAMP) 2>/dev/null)" = "$$hash" ]; then \
	  echo "venv: $(VENV) up to date ($${hash:0:12})"; exit 0; \
	fi; \
	t0=$$(date +%s); \
	if ! { [ -x $(PY) ] && $(PY) -c '' 2>/dev/null; }; then \
	  rm -rf $(VENV); echo "venv: creating $(VENV) with $(PYTHON_BOOTSTRAP)"; \
	  $(PYTHON_BOOTSTRAP) -m venv $(VENV); \
	fi; \
	rm -f $(VENV_STAMP); \
	echo "venv: installing requirements.txt"; \
	$(PY) -m pip install --quiet --no-input --progress-bar off -r requirements.txt 2>&1 | $(PIP_NOISE); \
	$(PY) -m pip install --quiet --no-input --no-deps --no-build-isolation -e . 2>&1 | $(PIP_NOISE); \
	$(PY) -m pip check; \
	$(PY) -c 'import importlib.metadata as m, sys; v = m.version("torch"); \
	  sys.exit(None if v.split("+")[0] == "2.13.0" else f"venv: torch {v} installed, 2.13.0 pinned")'; \
	$(PY) -m ipykernel install --sys-prefix --name python3 --display-name "Python 3 (nctwin)" >/dev/null; \
	$(PY) -c '$(KERNEL_ENV_PY)' $(KERNEL_ENV); \
	echo "$$hash" > $(VENV_STAMP); \
	echo "venv: ready in $$(( $$(date +%s) - t0 )) s"

# ---------------------------------------------------------------------------------------------
# lab: JupyterLab on notebooks/ with the venv's kernel ("Python 3 (nctwin)", installed by venv).
# A notebook finds data/ and writes results/<stem>/ through the package (nctwin.paths), whatever
# the kernel's working folder. JupyterLab prints the URL with its token; without a display (no
# DISPLAY or WAYLAND_DISPLAY) it opens no browser, and as root (a container) it passes
# --allow-root. LAB_PORT picks the port (default 8888, the next free one if taken).
LAB_PORT ?= 8888
lab: venv
	@browser=$$([ -n "$${DISPLAY:-}$${WAYLAND_DISPLAY:-}" ] || echo --no-browser); \
	root=$$([ "$$(id -u)" != 0 ] || echo --allow-root); \
	echo "lab: JupyterLab on notebooks/ (kernel \"Python 3 (nctwin)\"); open the URL it prints"; \
	$(VENV)/bin/jupyter lab --ServerApp.root_dir="$(CURDIR)/notebooks" --port=$(LAB_PORT) $$browser $$root

# chapter: one chapter on a reader's own input, e.g. make chapter NB=chien2023_bilstm
# PROGRAM=part.ngc (PARAMS="-p name value" sets other parameters). The executed notebook and its
# HTML go to build/chapter/, its tables to build/chapter/<stem>/results/; results/ and
# book/notebooks/ are not touched (nctwin.report.chapter).
chapter: venv
	@if [ -z "$(NB)" ]; then echo "chapter: say which, e.g. make chapter NB=chien2023_bilstm PROGRAM=part.ngc" >&2; exit 2; fi
	@$(PY) -m nctwin.report.chapter "$(NB)" $(if $(PROGRAM),--program "$(PROGRAM)") $(PARAMS)

# ---------------------------------------------------------------------------------------------
# mathjax: the book loads MathJax from its own _static/mathjax/ (no CDN). tex-svg.js loads its es5
# siblings, so the whole es5/ directory is copied. Source dir is book/_vendor/, not book/_static/:
# see the comment at the top of book/_config.yml.
mathjax:
	@if [ -f $(MATHJAX_DIR)/tex-svg.js ] && [ "$$(cat $(MATHJAX_DIR)/VERSION 2>/dev/null)" = "$(MATHJAX_VERSION)" ]; then \
	  echo "mathjax: $(MATHJAX_DIR) holds MathJax $(MATHJAX_VERSION)"; exit 0; \
	fi; \
	mkdir -p $(NPM_CACHE); \
	tgz=$(NPM_CACHE)/mathjax-$(MATHJAX_VERSION).tgz; \
	if [ ! -s $$tgz ]; then \
	  tmp=$$(mktemp -d $(NPM_CACHE)/pack.XXXXXX); \
	  (cd $$tmp && npm pack --silent mathjax@$(MATHJAX_VERSION) >/dev/null); \
	  mv $$tmp/mathjax-$(MATHJAX_VERSION).tgz $$tgz; rm -rf $$tmp; \
	fi; \
	tmp=$$(mktemp -d $(NPM_CACHE)/x.XXXXXX); \
	tar -xzf $$tgz -C $$tmp package/es5 package/LICENSE; \
	rm -rf $(MATHJAX_DIR); mkdir -p $(dir $(MATHJAX_DIR)); \
	mv $$tmp/package/es5 $(MATHJAX_DIR); mv $$tmp/package/LICENSE $(MATHJAX_DIR)/LICENSE; \
	rm -rf $$tmp; echo "$(MATHJAX_VERSION)" > $(MATHJAX_DIR)/VERSION; \
	echo "mathjax: MathJax $(MATHJAX_VERSION) es5/ -> $(MATHJAX_DIR)"

# apt-get waits for a dpkg/apt lock another apt run holds (up to 10 min) instead of failing.
APT_WAIT := -o DPkg::Lock::Timeout=600

chromium:
	@if [ -x $(CHROMIUM) ]; then echo "chromium: $(CHROMIUM) present"; exit 0; fi; \
	sudo=; [ "$$(id -u)" = 0 ] || sudo=sudo; \
	echo "chromium: installing Debian chromium with apt-get (waits up to 10 min for another apt run)"; \
	$$sudo env DEBIAN_FRONTEND=noninteractive apt-get $(APT_WAIT) update -q; \
	$$sudo env DEBIAN_FRONTEND=noninteractive apt-get $(APT_WAIT) install -y -q \
	  --no-install-recommends chromium

# ---------------------------------------------------------------------------------------------
# linuxcnc: the real NC kernel of nctwin.kernel.linuxcnc. Debian packages without recommends
# (the full install pulls a real-time kernel and PyQt5): linuxcnc-uspace (planner, HAL,
# halsampler, the `linuxcnc` module of /usr/bin/python3), libfaketime (runs it faster than real
# time), iproute2 (loopback in the private network namespace). As root LinuxCNC needs RTAPI_UID,
# an unprivileged user: LINUXCNC_USER must equal nctwin.kernel.linuxcnc.RTAPI_USER.
LINUXCNC_USER := linuxcnc-rt
LINUXCNC_PKGS := linuxcnc-uspace libfaketime iproute2
linuxcnc:
	@have() { [ -x /usr/bin/linuxcnc ] && [ -x /usr/bin/halsampler ] && [ -x /usr/sbin/ip ] && \
	  compgen -G '/usr/lib/*/faketime/libfaketimeMT.so.1' >/dev/null; }; \
	if have && id -u $(LINUXCNC_USER) >/dev/null 2>&1; then echo "linuxcnc: present"; exit 0; fi; \
	sudo=; [ "$$(id -u)" = 0 ] || sudo=sudo; t0=$$(date +%s); \
	if ! have; then \
	  echo "linuxcnc: installing $(LINUXCNC_PKGS) with apt-get (about 1 min)"; \
	  if ! { $$sudo env DEBIAN_FRONTEND=noninteractive apt-get $(APT_WAIT) update -q && \
	         $$sudo env DEBIAN_FRONTEND=noninteractive apt-get $(APT_WAIT) install -y -q \
	           --no-install-recommends $(LINUXCNC_PKGS); }; then \
	    echo "linuxcnc: FAILED to install $(LINUXCNC_PKGS) with apt-get (Debian bookworm" \
	         "packages; needs root or sudo and the network); see apt-get's message above" >&2; \
	    exit 1; \
	  fi; \
	fi; \
	if ! id -u $(LINUXCNC_USER) >/dev/null 2>&1; then \
	  $$sudo useradd --system --no-create-home --shell /usr/sbin/nologin $(LINUXCNC_USER); \
	  echo "linuxcnc: created user $(LINUXCNC_USER) (RTAPI_UID)"; \
	fi; \
	echo "linuxcnc: ready in $$(( $$(date +%s) - t0 )) s"

# record: the shipped LinuxCNC recordings (nctwin.record), re-recorded from nothing.
record: venv linuxcnc
	@t0=$$(date +%s); $(PY) -m nctwin.record; \
	echo "record: done in $$(( $$(date +%s) - t0 )) s"

# calibrate: what is fitted to the recordings is written into the machine's profile file (with a
# comment that says which recordings, when, and the residual), never read from results/ at run
# time. After `make record`, run this and commit the profile. (A real machine's profile comes
# from its MTConnect logs: nctwin calibrate LOG ... --output PROFILE.toml.)
calibrate: venv
	@t0=$$(date +%s); $(VENV)/bin/nctwin calibrate --recordings linuxcnc --machine linuxcnc_sim \
	  --output data/machines/linuxcnc_sim.toml; \
	echo "calibrate: done in $$(( $$(date +%s) - t0 )) s"

# ---------------------------------------------------------------------------------------------
# Steps that talk: each long step prints "[k/N] <step> (last run 9 min 40 s)" before it starts,
# with its duration from the last successful run on this machine, kept in $(DURATIONS) (build/
# is not committed). STEP_SH defines the shell helpers the recipes below use:
#   human S       "9 min 40 s"           last_run STEP   "last run 9 min 40 s" or "no previous run"
#   record_s STEP SECONDS                stores the step's duration
DURATIONS := build/durations.tsv
STEP_SH := \
  human() { if [ "$$1" -ge 60 ]; then echo "$$(( $$1 / 60 )) min $$(( $$1 % 60 )) s"; else echo "$$1 s"; fi; }; \
  last_run() { local s=; [ -f $(DURATIONS) ] && s=$$(awk -F'\t' -v k="$$1" '$$1 == k { v = $$2 } END { print v }' $(DURATIONS)); \
    if [ -n "$$s" ]; then echo "last run $$(human $$s)"; else echo "no previous run here"; fi; }; \
  record_s() { mkdir -p $(dir $(DURATIONS)); \
    { if [ -f $(DURATIONS) ]; then awk -F'\t' -v k="$$1" '$$1 != k' $(DURATIONS); fi; printf '%s\t%s\n' "$$1" "$$2"; } \
      > $(DURATIONS).tmp; mv $(DURATIONS).tmp $(DURATIONS); };

# ---------------------------------------------------------------------------------------------
# notebooks: papermill, headless, cwd = repo root (notebooks write results/<stem>/...). The output
# goes to build/papermill/ first and replaces book/notebooks/<name> only on success.
# `make notebooks` re-executes all; `make book`/`make test` execute only those whose executed copy
# is missing (order-only prerequisites: a fresh clone's file times never trigger a re-run).
# Figures: the kernel draws inline only with this backend (the exported Agg would drop them);
# progress bars stay out of the executed notebooks.
# Papermill runs through its Python API, not its command line, for two settings the command line
# lacks: the kernel talks to papermill over IPC sockets (with TCP, ipykernel warns on every start
# that the transport is not encrypted; the sockets live in build/papermill/, so that a killed run
# leaves none in the checkout), and IPython prints tracebacks without colour codes.
NB_MPLBACKEND := module://matplotlib_inline.backend_inline
NB_FORCE :=
NB_VENV := venv
STEP :=
PAPERMILL_PY := import sys, papermill; from traitlets.config import Config; \
  nb, out, cwd = sys.argv[1:]; \
  papermill.execute_notebook(nb, out, cwd=cwd, kernel_name="python3", progress_bar=False, \
    config=Config(KernelManager={"transport": "ipc", "ip": "build/papermill/kernel-ipc"}), \
    extra_arguments=["--InteractiveShell.colors=nocolor"])
book/notebooks/%.ipynb: $(NB_FORCE) | notebooks/%.ipynb $(NB_VENV)
	@mkdir -p book/notebooks build/papermill
	@$(STEP_SH) src=notebooks/$*.ipynb; tmp=build/papermill/$*.ipynb; t0=$$(date +%s); \
	echo "$(STEP)notebooks: executing $* ($$(last_run notebooks/$*))"; \
	if ! MPLBACKEND=$(NB_MPLBACKEND) TQDM_DISABLE=1 $(PY) -c '$(PAPERMILL_PY)' "$$src" "$$tmp" "$(CURDIR)"; then \
	  echo "notebooks: $$src FAILED; the partly executed notebook is $$tmp" >&2; exit 1; \
	fi; \
	mv "$$tmp" "$@"; dt=$$(( $$(date +%s) - t0 )); record_s notebooks/$* $$dt; \
	echo "notebooks: $@ ($$(human $$dt))"

notebooks: venv
	@if [ -z "$(strip $(EXECUTED))" ]; then echo "notebooks: notebooks/ holds no notebook"; exit 0; fi; \
	n=$(words $(EXECUTED)); k=0; \
	for nb in $(EXECUTED); do k=$$((k + 1)); \
	  $(MAKE) --no-print-directory NB_FORCE=FORCE NB_VENV= STEP="[$$k/$$n] " $$nb; \
	done

FORCE:

# ---------------------------------------------------------------------------------------------
# book: the Verdicts page is written from results/*/claims.json first (nctwin.report.verdicts),
# so the book always shows the claims its notebooks wrote. Jupyter Book colours Sphinx's messages
# whatever NO_COLOR says; sed takes the colour codes out of the log.
BOOK_SETUP := venv mathjax
book: $(BOOK_SETUP) | $(EXECUTED)
	@mkdir -p build; t0=$$(date +%s); \
	$(PY) -m nctwin.report.verdicts book/verdicts.md; \
	$(VENV)/bin/jupyter-book build book --all -W --keep-going --builder html 2>&1 \
	  | sed -u 's/\x1b\[[0-9;]*m//g' | tee build/book.log; \
	echo "book: built in $$(( $$(date +%s) - t0 )) s"; \
	echo "book: $(CURDIR)/$(HTML_DIR)/index.html"

# reproduce: venv, MathJax, LinuxCNC (its interpreter reads the chapters' programs in the whole
# language), every notebook, the book; one "[k/N]" line per step.
reproduce:
	@$(STEP_SH) nbs=($(EXECUTED)); n=$$(( 4 + $${#nbs[@]} )); k=0; t_all=$$(date +%s); \
	run() { local name=$$1; shift; k=$$((k + 1)); echo "[$$k/$$n] $$name ($$(last_run $$name))"; \
	  local t0=$$(date +%s); $(MAKE) --no-print-directory "$$@"; record_s $$name $$(( $$(date +%s) - t0 )); }; \
	run venv venv; \
	run mathjax mathjax; \
	run linuxcnc linuxcnc; \
	for nb in "$${nbs[@]}"; do k=$$((k + 1)); \
	  $(MAKE) --no-print-directory NB_FORCE=FORCE NB_VENV= STEP="[$$k/$$n] " $$nb; \
	done; \
	run book book BOOK_SETUP= NB_VENV=; \
	total=$$(( $$(date +%s) - t_all )); \
	echo "reproduce: done in $$(human $$total) ($$(last_run reproduce)); open $(CURDIR)/$(HTML_DIR)/index.html"; \
	record_s reproduce $$total

# ---------------------------------------------------------------------------------------------
# make test installs LinuxCNC (make linuxcnc) and requires its live tests to run (they fail
# instead of skipping): the real NC kernel and the shipped recordings are proven, not assumed.
# nbval first: its executions leave the chapters' networks in the cache, which the unit tests of
# the CLI's learned methods (the LinuxCNC chapter's networks) then load instead of training.
test: export NCTWIN_REQUIRE_LINUXCNC := 1
test: venv linuxcnc lint nbval unit chapter-runs browser
	@echo "test: all steps passed"

lint: venv
	$(VENV)/bin/ruff check $(wildcard src tests benchmarks)

# unit: the tests that do not run LinuxCNC on TEST_WORKERS processes (pytest-xdist), then the
# live ones alone: a live run is timed against the servo thread and aborts on a loaded host.
unit: venv
	$(PY) -m pytest -n $(TEST_WORKERS) -m "not chapter and not live" --durations=15
	$(PY) -m pytest -m "live and not chapter"

# chapter-runs: a chapter through papermill on a reader's input, as `make chapter` runs it
# (tests/test_chapter_runs.py, marked `chapter`, which a plain pytest leaves out): the parameter
# reaches the chapter, its tables go to the run's folder and results/ is unchanged. Every
# chapter's own "Your ..." section runs in nbval, on the shipped examples. After nbval, whose
# executions leave the chapter's data in the cache.
chapter-runs: venv | $(EXECUTED)
	$(PY) -m pytest -m chapter -p no:cacheprovider tests/test_chapter_runs.py

# nbval re-executes the notebooks in the environment papermill executed them in (inline figures,
# no progress bars on stderr): a checked cell whose training outlasts the bar's delay would
# otherwise print to stderr, which its executed copy does not have. Every cell's time goes to
# build/nbval-cells.xml (JUnit XML; a notebook's time is the sum of its cells'). The
# re-execution rewrites results/; nbval fails if any file there differs afterwards from what it
# was before (a copy taken first, so uncommitted work is compared with itself, and a fresh clone
# with the commit).
nbval: venv | $(EXECUTED)
	@shopt -s nullglob; nbs=(book/notebooks/*.ipynb); \
	if [ $${#nbs[@]} -eq 0 ]; then echo "nbval: book/notebooks/ holds no executed notebook; skipped"; exit 0; fi; \
	echo "nbval: $${nbs[*]}"; \
	snap=build/results-before-nbval; rm -rf $$snap; mkdir -p build; cp -a results $$snap; status=0; \
	MPLBACKEND=$(NB_MPLBACKEND) TQDM_DISABLE=1 $(PY) -m pytest --nbval-lax --nbval-current-env \
	  -p no:cacheprovider --color=no --durations=20 --junitxml=build/nbval-cells.xml \
	  "$${nbs[@]}" || status=$$?; \
	changed=$$(diff -rq $$snap results | sed -E \
	  -e "s#^Files $$snap/(.*) and results/.* differ\$$#  results/\1#" \
	  -e "s#^Only in $$snap/?(.*): (.*)\$$#  results/\1/\2 (no longer written)#" \
	  -e "s#^Only in results/?(.*): (.*)\$$#  results/\1/\2 (new)#" -e "s#results//#results/#" || true); \
	rm -rf $$snap; \
	if [ -n "$$changed" ]; then \
	  echo "nbval: FAILED: re-executing the notebooks changed these files under results/:" >&2; \
	  echo "$$changed" >&2; \
	  echo "nbval: results/ must be reproducible bit for bit; measured timings belong elsewhere" \
	       "(see README, 'Timings')" >&2; \
	  exit 1; \
	fi; \
	exit $$status

browser: book chromium
	@t0=$$(date +%s); \
	$(PY) tests/browser/check_book.py --chromium $(CHROMIUM) $(HTML_DIR); \
	echo "browser: checked in $$(( $$(date +%s) - t0 )) s"

# bench: every benchmarks/*.py except helper modules (_common.py, ...); JSON lines on stdout.
bench: venv
	@shopt -s nullglob; scripts=(benchmarks/[!_]*.py); \
	if [ $${#scripts[@]} -eq 0 ]; then echo "bench: benchmarks/ holds no script" >&2; exit 0; fi; \
	set -o pipefail; status=0; \
	for s in "$${scripts[@]}"; do echo "bench: $$s" >&2; \
	  $(PY) "$$s" | $(PY) benchmarks/_targets.py || { echo "bench: $$s FAILED" >&2; status=1; }; \
	done; exit $$status

# ---------------------------------------------------------------------------------------------
clean:
	rm -rf book/_build build book/_vendor

distclean: clean
	rm -rf $(VENV)
