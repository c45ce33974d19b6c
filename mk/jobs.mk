# Cluster job scripts (jobs/): `make jobs-test` submits the real SLURM scripts to a
# single-node SLURM on this machine (scripts/slurm_local.sh installs slurm-wlm and
# munge with apt if needed and starts the daemons; the test stops them again if it
# started them).  If the scheduler cannot start here, the test is skipped and says why.
.PHONY: jobs-test slurm-start slurm-stop

jobs-test: install
	$(PY) -m pytest -q -ra tests/test_jobs.py

# the local SLURM by hand, e.g. to try a job script: make slurm-start; sbatch ...
slurm-start:
	bash scripts/slurm_local.sh start

slurm-stop:
	bash scripts/slurm_local.sh stop
