# Set-up and entry points. `make demo` runs the main job, `make test` the test suite;
# both create the virtual environment and install the package first.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test wheel-check bench zoo clean

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet --only-binary=:all: -c constraints.txt -e ".[test,docs,montecarlo,fleet,long-logs,ros,xacro]"
	$(BIN)/python -m dynid.warm_up  # compiles the numba kernels into their cache, so the first run does not
	touch $(STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/dynid run

test: $(STAMP)
	$(BIN)/ruff check  # lint ([tool.ruff] in pyproject.toml: pyflakes, pycodestyle, imports, bugbear, pyupgrade)
# the type check of src/dynid ([tool.mypy] in pyproject.toml) and the docs site (mkdocs.yml, into .site/; a warning,
# such as a broken link, fails it) run beside the test suite on one core, their output printed after it; any of the
# three failing fails the target. Bytecode is written (PYTHONDONTWRITEBYTECODE emptied, as Python runs by default): each
# worker's collection and every dynid subprocess read the compiled modules of a run before (benchmarks/NOTEBOOK.md)
	log=$$(mktemp); { $(BIN)/python -m mypy && \
	  $(BIN)/python -m mkdocs build --strict ; } > $$log 2>&1 & checks=$$!; \
	PYTHONDONTWRITEBYTECODE= MPLBACKEND=Agg $(BIN)/python -m pytest -q -n 2; tests=$$?; \
	wait $$checks; checked=$$?; cat $$log; rm -f $$log; [ $$tests -eq 0 ] && [ $$checked -eq 0 ]

wheel-check: $(STAMP)  # the wheel as a user installs it, in a fresh virtualenv: example, identify, export (CI)
	rm -rf .wheel-check && mkdir -p .wheel-check/dist
	$(BIN)/pip wheel --quiet --no-deps -w .wheel-check/dist .
	$(PYTHON) -m venv .wheel-check/venv
	.wheel-check/venv/bin/pip install --quiet --only-binary=:all: -c constraints.txt .wheel-check/dist/dynid-*.whl
	cd .wheel-check && venv/bin/dynid example ur10e try -q
	cd .wheel-check/try && ../venv/bin/dynid identify ur10e.toml -q && test -s dynid-identify/ur10e.urdf \
	  && ../venv/bin/dynid export ur10e.toml --results dynid-identify/results.json --urdf ur10e-identified.urdf \
	     --mjcf ur10e-identified.xml -q && test -s ur10e-identified.urdf && test -s ur10e-identified.xml
	@echo "wheel-check: $$(.wheel-check/venv/bin/pip list --format=freeze | wc -l) packages," \
	  "$$(du -sm .wheel-check/venv/lib/python3*/site-packages | cut -f1) MB installed; example, identify, export ran"

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_table.py
	$(BIN)/python benchmarks/bench_regressor.py
	$(BIN)/python benchmarks/bench_objective.py
	$(BIN)/python benchmarks/bench_identify_memory.py
	$(BIN)/python benchmarks/bench_excitation_design.py

zoo: $(STAMP)  # dynid's defaults on nine public arm descriptions simulated in MuJoCo (benchmarks/zoo, ~15 min)
	$(BIN)/pip install --quiet --only-binary=:all: -c constraints.txt -e ".[zoo]"
	$(BIN)/python benchmarks/zoo/zoo.py

clean:
	rm -rf $(VENV) .wheel-check dynid-zoo dynid-run dynid-identify dynid-validate dynid-excite dynid-montecarlo dynid-fleet dynid-monitor .site
