# Two commands do all the set-up: `make run` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test test-fast test-slurm slurm-up slurm-down bench clean-venv

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[test,sweep]'
	# mypy and pyright resolve filmfriction.* from the checkout: a folder on the venv's
	# path (a .pth file) holds a link named filmfriction to this checkout
	mkdir -p $(VENV)/src && ln -sfn "$(CURDIR)" $(VENV)/src/filmfriction
	$(BIN)/python -c 'import pathlib, site; pathlib.Path(site.getsitepackages()[0], "filmfriction-src.pth").write_text("$(CURDIR)/$(VENV)/src\n")'
	touch $(STAMP)

# The main job: the default study, then a preview of the Klein-similar scene (about 1.5 min
# on 2 cores), and one report that compares the two with Klein's experiment.  Each make run
# gets its own folder under runs/ (a run directory is never overwritten).
STUDY := runs/study-$(shell date +%Y%m%d-%H%M%S)

run: $(STAMP)
	$(BIN)/filmfriction run --out $(STUDY)/stick-slip
	$(BIN)/filmfriction run sfb-similar --fidelity preview --out $(STUDY)/sfb-similar-preview
	$(BIN)/filmfriction report $(STUDY)/stick-slip --compare $(STUDY)/sfb-similar-preview --out $(STUDY)/report.html

test: $(STAMP)
	$(BIN)/python -m pytest -q

# the edit-test loop: everything but the real-LAMMPS tests (marker md), on two processes
test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -m "not md" -n 2

# A one-node Slurm on this machine (Debian 12, as root: apt-get, munge, slurmdbd on MariaDB),
# for the Slurm tests (marker slurm; skipped with the reason when no cluster answers)
slurm-up:
	tests/slurm/start-cluster.sh

slurm-down:
	tests/slurm/stop-cluster.sh

test-slurm: $(STAMP)
	$(BIN)/python -m pytest -q -m slurm

bench: $(STAMP)
	$(BIN)/filmfriction bench

clean-venv:
	rm -rf $(VENV)
