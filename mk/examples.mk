# `make examples`: the worked examples of examples/ (examples/README.md, docs/examples.md),
# each checked, run to its t_end on 2 ranks into runs/examples/NAME/ (--overwrite: a
# rerun replaces the last one) and drawn by `mpipd.post fracture` on a section through
# the rock; each picture is copied to docs/img/examples/NAME.png for the docs page.
# About 5-10 minutes on 2 cores.  `make example-NAME` makes one of them.
EXAMPLES := single_hole paper_charge two_holes_delay jointed_rock

# the section of each picture: a lattice level of the rock that holds no charge or tube
# point (the height each example's header gives; tests/test_examples.py checks it)
EXAMPLE_Z_single_hole := 0.0025
EXAMPLE_Z_paper_charge := 0.002
EXAMPLE_Z_two_holes_delay := 0.0025
EXAMPLE_Z_jointed_rock := 0.002
# further frames drawn (docs/img/examples/NAME_frameK.png): the delayed hole just
# lit (frame 3, t = 6 us) and the joints before the blast (frame 0)
EXAMPLE_FRAMES_two_holes_delay := 3
EXAMPLE_FRAMES_jointed_rock := 0

.PHONY: examples $(addprefix example-,$(EXAMPLES))

examples: $(addprefix example-,$(EXAMPLES))
	@for n in $(EXAMPLES); do $(PY) -c "import h5py; f = h5py.File('runs/examples/$$n/run.h5', 'r'); print('examples: $$n: run file at commit', f.attrs['git_commit'])"; done
	@echo "examples: pictures in $(CURDIR)/docs/img/examples/ (runs in runs/examples/)"

$(addprefix example-,$(EXAMPLES)): example-%: install
	$(VENV)/bin/mpipd check examples/$*.toml > /dev/null
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run examples/$*.toml --out runs/examples/$* --overwrite
	$(MPIRUN) -n 2 $(PY) -m mpipd.post fracture runs/examples/$*/run.h5 --z $(EXAMPLE_Z_$*) --out runs/examples/$*/fracture.png
	mkdir -p docs/img/examples && cp runs/examples/$*/fracture.png docs/img/examples/$*.png
	@for k in $(EXAMPLE_FRAMES_$*); do \
	  echo "$(MPIRUN) -n 2 $(PY) -m mpipd.post fracture runs/examples/$*/run.h5 --z $(EXAMPLE_Z_$*) --frame $$k --out runs/examples/$*/fracture_frame$$k.png"; \
	  $(MPIRUN) -n 2 $(PY) -m mpipd.post fracture runs/examples/$*/run.h5 --z $(EXAMPLE_Z_$*) --frame $$k --out runs/examples/$*/fracture_frame$$k.png || exit 1; \
	  cp runs/examples/$*/fracture_frame$$k.png docs/img/examples/$*_frame$$k.png; \
	done

# Kalthoff-Winkler, the built-in scene (docs/examples.md): run on 2 ranks (~3 minutes),
# the crack angle at each notch tip, and the damage on the level z = 3.75 mm
.PHONY: example-kalthoff_winkler
example-kalthoff_winkler: install
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run kalthoff_winkler --out runs/examples/kalthoff_winkler --overwrite
	$(PY) -m mpipd.post.crack_angle runs/examples/kalthoff_winkler/run.h5 --json runs/examples/kalthoff_winkler/crack_angle.json
	$(MPIRUN) -n 2 $(PY) -m mpipd.post fracture runs/examples/kalthoff_winkler/run.h5 --z 0.00375 --out runs/examples/kalthoff_winkler/fracture.png
	mkdir -p docs/img/examples && cp runs/examples/kalthoff_winkler/fracture.png docs/img/examples/kalthoff_winkler.png
