# Research targets of the multi-rate and rock-mass studies (studies/multirate/README.md):
# each runs blast_demo or the paper's slab many times and rewrites its table under
# studies/.  Not user targets: `make help` does not list them.

# multi-rate against single-rate on blast_demo (docs/multirate.md): single-rate, ratio 4
# (the graded buffer, the default), ratio 4 with the full buffer and ratio 4 with
# fracture_class = 1, each at five time steps dt = 2 us / N (N = MR_N; 100 is the scene's
# dt, 200 is dt/2), ratio 2 at the scene's dt, each reported, then the table
# studies/multirate/multirate_blast_demo.md with each group's range over dt (about 25 minutes on 2 cores)
MR_N := 100 96 104 120 200
MR_RUNS := $(foreach g,sr mr4 mr4full mr4fc1,$(foreach n,$(MR_N),$(g)_$(n))) mr2_100
MR_SET_sr := --set "time.multirate={max_ratio=1}"
MR_SET_mr4 := --set "time.multirate={max_ratio=4, safety=0.5}"
MR_SET_mr4full := --set 'time.multirate={max_ratio=4, safety=0.5, buffer="full"}'
MR_SET_mr4fc1 := --set "time.multirate={max_ratio=4, safety=0.5, fracture_class=1}"
# $(call dt_sweep,GROUPS,SETS,FOLDER[,SCENE,NS,EVERY]): SCENE (blast_demo) for each
# group g of GROUPS (its options in $(SETS_g)) at each dt = 2 us / N of NS (MR_N), a
# frame every EVERY x N steps (1: every 2 us), into FOLDER/g_N, each reported
define dt_sweep
for n in $(or $(5),$(MR_N)); do dt=$$($(PY) -c "print(2e-6/$$n)"); \
  $(foreach g,$(1),$(MPIRUN) -n 2 $(VENV)/bin/mpipd run $(or $(4),blast_demo) \
    --out $(3)/$(g)_$$n --overwrite --quiet --set time.dt=$$dt --set output.every=$$(($$n * $(or $(6),1))) \
    $($(2)_$(g)) || exit 1;) done
for r in $(foreach g,$(1),$(foreach n,$(or $(5),$(MR_N)),$(g)_$(n))); do \
  $(MPIRUN) -n 2 $(PY) -m mpipd.post report $(3)/$$r/run.h5 --out $(3)/$$r/report > /dev/null || exit 1; done
endef

.PHONY: multirate-verify
multirate-verify: install
	$(call dt_sweep,sr mr4 mr4full mr4fc1,MR_SET,runs/multirate)
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run blast_demo --out runs/multirate/mr2_100 --overwrite --quiet --set "time.multirate={max_ratio=2, safety=0.5}"
	$(MPIRUN) -n 2 $(PY) -m mpipd.post report runs/multirate/mr2_100/run.h5 --out runs/multirate/mr2_100/report > /dev/null
	$(PY) benchmarks/multirate_compare.py --out studies/multirate/multirate_blast_demo.md --bands sr,mr4,mr4full,mr4fc1 --stats \
	    $(foreach r,$(MR_RUNS),$(r)=runs/multirate/$(r))

# the fracture window on blast_demo (docs/multirate.md, The fracture phase and the fracture window): single-rate
# and ratio 4 with fracture_window = 2 (the default), 1 and 0, each at the five dt of
# multirate-verify, each reported, then studies/multirate/multirate_fracture_window.md (about 25
# minutes on 2 cores)
FW_SET_sr := --set "time.multirate={max_ratio=1}"
FW_SET_mr4 := --set "time.multirate={max_ratio=4, safety=0.5}"
FW_SET_w1 := --set "time.multirate={max_ratio=4, safety=0.5, fracture_window=1}"
FW_SET_w0 := --set "time.multirate={max_ratio=4, safety=0.5, fracture_window=0}"
FW_RUNS := $(foreach g,sr mr4 w1 w0,$(foreach n,$(MR_N),$(g)_$(n)))
.PHONY: multirate-window
multirate-window: install
	$(call dt_sweep,sr mr4 w1 w0,FW_SET,runs/window)
	$(PY) benchmarks/multirate_compare.py --out studies/multirate/multirate_fracture_window.md --bands sr,mr4,w1,w0 --stats \
	    --title "blast_demo over five dt: single-rate (sr) and ratio 4 with fracture_window 2 (mr4, the default), 1 (w1) and 0 (w0); \`make multirate-window\`" \
	    $(foreach r,$(FW_RUNS),$(r)=runs/window/$(r))

# the integration on the paper's specimen cut to a slab (blast_paper:slab, 10 mm thick, 40 mm
# in radius; studies/validation/notes.md §25): single-rate (sr), ratio 4 under the default
# rule (mr4) and without the fracture rule (w0), each at dt = 2 us / N for N of SLAB_N
# (100 is the scene's dt), then at the scene's dt the part-wide row sum (rsp) and
# fracture_class = 1 (fc1); a frame every 10 us, each reported, then
# studies/multirate/multirate_slab.md with each group's range over dt (about 50 minutes on 2 cores)
SLAB_N := 100 104 120
SLAB_RUNS := $(foreach g,sr mr4 w0,$(foreach n,$(SLAB_N),$(g)_$(n))) rsp_100 fc1_100
SLAB_SET_sr := --set "time.multirate={max_ratio=1}"
SLAB_SET_mr4 :=
SLAB_SET_w0 := --set "time.multirate={max_ratio=4, safety=0.5, fracture_window=0}"
SLAB_SET_rsp := --set 'time.multirate={max_ratio=4, safety=0.5, family_factor="row_sum_part"}'
SLAB_SET_fc1 := --set "time.multirate={max_ratio=4, safety=0.5, fracture_class=1}"
.PHONY: multirate-slab
multirate-slab: install
	$(call dt_sweep,sr mr4 w0,SLAB_SET,runs/slab,blast_paper:slab,$(SLAB_N),5)
	$(call dt_sweep,rsp fc1,SLAB_SET,runs/slab,blast_paper:slab,100,5)
	$(PY) benchmarks/multirate_compare.py --out studies/multirate/multirate_slab.md --bands sr,mr4,w0 --stats \
	    --title "blast_paper:slab over three dt: single-rate (sr), ratio 4 under the default rule (mr4) and without the fracture rule (w0); at the scene's dt the part-wide row sum (rsp) and fracture_class = 1 (fc1); \`make multirate-slab\`" \
	    $(foreach r,$(SLAB_RUNS),$(r)=runs/slab/$(r))

# the rock mass on blast_demo (README: The rock mass): the lattice, jitter, Weibull
# strength and both, over 3 seeds, each reported, then studies/model/rockmass_blast_demo.md
# (studies/multirate/rockmass_study.py; about 25 minutes on 2 cores)
.PHONY: rockmass-study
rockmass-study: install
	$(PY) studies/multirate/rockmass_study.py --out runs/rockmass --mpirun "$(MPIRUN)" \
	    --table studies/model/rockmass_blast_demo.md
