# Two commands do all the set-up: `make run` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test test-fast bench clean-venv

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[test,sweep]'
	touch $(STAMP)

run: $(STAMP)
	$(BIN)/filmfriction run

test: $(STAMP)
	$(BIN)/python -m pytest -q

# the edit-test loop: everything but the real-LAMMPS tests (marker md)
test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -m "not md"

bench: $(STAMP)
	$(BIN)/filmfriction bench

clean-venv:
	rm -rf $(VENV)
