# `make validate`: the validation record (issue 15), studies/validation/record.md with
# studies/validation/record/<case>/ (each run's report.json and key figures), re-created from
# the run files in VALIDATE_RUNS: each is reported again (python -m mpipd.post report,
# into report/ beside it) and the record is written from those report.json files,
# with the hand-written diagnoses of VALIDATE_NOTES (if the file exists) verbatim.
# A missing run file stops it first with one line naming the file and the command
# that makes it (exit status 2), before anything is written.
#   make validate VALIDATE_RUNS="runs/demo/run.h5"      # another set of runs
.PHONY: validate

# blast_paper_mr4 / _graded_mr4 / _dx1.2_mr4: mpirun -n 2 mpipd run blast_paper[:graded or :dx1.2] --set 'time.multirate={max_ratio=4,safety=0.5}'
#   --set output.every=200 --set output.checkpoint_every=400 (500 for dx1.2) --out runs/blast_paper[_graded or _dx1.2]_mr4
#   (blast_paper steps at ratio 4 by default since 8850a06: the --set multirate is now the scene's own)
# blast_paper_dx1.2_rockmass_mr4 (b820a4a): mpirun -n 2 mpipd run blast_paper:rockmass --set parts.2.dx=1.2e-3
#   --set 'scene.name="blast_paper-dx1.2-rockmass"' --set 'time.multirate={max_ratio=4,safety=0.5}'
#   --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_dx1.2_rockmass_mr4
# blast_paper_dx1.2_contained (922369c, after the gas-neighbourhood rule of notes §12; the gas acts on the granite too, the scene's default
#   since then): mpirun -n 2 mpipd run blast_paper:dx1.2 --set output.every=200
#   --set output.checkpoint_every=500 --out runs/blast_paper_dx1.2_contained
#   (the four rows before it ran with the gas acting on the copper only: case paper_coupling)
# blast_paper_contained (0242812, the full 0.8 mm scene with the contained gas, notes §13): mpirun -n 2 mpipd run blast_paper
#   --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_contained
# blast_paper_dx1.2_gas_contact (b3790a0, the contact with the stretch-following classes, notes §14):
#   mpirun -n 2 mpipd run blast_paper:gas_contact --set parts.2.dx=1.2e-3 --out runs/blast_paper_dx1.2_gas_contact
# blast_paper_dx1.0 (a153522, the named case, notes §15): mpirun -n 2 mpipd run blast_paper:dx1.0
#   --set output.every=200 --set output.checkpoint_every=400 --out runs/blast_paper_dx1.0
# blast_paper_kappa (5a6162e, the full 0.8 mm scene under the class rule that follows the family, notes §16):
#   mpirun -n 2 mpipd run blast_paper --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_kappa
# blast_paper_graded_contained (175ed73, the graded case with the contained gas and the class rule of §16, notes §17):
#   mpirun -n 2 mpipd run blast_paper:graded --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_graded_contained
# blast_paper_buffer_graded (ac55d26, the full 0.8 mm scene under the graded buffer, notes §18):
#   mpirun -n 2 mpipd run blast_paper --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_buffer_graded
# blast_paper_dx1.2_buffer_graded (d15d3f8, dx1.2 with the contained gas under the graded buffer, notes §19):
#   mpirun -n 2 mpipd run blast_paper:dx1.2 --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_dx1.2_buffer_graded
# blast_paper_row_sum (cd94582, the full 0.8 mm scene under the row-sum family factor, notes §19):
#   mpirun -n 2 mpipd run blast_paper --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_row_sum
# blast_paper_row_sum_part (a6222a4, the full 0.8 mm scene under the part-wide row sum, notes §20):
#   mpirun -n 2 mpipd run blast_paper --set 'time.multirate={ max_ratio = 4, safety = 0.5, family_factor = "row_sum_part" }' --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_row_sum_part
# blast_paper_window0 (bce4717, the full 0.8 mm scene without the fracture rule, notes §21):
#   mpirun -n 2 mpipd run blast_paper --set 'time.multirate={ max_ratio = 4, safety = 0.5, fracture_window = 0 }' --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_window0
# blast_paper_kernels (9c20d47, the full 0.8 mm scene with the bond loops rewritten, rounding only, notes §22):
#   mpirun -n 2 mpipd run blast_paper --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_kernels
# The record of 2026-12-03 (notes §12) was made from report folders for the four copper-only
#   rows, whose run files were not on the machine: runs/rows/<case> = studies/validation/record/<case>
#   as of 8edcf30 (`git archive 8edcf30 studies/validation/record/<case>`), beside the three new run reports; the record of 2026-12-04 (notes §13) the same, with runs/blast_paper_contained/report beside them; the record of 2026-12-04 (notes §14) from report folders for all eight earlier rows (runs/rows/<case> = studies/validation/record/<case> at 19b1ac2) and runs/blast_paper_dx1.2_gas_contact/report; the record of 2026-12-04 (notes §15) the same, with runs/blast_paper_dx1.0/report after runs/rows/blast_paper_contained; the record of 2026-12-04 (notes §16) the same, with runs/blast_paper_kappa/report after runs/blast_paper_dx1.0/report; the record of 2026-12-04 (notes §17) from report folders for all eleven earlier rows (runs/rows/<case> = studies/validation/record/<case> at db5f253: the machine was new) with runs/blast_paper_graded_contained/report after runs/rows/blast_paper_kappa. The record of 2026-12-05 (notes §18) the same, with runs/blast_paper_buffer_graded/report after runs/blast_paper_graded_contained/report. The record of 2026-12-05 (notes §19) the same, with runs/blast_paper_row_sum/report and runs/blast_paper_dx1.2_buffer_graded/report after runs/blast_paper_buffer_graded/report. The record of 2026-12-05 (notes §20) the same, with runs/blast_paper_row_sum_part/report after runs/blast_paper_dx1.2_buffer_graded/report. The record of 2026-12-05 (notes §21) from report folders for all sixteen earlier rows (runs/rows/<case> = studies/validation/record/<case> at 110e037: the machine was new) with runs/blast_paper_window0/report after runs/rows/blast_paper_row_sum_part (the earlier rows' PNGs, re-encoded by the run, checked out again). The record of 2026-12-05 (notes §22) the same (the seventeen earlier rows from runs/rows/<case> and runs/blast_paper_window0/report), with runs/blast_paper_kernels/report after runs/blast_paper_window0/report. The record of 2026-12-05 (notes §23) the same, with runs/blast_paper_single_rate/report after runs/blast_paper_kernels/report. The record of 2026-12-05 (notes §24, §25) the same, with runs/blast_paper_index/report after runs/blast_paper_single_rate/report. The record of 2026-12-06 (notes §33) and after: `make record` (below).
# blast_paper_single_rate (1fce7df, the full 0.8 mm scene with the paper's single-rate integration, notes §23):
#   mpirun -n 2 mpipd run blast_paper:single_rate --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_single_rate
# blast_paper_index (0951571, the full 0.8 mm scene with the masked indices, bit for bit §22's physics, notes §24):
#   mpirun -n 2 mpipd run blast_paper --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_index
# blast_paper_case1 (7d0cd09, Table 3's case 1 at the paper's geometry, notes §27; case<k> the same):
#   mpirun -n 2 mpipd run blast_paper:case1 --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_case1
# blast_paper_case2 (11f9901 to step 920, then resumed at c65e0b2, the same physics, notes §29): the same with case2,
#   then mpirun -n 2 mpipd run --restart runs/blast_paper_case2/checkpoint.h5
# blast_paper_case5 (2103603, notes §32) and blast_paper_case6 (553bbef, notes §32; the commits between them
#   change no built-in scene's arithmetic): the same with case5 and case6
# blast_paper_slab (a71b23f, notes §33): the same with slab (the integration's test bed, 10 mm thick, 40 mm in radius)
# blast_paper_case3 (cd19d8e, whose mpipd/ is a71b23f's: only postprocess changed between them; notes §33): the same with case3
# blast_paper_case4 (a7ab5a3 to step 2540, then resumed at ed91c1a, the same mpipd/; notes §34): the same with case4,
#   then mpirun -n 2 mpipd run --restart runs/blast_paper_case4/checkpoint.h5
# blast_paper_paper_coupling (c008304, after the gas's volume-strain bound, notes §34): the same with paper_coupling
# blast_paper_rockmass (61f49a6 to step 2240, then resumed at 2bada73; the mpipd/ of both is c008304's, notes §35):
#   the same with rockmass, then mpirun -n 2 mpipd run --restart runs/blast_paper_rockmass/checkpoint.h5
# blast_paper_rerun (1e1fe43, whose physics is c008304's; notes §36): the base scene again after the stable-step
#   fallback and the gas's volume-strain bound: mpirun -n 2 mpipd run blast_paper --set output.every=200
#   --set output.checkpoint_every=500 --out runs/blast_paper_rerun
# blast_paper_dx0.7 (a6720de to step 1840, then resumed at c54853e, whose mpipd/ differs only in how broken bonds become gid pairs and back and in a log line's helper (0ae01ec);
#   the physics of both is c008304's, notes §37): mpirun -n 2 mpipd run blast_paper:dx0.7
#   --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_dx0.7,
#   then mpirun -n 2 mpipd run --restart runs/blast_paper_dx0.7/checkpoint.h5
# blast_paper_gas_contact (eb82169 to step 3080, stopped with SIGUSR1 for `make bench`, then resumed at 307754a, whose
#   mpipd/ changes only the failure line's text of the over-dt warning; the case at dt 5e-9 s, max_ratio 8, notes §42):
#   mpirun -n 2 mpipd run blast_paper:gas_contact --out runs/blast_paper_gas_contact,
#   then mpirun -n 2 mpipd run --restart runs/blast_paper_gas_contact/checkpoint.h5
# blast_paper_seamless (started at 394558f, stopped with SIGUSR1 at steps 400 and 4800, resumed at 394558f and at
#   77b4891, whose mpipd/ is 394558f's: one physics throughout; the case at dt 1e-8 s, max_ratio 8, notes §44):
#   mpirun -n 2 mpipd run blast_paper:seamless --out runs/blast_paper_seamless,
#   then mpirun -n 2 mpipd run --restart runs/blast_paper_seamless/checkpoint.h5 (twice)
# blast_paper_case5_rerun (77b4891, whose mpipd/ is 394558f's; case 5 run again for the ring-crack measure of §33,
#   notes §45): mpirun -n 2 mpipd run blast_paper:case5 --set output.every=200 --set output.checkpoint_every=500
#   --out runs/blast_paper_case5_rerun
# blast_paper_rerun2 (27a8378, whose mpipd/ is 394558f's: the base scene at the physics of seamless and case5_rerun,
#   for the ring arcs at every frame beside case 5's, notes §46): mpirun -n 2 mpipd run blast_paper
#   --set output.every=200 --set output.checkpoint_every=500 --out runs/blast_paper_rerun2
# blast_paper_case6_rerun (d531082, whose mpipd/ differs from 394558f's only in the end-checkpoint message, cli.py, checkpoint.py:
#   case 6 at the physics of rerun2 and case5_rerun, for its ring arcs at every frame, notes §47):
#   mpirun -n 2 mpipd run blast_paper:case6 --set output.every=200 --set output.checkpoint_every=500
#   --out runs/blast_paper_case6_rerun
# blast_paper_eq35 (04370ba, the base scene at the paper's model: Eq. 35's pressure, the gas on the copper only,
#   the spring-fallback fix; notes §48; the Summary's row): mpirun -n 2 mpipd run blast_paper --set output.every=200
#   --set output.checkpoint_every=500 --out runs/blast_paper_eq35
# blast_paper_eos (ee4cce2, the base with Eq. 25's cubic EOS: issue 60 item 5's second row; physics of 04370ba):
#   mpirun -n 2 mpipd run blast_paper:eos_pressure --set output.every=200 --set output.checkpoint_every=500
#   --out runs/blast_paper_eos
VALIDATE_RUNS ?= runs/blast_paper_mr4/run.h5 runs/blast_paper_graded_mr4/run.h5 runs/blast_paper_dx1.2_mr4/run.h5 \
    runs/blast_paper_dx1.2_rockmass_mr4/run.h5 runs/blast_paper_dx1.2_contained/run.h5 \
    runs/blast_paper_contained/run.h5 runs/blast_paper_dx1.0/run.h5 runs/blast_paper_kappa/run.h5 runs/blast_paper_graded_contained/run.h5 \
    runs/blast_paper_buffer_graded/run.h5 runs/blast_paper_row_sum/run.h5 runs/blast_paper_dx1.2_buffer_graded/run.h5 \
    runs/blast_paper_row_sum_part/run.h5 runs/blast_paper_window0/run.h5 runs/blast_paper_kernels/run.h5 \
    runs/blast_paper_single_rate/run.h5 runs/blast_paper_index/run.h5 runs/blast_paper_case1/run.h5 runs/blast_paper_case2/run.h5 \
    runs/blast_paper_case3/run.h5 runs/blast_paper_case4/run.h5 runs/blast_paper_case5/run.h5 runs/blast_paper_case6/run.h5 \
    runs/blast_paper_slab/run.h5 runs/blast_paper_paper_coupling/run.h5 runs/blast_paper_rockmass/run.h5 \
    runs/blast_paper_rerun/run.h5 runs/blast_paper_dx0.7/run.h5 \
    runs/blast_paper_dx1.2_gas_contact/run.h5 runs/blast_paper_gas_contact/run.h5 runs/blast_paper_seamless/run.h5 \
    runs/blast_paper_case5_rerun/run.h5 runs/blast_paper_rerun2/run.h5 runs/blast_paper_case6_rerun/run.h5 \
    runs/demo/run.h5 runs/blast_demo_dx0.8/run.h5 runs/blast_paper_eq35/run.h5 \
    runs/blast_paper_eos/run.h5
VALIDATE_OUT ?= studies/validation/record
VALIDATE_NOTES ?= studies/validation/notes.md
VALIDATE_RANKS ?= 2
# the row of the record's Summary table: the base scene at the paper's model (issue 60)
VALIDATE_BASE ?= blast_paper_eq35

validate: install
	@$(PY) -m mpipd.post validate --check $(VALIDATE_RUNS)
	$(MPIRUN) -n $(VALIDATE_RANKS) $(PY) -m mpipd.post validate --out $(VALIDATE_OUT) \
	    $(VALIDATE_RUNS) $(if $(wildcard $(VALIDATE_NOTES)),--notes $(VALIDATE_NOTES)) \
	    $(if $(filter $(VALIDATE_BASE),$(notdir $(patsubst %/run.h5,%,$(VALIDATE_RUNS)))),--base $(VALIDATE_BASE))

# `make diagnoses`: the cheaper runs behind studies/validation/notes.md's diagnoses, each
# changing one thing, and their tables under studies/diagnoses/out/ (a run file that exists
# under runs/diag/ is reused; delete it to run it again).
# The crushed zone (notes §43): the slab to 16 us with close frames of pressure and
# failure mode, as it is and with one change each (a linear EOS; JH2's T doubled, a
# diagnosis, not a case), each read by failure_pressure.py.
FAILP_RUN = run blast_paper:slab --set time.t_end=1.6e-5 --set output.every=4 \
	--set 'output.fields=["pressure","failure_mode","damage"]' --set output.checkpoint_every=0
FAILP_slab_failp_linear = --set materials.granite.K2=0.0 --set materials.granite.K3=0.0
FAILP_slab_failp_T108 = --set materials.granite.T=108e6
FAILP_CASES = slab_failp slab_failp_linear slab_failp_T108
# on full rows (a row without its run file here is skipped with a line saying so): the
# crushed zone by mode (--crushed-only: their frames are microseconds apart) and each
# crack-density zone's share inside and beyond r = 10 mm, the seamless band's edge (§44);
# the ring arcs at every frame (§45); then the direct wave's peak-arrival speed of every
# row that stores first-pulse peak times
FAILP_ROWS = gas_contact seamless case5_rerun rerun2 case6_rerun

.PHONY: diagnoses
diagnoses: install
	$(PY) studies/diagnoses/wave_speed.py --study --mpirun "$(MPIRUN)" \
	    --out studies/diagnoses/out/wave_ring_elastic.md
	$(foreach c,$(FAILP_CASES),{ test -f runs/diag/$(c)/run.h5 || $(MPIRUN) -n 1 \
	    $(VENV)/bin/mpipd $(FAILP_RUN) $(FAILP_$(c)) --out runs/diag/$(c); } && \
	    $(PY) studies/diagnoses/failure_pressure.py runs/diag/$(c)/run.h5 \
	    > runs/diag/$(c)/failure_pressure.txt && \
	    cp runs/diag/$(c)/failure_pressure.txt studies/diagnoses/out/failure_pressure_$(c).txt &&) true
	@for r in $(FAILP_ROWS); do f=runs/blast_paper_$$r/run.h5; \
	    if test -f $$f; then echo "failure_pressure.py $$f --crushed-only"; \
	    mkdir -p runs/diag/$$r || exit 1; \
	    $(PY) studies/diagnoses/failure_pressure.py $$f --crushed-only \
	    > runs/diag/$$r/failure_pressure.txt || exit 1; \
	    $(PY) studies/diagnoses/zone_split.py $$f > runs/diag/$$r/zone_split.txt || exit 1; \
	    $(PY) studies/diagnoses/ring_history.py $$f > runs/diag/$$r/ring_history.txt || exit 1; \
	    cp runs/diag/$$r/failure_pressure.txt studies/diagnoses/out/failure_pressure_$$r.txt || exit 1; \
	    cp runs/diag/$$r/zone_split.txt studies/diagnoses/out/zone_split_$$r.txt || exit 1; \
	    cp runs/diag/$$r/ring_history.txt studies/diagnoses/out/ring_history_$$r.txt || exit 1; \
	    else echo "skip $$r: no $$f (its command is above VALIDATE_RUNS)"; fi; done
	@mkdir -p runs/diag && $(PY) studies/diagnoses/peak_arrival_rows.py studies/validation/record \
	    > runs/diag/peak_arrival_rows.txt && cp runs/diag/peak_arrival_rows.txt studies/diagnoses/out/

# compare_rows(OUT, TITLE, BASE_LABEL=BASE_DIR, ROWS, WHAT): the comparison table of
# `make sensitivity`, `make model-cases` and `make resolution` — the base row beside every
# row dir in ROWS (labelled by its name after blast_paper_), each with its difference from
# the base, written to OUT by benchmarks/multirate_compare.py from the rows' report.json.
# No row: one line naming WHAT is missing, exit status 2.
define compare_rows
	@test -n "$(strip $(4))" || { echo "no $(5) in studies/validation/record/ to set beside the base: run one and make validate with it first" >&2; exit 2; }
	$(PY) benchmarks/multirate_compare.py --out $(1) --title "$(2)" \
	    $(3) $(foreach d,$(4),$(patsubst blast_paper_%,%,$(notdir $(d)))=$(d))
endef

# `make sensitivity`: Table 3's cases (Fig. 22) at the paper's geometry, from the rows of
# the record: the base scene (SENS_BASE, the default rule's full run) beside every case
# row studies/validation/record/blast_paper_case<k>/ that exists, and the base run again at a later
# commit (blast_paper_rerun, notes §36: the base's own shift) and case 5 run again at a
# later commit (blast_paper_case5_rerun, notes §45: its ring cracks), the base again beside
# it (blast_paper_rerun2, §46) and case 6 again (blast_paper_case6_rerun, §47), in
# studies/model/sensitivity_blast_paper.md. A case row is made by its run (about an hour on 2
# ranks; the commands are above), its report and `make validate` with it in VALIDATE_RUNS.
SENS_BASE ?= studies/validation/record/blast_paper_index
SENS_ROWS ?= $(wildcard studies/validation/record/blast_paper_rerun) $(sort $(wildcard studies/validation/record/blast_paper_case[1-6])) \
    $(wildcard studies/validation/record/blast_paper_case5_rerun) $(wildcard studies/validation/record/blast_paper_rerun2) \
    $(wildcard studies/validation/record/blast_paper_case6_rerun)
SENS_OUT ?= studies/model/sensitivity_blast_paper.md
.PHONY: sensitivity
sensitivity: install
	$(call compare_rows,$(SENS_OUT),Table 3 at the paper's geometry: the base scene (Table 1) and each case run so far; \`make sensitivity\`,table1=$(SENS_BASE),$(SENS_ROWS),case row (studies/validation/record/blast_paper_case<k>/))

# `make model-cases`: the named cases at the paper's geometry that change the model rather
# than Table 3's parameters (the rock mass, the paper's gas coupling, the gas contact, the
# seamless band) and the base scene run again at a later commit, each row that exists
# beside the base scene's (SENS_BASE), in studies/model/model_cases_blast_paper.md.
MODEL_ROWS ?= $(wildcard $(addprefix studies/validation/record/blast_paper_,rerun rockmass paper_coupling gas_contact seamless))
MODEL_OUT ?= studies/model/model_cases_blast_paper.md
.PHONY: model-cases
model-cases: install
	$(call compare_rows,$(MODEL_OUT),The model's own cases at the paper's geometry beside the base scene; \`make model-cases\`,base=$(SENS_BASE),$(MODEL_ROWS),row of MODEL_ROWS)

# `make resolution`: the discretisation study at the paper's geometry (the paper's §3.4):
# the rock at 0.8 mm (RES_BASE: the base scene's run on the physics of dx0.7's run,
# blast_paper_rerun) beside every other rock dx with a row, coarse to fine, in
# studies/model/resolution_blast_paper.md. The 1.2 and 1.0 mm rows predate the stable-step fallback
# and the gas's bound (their commits are in the table): notes §37 reads them with §36.
RES_BASE ?= studies/validation/record/blast_paper_rerun
RES_ROWS ?= $(wildcard $(addprefix studies/validation/record/blast_paper_,dx1.2_contained dx1.0 dx0.7))
RES_OUT ?= studies/model/resolution_blast_paper.md
.PHONY: resolution
resolution: install
	$(call compare_rows,$(RES_OUT),The rock's dx at the paper's geometry beside the 0.8 mm scene; \`make resolution\`,dx0.8=$(RES_BASE),$(RES_ROWS),other rock dx)

# `make record`: the same record on a machine that lacks some of VALIDATE_RUNS' run files
# (a new machine keeps none): each row from its run's report or run file when it is here,
# else from the row's committed folder studies/validation/record/<case>/ at HEAD, extracted into
# runs/rows/<case> (studies/validation/record_rows.py; the record names that folder as the row's
# report). Figures already shrunk are copied unchanged, so a row read back is the same.
.PHONY: record
record: install
	@mkdir -p runs
	@$(PY) studies/validation/record_rows.py --rows runs/rows $(VALIDATE_RUNS) > runs/record_inputs.txt
	$(MPIRUN) -n $(VALIDATE_RANKS) $(PY) -m mpipd.post validate --out $(VALIDATE_OUT) \
	    $$(cat runs/record_inputs.txt) $(if $(wildcard $(VALIDATE_NOTES)),--notes $(VALIDATE_NOTES)) \
	    $(if $(filter $(VALIDATE_BASE),$(notdir $(patsubst %/run.h5,%,$(VALIDATE_RUNS)))),--base $(VALIDATE_BASE))

# `make effective-load`: the slab of blast_paper (blast_paper:slab) at the base's model,
# with Eq. 25's pressure, and with the gas pressure scaled by 0.5 and 0.25 (the cases
# load0.5 / load0.25 on the slab), each reported, then the table
# studies/model/effective_load_slab.md (issue 60, item 7; about 30 minutes on 2 cores alone)
EL_RUNS := eq35 eos pf0.5 pf0.25
EL_SET_eq35 :=
EL_SET_eos := --set 'materials.granite.pressure="eos"'
EL_SET_pf0.5 := --set materials.explosive.pressure_factor=0.5
EL_SET_pf0.25 := --set materials.explosive.pressure_factor=0.25
.PHONY: effective-load
effective-load: install
	$(foreach r,$(EL_RUNS),$(MPIRUN) -n 2 $(VENV)/bin/mpipd run blast_paper:slab --out runs/slab_$(r) \
	    --overwrite --quiet --set output.every=100 $(EL_SET_$(r)) && \
	    $(MPIRUN) -n 2 $(PY) -m mpipd.post report runs/slab_$(r)/run.h5 --out runs/slab_$(r)/report > /dev/null &&) true
	$(PY) benchmarks/multirate_compare.py --out studies/model/effective_load_slab.md \
	    --title "blast_paper:slab at the base's model (eq35), with Eq. 25's pressure (eos) and with the gas pressure x 0.5 and x 0.25; \`make effective-load\`" \
	    $(foreach r,$(EL_RUNS),$(r)=runs/slab_$(r))

# `make paper-model`: the base scene at the paper's model (row blast_paper_eq35: Eq. 35's
# pressure, the gas on the copper only, the spring-fallback fix; issue 60) beside the
# previous model's last base row (blast_paper_rerun2), from the rows' report.json
PM_BASE ?= studies/validation/record/blast_paper_rerun2
PM_ROWS ?= $(wildcard studies/validation/record/blast_paper_eq35 studies/validation/record/blast_paper_eos)
PM_OUT ?= studies/model/paper_model_blast_paper.md
.PHONY: paper-model
paper-model: install
	$(call compare_rows,$(PM_OUT),The base scene at the paper's model (eq35) beside the previous model's base row (previous); \`make paper-model\`,previous=$(PM_BASE),$(PM_ROWS),blast_paper_eq35 row)
