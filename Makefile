# mpipd — set-up, demo, tests, benchmarks.  `make demo` and `make test` each do the
# whole set-up first (Debian packages, .venv, mpi4py + parallel h5py), idempotently;
# `make test` also installs Debian's ParaView (pvbatch, for tests/test_paraview.py).
SHELL := /bin/bash
VENV ?= .venv
PY := $(VENV)/bin/python
MPIRUN ?= mpirun
STAMP := $(VENV)/.mpipd-installed

# Open MPI: allow root (CI and this machine run as root) and more ranks than cores.
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMPI_MCA_rmaps_base_oversubscribe := 1
export OMP_NUM_THREADS := 1

.PHONY: help install paraview lammps demo demo-figure test test-quick bench lint clean

# the user targets, one line each (research targets live in studies/*.mk: studies/README.md)
help:
	@echo "make install      set-up once: Debian Open MPI + parallel HDF5, .venv, mpi4py, h5py, mpipd"
	@echo "make demo         the built-in scene blast_demo on 2 ranks, its picture and report (runs/demo)"
	@echo "make test         every test CI runs (serial, mpirun -n 2 and -n 3), under 20 minutes"
	@echo "make test-quick   the serial unit tests only (no mpirun, no whole simulations), under 3 minutes"
	@echo "make docs         the documentation site from docs/ into site/, strict"
	@echo "make bench        throughput and memory of the kernels, beside LAMMPS"
	@echo "make verify       error against run time of the verification problems, then make stability"
	@echo "make examples     run the worked examples in examples/ and draw each (docs/img/examples)"
	@echo "make lint         ruff"
	@echo "make clean        remove caches (pytest, __pycache__, site/); never runs/"

install: $(STAMP)

$(STAMP): scripts/bootstrap.sh pyproject.toml
	bash scripts/bootstrap.sh
	touch $@

# Debian's paraview + python3-paraview, no recommends; a no-op once pvbatch is there
paraview:
	bash scripts/install_paraview.sh

# Debian's lammps, the peer of `make bench`; a no-op once lmp is there
lammps:
	bash scripts/install_lammps.sh

demo: install
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run blast_demo --out runs/demo --overwrite
	$(MPIRUN) -n 2 $(PY) -m mpipd.post fracture runs/demo/run.h5 --z 0.0005 --out runs/demo/fracture.png
	$(MPIRUN) -n 2 $(PY) -m mpipd.post report runs/demo/run.h5 --out runs/demo/report
	@echo "demo: the fracture pattern is in $(CURDIR)/runs/demo/fracture.png (validation report: runs/demo/report/report.md, fields: runs/demo/run.h5, ParaView: runs/demo/run.xdmf)"

# the README's picture: make demo first; the caption names the run file's commit
demo-figure:
	@test -f runs/demo/fracture.png || { echo "make demo-figure: runs/demo/fracture.png is missing: run make demo first"; exit 2; }
	mkdir -p docs/img && cp runs/demo/fracture.png docs/img/demo_fracture.png
	@$(PY) -c "import h5py; print('demo-figure: run file at commit', h5py.File('runs/demo/run.h5', 'r').attrs['git_commit'][:7])"

# the package's tests and those of the research scripts beside the studies (studies/tests)
test: install paraview
	$(PY) -m pytest -q -ra tests studies/tests

# the serial unit tier of the package, under 3 minutes: no test that launches mpirun
# (marker `mpi`, applied in tests/conftest.py) and none that runs a whole simulation
# (marker `slow`); make test runs them all
test-quick: install
	$(PY) -m pytest -q -ra -m "not mpi and not long and not slow" tests

bench: install lammps
	$(PY) benchmarks/run.py
	$(PY) benchmarks/fragments_bench.py

# ruff (lint + import order), configured in pyproject.toml; tests/test_lint.py runs it too
lint: install
	$(VENV)/bin/ruff check .

# caches only: runs/ (every run's home by default) is never deleted by make
clean:
	rm -rf .pytest_cache site
	find . -path ./.venv -prune -o -name __pycache__ -type d -prune -exec rm -rf {} +

# further targets (verify, jobs-test, ...) live in mk/*.mk, one file a topic
-include mk/*.mk studies/*.mk
