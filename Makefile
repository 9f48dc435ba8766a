# swarm: two commands on a fresh machine with Python 3.11+ and make:
#   make demo   installs everything and runs the default swarm
#   make test   installs everything and runs the tests
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: install browser docker demo test lint experiments reproduce bench clean

install: $(STAMP)

$(STAMP): pyproject.toml examples/flocking/pyproject.toml examples/grid_walk/pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "swarm needs Python 3.11 or newer"'
	@echo "swarm: installing into $(VENV) (a few minutes the first time; errors, if any, are shown)"
	@$(PYTHON) -m venv $(VENV)
	@$(BIN)/pip install -qq --upgrade pip
	@$(BIN)/pip install -qq -e '.[dev]'
	@$(BIN)/pip install -qq -e examples/flocking  # a controller package of a user's, tested with the rest
	@$(BIN)/pip install -qq -e examples/grid_walk  # a grid controller package of a user's, tested with the rest
	@touch $(STAMP)
	@echo "swarm: installed: $(BIN)/swarm --help"

demo: install
	@echo "swarm: 20 agent processes forage on setup1 (the first run compiles the kernels, about a minute)"
	@$(BIN)/swarm up setup1 --agents 20 --seed 1

# The web-viewer test drives Debian's chromium headless (Playwright, no browser download).
browser:
	@command -v chromium >/dev/null || { command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] \
		&& apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; } \
		|| echo "note: chromium not installed (needs root and apt); the web viewer test will be skipped"

# The compose test starts a real Docker engine (Debian's docker.io, compose v1, debootstrap for a base image).
docker:
	@{ command -v dockerd && command -v docker-compose && command -v debootstrap && command -v ip; } >/dev/null \
		|| { command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] && apt-get update -qq \
		&& DEBIAN_FRONTEND=noninteractive apt-get install -y -qq docker.io docker-compose debootstrap iproute2 >/dev/null; } \
		|| echo "note: Docker engine not installed (needs root and apt); the compose test will be skipped"

test: install browser docker
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/python -m pytest -q -n 2 --dist loadfile --durations=25

lint: install
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

experiments: install
	$(BIN)/swarm experiment table1 --reps 1000
	$(BIN)/swarm experiment table2 --reps 5000
	$(BIN)/swarm experiment table3 --reps 50
	$(BIN)/swarm experiment ants --reps 20
	$(BIN)/swarm experiment congestion --reps 10 --seed 1

reproduce: install
	$(BIN)/swarm reproduce all --out docs/reports

bench: install
	$(BIN)/swarm bench engine

clean:
	rm -rf $(VENV) build *.egg-info results .pytest_cache .ruff_cache
