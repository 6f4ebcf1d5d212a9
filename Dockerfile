# The mocapqa dashboard: Python 3.11 on Debian, the package with its PostgreSQL driver.
# three.js (the dashboard's 3D views) comes from the npm registry, pinned by package-lock.json.
FROM node:20-bookworm-slim AS three
WORKDIR /js
COPY package.json package-lock.json ./
RUN npm ci --omit=dev --no-audit --no-fund && mkdir -p vendor/three \
 && cp node_modules/three/build/three.module.min.js node_modules/three/build/three.core.min.js \
       node_modules/three/LICENSE vendor/three/

FROM python:3.11-slim-bookworm
ENV PYTHONDONTWRITEBYTECODE=1 PYTHONUNBUFFERED=1 PIP_NO_CACHE_DIR=1 MOCAPQA_DATA_DIR=/data
WORKDIR /app
COPY pyproject.toml README.md ./
COPY backend ./backend
COPY frontend ./frontend
COPY --from=three /js/vendor/three ./frontend/vendor/three
# Extra PyPI packages, e.g. "dask[distributed]" for the compose file's Dask worker.
ARG EXTRA_PACKAGES=""
RUN pip install ".[postgres]" $EXTRA_PACKAGES && mkdir -p /data
EXPOSE 8000
CMD ["mocapqa", "serve", "--host", "0.0.0.0", "--port", "8000", "--demo"]
