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

# multi-rate against single-rate on blast_demo (docs/multirate.md): single-rate at dt
# and at dt/2 (its own time-step sensitivity), multi-rate at ratios 2 and 4, each
# reported, then the table docs/multirate_blast_demo.md (about 15 minutes on 2 cores)
MR_RUNS := sr:runs/multirate/sr sr_half_dt:runs/multirate/sr_half_dt mr2:runs/multirate/mr2 mr4:runs/multirate/mr4
.PHONY: multirate-verify
verify: multirate-verify
multirate-verify: install
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run blast_demo --out runs/multirate/sr --overwrite --quiet
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run blast_demo --out runs/multirate/sr_half_dt --overwrite --quiet --set time.dt=1e-8
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run blast_demo --out runs/multirate/mr2 --overwrite --quiet --set "time.multirate={max_ratio=2, safety=0.5}"
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run blast_demo:multirate --out runs/multirate/mr4 --overwrite --quiet
	for r in sr sr_half_dt mr2 mr4; do $(MPIRUN) -n 2 $(PY) -m postprocess report runs/multirate/$$r/run.h5 --out runs/multirate/$$r/report || exit 1; done
	$(PY) benchmarks/multirate_compare.py --out docs/multirate_blast_demo.md \
	    $(foreach r,$(MR_RUNS),$(subst :,=,$(r)))
