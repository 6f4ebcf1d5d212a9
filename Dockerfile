# The mocapqa dashboard: Python 3.11 on Debian, the package with its PostgreSQL driver.
FROM python:3.11-slim-bookworm
ENV PYTHONDONTWRITEBYTECODE=1 PYTHONUNBUFFERED=1 PIP_NO_CACHE_DIR=1 MOCAPQA_DATA_DIR=/data
WORKDIR /app
COPY pyproject.toml README.md ./
COPY backend ./backend
COPY frontend ./frontend
# Extra PyPI packages, e.g. "dask[distributed]" for the compose file's Dask worker.
ARG EXTRA_PACKAGES=""
RUN pip install ".[postgres]" $EXTRA_PACKAGES && mkdir -p /data
EXPOSE 8000
CMD ["mocapqa", "serve", "--host", "0.0.0.0", "--port", "8000", "--demo"]
