# `make verify`: error against run time of the verification problems (issue 7).
# Writes runs/verify/{table.md,table.csv,results.json,error_vs_time.png}; about
# 20 minutes on 2 cores.  `make verify-quick` runs the subset that `make test` runs
# (tests/test_verify.py), in under a minute.
.PHONY: verify verify-quick

verify: install
	$(PY) benchmarks/verify.py --out runs/verify --mpirun $(MPIRUN)

verify-quick: install
	$(PY) benchmarks/verify.py --quick --out runs/verify-quick --mpirun $(MPIRUN)
