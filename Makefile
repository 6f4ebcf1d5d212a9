# Two entry points for a fresh Debian machine with Python 3.11 and root:
#   make run   - virtual environment, install, start the dashboard with the demo takes
#   make test  - install what the tests need (system packages too), then lint, types and the suite,
#                with the image built and started beside it (scripts/image/check.sh)
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
HOST ?= 127.0.0.1
PORT ?= 8000
APT_PACKAGES := chromium libegl1 libegl-mesa0 libgl1-mesa-dri postgresql

.PHONY: run test venv install install-dev system-deps js-deps lint typecheck unit unit-and-image coverage serve clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

venv: $(BIN)/python

install: venv
	$(BIN)/pip install --quiet -e .

install-dev: venv
	$(BIN)/pip install --quiet -e ".[dev]"

# Debian packages the tests use: chromium (browser tests), Mesa EGL (off-screen pyvista),
# PostgreSQL (store and API tests against a real server), and Node.js with npm when the machine
# has no node (three.js for the 3D views, ESLint, node --test). Installed only when missing.
system-deps:
	@missing=""; for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	command -v node >/dev/null 2>&1 || missing="$$missing nodejs"; \
	command -v npm >/dev/null 2>&1 || missing="$$missing npm"; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	fi

# The dashboard's JavaScript lint and unit tests (ESLint, node --test) need Node >= 20 and the
# npm packages pinned in package-lock.json, installed from the npm registry. three.js and
# Plotly's cartesian bundle are served from frontend/vendor/, copied from their npm packages by
# scripts/vendor_js.py (the list the package build uses too, so a wheel carries them).
JS_VENDOR := frontend/vendor/three/three.module.min.js

$(JS_VENDOR): package.json package-lock.json scripts/vendor_js.py
	$(PYTHON) scripts/vendor_js.py

js-deps: $(JS_VENDOR)

run: install system-deps js-deps
	$(BIN)/mocapqa serve --host $(HOST) --port $(PORT) --demo

lint: install-dev js-deps
	npx eslint frontend/js tests/js
	$(BIN)/ruff check backend tests scripts setup.py
	$(BIN)/ruff format --check backend tests scripts setup.py
	$(BIN)/lint-imports
	$(BIN)/python scripts/function_length.py backend
	$(BIN)/check-jsonschema --builtin-schema vendor.compose-spec docker-compose.yml
	$(BIN)/hadolint Dockerfile

typecheck: install-dev
	$(BIN)/mypy

unit: install-dev system-deps js-deps
	node --test tests/js/
	bash scripts/with-postgres.sh $(BIN)/python -m pytest -q --durations=20

# The suite with the image check (image-check, below) running beside it: the check mostly
# waits on downloads, the suite on the CPU, so together they take about as long as the suite.
unit-and-image: install-dev system-deps js-deps image-deps
	node --test tests/js/
	bash scripts/image/alongside.sh bash scripts/with-postgres.sh $(BIN)/python -m pytest -q --durations=20

# Line and branch coverage of the same suite: about a quarter slower, so not part of `make test`.
coverage: install-dev system-deps js-deps
	bash scripts/with-postgres.sh $(BIN)/python -m pytest -q --cov --cov-report=term:skip-covered

test: install-dev system-deps lint typecheck unit-and-image

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache node_modules frontend/vendor

# The image built from the repository's Dockerfile and started under chroot, as root
# (scripts/image/check.sh, docs/deploy.md): base images from Debian's packages (cached in
# ~/.cache/mocapqa/image), `podman build --isolation chroot`, then the server's health, a batch
# of real takes and the compose file's Dask scheduler and worker, all as the image's user.
# Debian's podman and debootstrap (and npm, which fetches the node base's npm) are installed
# when missing, like system-deps.
IMAGE_APT_PACKAGES := podman debootstrap

.PHONY: image-deps image-base image-check

image-deps:
	@missing=""; for p in $(IMAGE_APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	command -v npm >/dev/null 2>&1 || missing="$$missing npm"; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	fi

image-base: image-deps
	bash scripts/image/base.sh

image-check: image-deps
	bash scripts/image/check.sh
