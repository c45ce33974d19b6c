# `make verify`: error against run time of the verification problems (issue 7).
# Writes runs/verify/{table.md,table.csv,results.json,error_vs_time.png}; about
# 20 minutes on 2 cores.  `make verify-quick` runs the subset that `make test` runs
# (tests/test_verify.py), in under a minute.
.PHONY: verify verify-quick stability cases

verify: install
	$(PY) benchmarks/verify.py --out runs/verify --mpirun $(MPIRUN)
	$(MAKE) stability

# the stability cases of minutes (tests marked `long`: the paper's geometry at the
# resolutions that once blew up); `make test` skips them and says so
stability: install
	$(PY) -m pytest -q -ra --long -m long tests

verify-quick: install
	$(PY) benchmarks/verify.py --quick --out runs/verify-quick --mpirun $(MPIRUN)

# a built-in scene and every named case of it to t_end (benchmarks/cases.py):
# make cases [CASES_SCENE=blast_demo] -> runs/cases/<scene>/cases.md
CASES_SCENE ?= blast_demo
cases: install
	$(PY) benchmarks/cases.py --scene $(CASES_SCENE) --out runs/cases --mpirun $(MPIRUN)
