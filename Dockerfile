# syntax=docker/dockerfile:1
# The mocapqa image: the dashboard (`mocapqa serve`), the batch CLI and the Dask scheduler and
# workers of the compose file's "dask" profile all run from it, so every process has the same
# Python, numpy, dask and distributed versions.

# three.js (the dashboard's 3D views) and Plotly's cartesian bundle (its charts) come from the npm
# registry, pinned by package-lock.json.
#
# A network that inspects TLS needs its CA bundle for the two registries (npm's, PyPI's): pass
# the machine's as a build secret, mounted for the downloading steps and never copied into the
# image; without it the images' own CAs are used and nothing changes:
#   docker build --secret id=ca-certificates,src=/etc/ssl/certs/ca-certificates.crt .
FROM node:20.18.0-bookworm-slim AS three
WORKDIR /js
COPY package.json package-lock.json ./
RUN --mount=type=secret,id=ca-certificates,target=/run/secrets/ca-certificates.crt \
    if [ -s /run/secrets/ca-certificates.crt ]; then \
      export NODE_EXTRA_CA_CERTS=/run/secrets/ca-certificates.crt; \
    fi \
 && npm ci --omit=dev --no-audit --no-fund && mkdir -p vendor/three \
 && cp node_modules/three/build/three.module.min.js node_modules/three/build/three.core.min.js \
       node_modules/three/LICENSE vendor/three/ \
 && mkdir -p vendor/plotly && cp node_modules/plotly.js-cartesian-dist-min/plotly-cartesian.min.js \
       node_modules/plotly.js-cartesian-dist-min/LICENSE vendor/plotly/

FROM python:3.11.9-slim-bookworm

# Mesa's EGL/GL libraries let pyvista render off-screen (PNG thumbnails, contact sheets);
# without them the app falls back to SVG drawings. curl is not needed: the healthcheck is Python.
RUN apt-get update \
    && apt-get install -y --no-install-recommends \
       libegl1=1.6.0-1 libegl-mesa0=22.3.6-1+deb12u2 libgl1=1.6.0-1 \
       libgl1-mesa-dri=22.3.6-1+deb12u2 libxrender1=1:0.9.10-1.1 \
    && rm -rf /var/lib/apt/lists/*

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    MOCAPQA_DATA_DIR=/data \
    NUMBA_CACHE_DIR=/tmp/numba-cache \
    PYVISTA_OFF_SCREEN=true

RUN groupadd --system --gid 10001 mocapqa \
    && useradd --system --uid 10001 --gid mocapqa --home-dir /app --shell /usr/sbin/nologin mocapqa

WORKDIR /app
# The package's dependencies first, read from pyproject.toml alone, with its PostgreSQL driver;
# dask[distributed] is one of them. Their versions are bounded in pyproject.toml; the ones the
# image serves with are pinned here so that app, scheduler and workers match. A change to the
# code then rebuilds only the layers below (the package itself, seconds), not this one (minutes).
# Wheels only: nothing is compiled (the image has no compiler).
COPY pyproject.toml README.md ./
RUN --mount=type=secret,id=ca-certificates,target=/run/secrets/ca-certificates.crt \
    if [ -s /run/secrets/ca-certificates.crt ]; then \
      export PIP_CERT=/run/secrets/ca-certificates.crt; \
    fi \
    && pip install "pip==24.2" \
    && python -c "import tomllib; p = tomllib.load(open('pyproject.toml', 'rb'))['project']; \
print('\n'.join(p['dependencies'] + p['optional-dependencies']['postgres']))" \
       > /tmp/requirements.txt \
    && pip install --only-binary=:all: -r /tmp/requirements.txt "dask[distributed]==2026.8.0" \
    && rm /tmp/requirements.txt
COPY backend ./backend
COPY frontend ./frontend
COPY --from=three /js/vendor/three ./frontend/vendor/three
COPY --from=three /js/vendor/plotly ./frontend/vendor/plotly
# Dask settings of the workers (and the scheduler): read from /etc/dask by every dask process.
COPY backend/mocapqa/data/dask/mocapqa.yaml /etc/dask/mocapqa.yaml
# The package itself ("." is this project's own package: DL3013 asks for a version it cannot
# have), built by setuptools; `pip check` fails the build if a dependency went missing.
# hadolint ignore=DL3013
RUN --mount=type=secret,id=ca-certificates,target=/run/secrets/ca-certificates.crt \
    if [ -s /run/secrets/ca-certificates.crt ]; then \
      export PIP_CERT=/run/secrets/ca-certificates.crt; \
    fi \
    && pip install --no-deps . \
    && pip check \
    && mkdir -p /data \
    && chown 10001:10001 /data

USER 10001:10001
VOLUME ["/data"]
EXPOSE 8000 8786 8787
# Healthy when the API answers and its database query succeeds (/api/v1/health runs one).
HEALTHCHECK --interval=15s --timeout=5s --start-period=60s --retries=4 \
    CMD ["python", "-c", "import json,sys,urllib.request as u; r=json.load(u.urlopen('http://127.0.0.1:8000/api/v1/health', timeout=4)); sys.exit(r.get('status') != 'ok')"]
# Serving on 0.0.0.0 (the container's address) needs a user: an admin is made on the first
# start; its one-time sign-in link is in the container's log (`docker logs`).
CMD ["sh", "-c", "mocapqa users list | grep -q . || mocapqa users add admin --role admin; exec mocapqa serve --host 0.0.0.0 --port 8000 --demo"]
