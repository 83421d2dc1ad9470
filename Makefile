# The two commands of the README: `make demo` and `make test`. Both build .venv from scratch
# with only Python 3.11 on the machine.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test test-fast tex lint lock bench figures generated clean

# The venv and TeX install side by side (each waits on downloads and the disk more than on a
# core: half a minute saved on a fresh machine), where no password prompt for sudo can be lost
# to a job without the terminal.
ifeq ($(shell id -u),0)
MAKEFLAGS += -j2
endif

# constraints.txt pins every package of the test and demo environment (make lock refreshes it).
# The venv's bytecode is compiled once, on every core (compileall -j 0; pip's own --compile is
# one core), packages' own test folders left out: where PYTHONDONTWRITEBYTECODE is set nothing
# writes it as it imports, and every new process (a CLI run, a Dask worker, a child) compiled
# SymPy, SciPy and NumPy from source again, about 3 s of CPU each (lindstedt.sweep.kinds
# imported in 4.4 s rather than 1.4).
$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet -c constraints.txt --upgrade pip
	$(BIN)/pip install --quiet --no-compile -c constraints.txt -e '.[test]'
	$(BIN)/python -m compileall -q -j 0 -x 'site-packages/.+/tests?/' \
	  "$$($(BIN)/python -c "import sysconfig; print(sysconfig.get_path('purelib'))")" generator \
	  > /dev/null
	touch $(STAMP)

# Re-pins constraints.txt from pyproject.toml's ranges in a scratch venv: run it on purpose,
# then run make test and commit both.
lock:
	rm -rf .lock-venv
	$(PYTHON) -m venv .lock-venv
	.lock-venv/bin/pip install --quiet --upgrade pip
	.lock-venv/bin/pip install --quiet '.[test]'
	{ sed -n '1,3p' constraints.txt; \
	  echo "pip==$$(.lock-venv/bin/pip --version | cut -d' ' -f2)"; \
	  .lock-venv/bin/pip freeze --exclude lindstedt; } > constraints.txt.new
	mv constraints.txt.new constraints.txt
	rm -rf .lock-venv

# pdflatex for the tests that compile every generated .tex (Debian's texlive).
tex:
	@command -v pdflatex >/dev/null 2>&1 || { \
	  SUDO=$$( [ "$$(id -u)" -eq 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends \
	    texlive-latex-base texlive-latex-recommended >/dev/null; }

# Writes only under out/ (ignored by git): the checkout stays clean.
demo: $(STAMP) tex
	$(BIN)/lindstedt demo --out out

# The whole suite in one run on every core (pytest-xdist): whole test files handed to the first
# idle worker, the longest first (tests/conftest.py, tests/durations.json).
SUITE = -n auto --dist loadfile --no-loadscope-reorder
test: $(STAMP) tex
	$(BIN)/ruff check generator tests benchmarks
	$(BIN)/python -m pytest $(SUITE)

test-fast: $(STAMP)
	$(BIN)/python -m pytest $(SUITE) -m exact

lint: $(STAMP)
	$(BIN)/ruff check generator tests benchmarks

bench: $(STAMP)
	$(BIN)/python benchmarks/derive.py
	$(BIN)/python benchmarks/evaluate.py
	$(BIN)/python benchmarks/speed_accuracy.py
	$(BIN)/python benchmarks/q_speed_accuracy.py
	$(BIN)/python benchmarks/driven_speed_accuracy.py
	$(BIN)/python benchmarks/slow_flow.py
	$(BIN)/python benchmarks/ince_strutt.py

# The committed copies: docs/figures (the README's computed figures, byte-identical run to run)
# and generated/ (the default evaluators and LaTeX).
DRIVEN_SYSTEM = x1'' + 0.05*x1' + 2*x1 - x2 + x1**3/2 = f*cos(w*t); x2'' + 0.05*x2' + 2*x2 - x1 = 0
figures: $(STAMP)
	$(BIN)/python -c "from lindstedt.charts import gallery; gallery('docs/figures')"
	$(BIN)/python -c "from lindstedt.charts import slow_flow_figures; slow_flow_figures('docs/figures')"
	$(BIN)/python -c "from lindstedt.charts import PARAMETRIC_FIGURE, parametric_figure; \
	from lindstedt.analysis.parametric import parametric_report; \
	parametric_figure(parametric_report(*PARAMETRIC_FIGURE), 'docs/figures/parametric.png')"
	$(BIN)/python -c "from lindstedt.charts import ince_strutt_figure; \
	ince_strutt_figure('docs/figures/ince_strutt.png')"
	$(BIN)/lindstedt nnm "x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0" \
	  --plot docs/figures/nnm.png > /dev/null
	$(BIN)/lindstedt response "$(DRIVEN_SYSTEM)" --param f=3/10 \
	  --plot docs/figures/response_system.png > /dev/null

generated: $(STAMP)
	$(BIN)/lindstedt generate duffing --order 12 --out generated
	$(BIN)/lindstedt generate pendulum --order 12 --out generated
	$(BIN)/lindstedt generate driven --order 3 --out generated
	$(BIN)/lindstedt generate balance --harmonics 4 --out generated

clean:
	rm -rf $(VENV) out .pytest_cache
