# `make docs`: the documentation site (mkdocs-material + mkdocstrings, pinned in
# pyproject.toml's `docs` extra, which scripts/bootstrap.sh installs) from docs/ into
# site/, built strict: a broken link, anchor or reference fails it.  The scene reference,
# the validation summary and the bench table are generated during the build
# (docs/hooks.py, docs/gen_scene_reference.py); tests/test_docs.py runs the same build.
# `make docs-serve` serves it on localhost:8000 while you edit.  `make docs-figures`
# remakes the tutorial's ParaView picture: blast_demo into runs/docs_figures, then
# pvbatch under xvfb-run (scripts/docs_figures.sh; a few minutes).
.PHONY: docs docs-serve docs-figures

export NO_MKDOCS_2_WARNING := 1

docs: install
	$(VENV)/bin/mkdocs build --strict --site-dir site
	@echo "docs: open $(CURDIR)/site/index.html"

docs-serve: install
	$(VENV)/bin/mkdocs serve --strict

docs-figures: install paraview
	$(MPIRUN) -n 2 $(VENV)/bin/mpipd run blast_demo --out runs/docs_figures --overwrite --quiet
	bash scripts/docs_figures.sh runs/docs_figures/run.xdmf docs/img/paraview_damage.png
