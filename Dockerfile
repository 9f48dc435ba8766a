# One image for every service of compose.yaml: router, world, agent, viewer, swarm.
#
#   docker compose build                  # users: BASE is pulled from their registry
#   docker compose build --build-arg BASE=localpy:3.11    # no registry: see docker/local-base.sh
#
# wheels/ is empty in the repository: the image then installs from the package
# index.  Filled (pip wheel -w wheels . ; pip download -d wheels setuptools wheel),
# it installs from there alone, with no network (tests/test_compose.py does this).
ARG BASE=python:3.11-slim

# ---- build: install, then compile every kernel and the agents' ahead-of-time
# step, so containers start at once and agents run without numba (~47 MB).
FROM ${BASE} AS build
# C and C++ compilers (numba's pycc checks for both); Python's headers where the base lacks them.
RUN apt-get update \
 && packages="gcc g++ libc6-dev" \
 && if [ ! -f "$(python3 -c 'import sysconfig; print(sysconfig.get_paths()["include"])')/Python.h" ]; then \
        packages="$packages python3-dev"; fi \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends $packages \
 && rm -rf /var/lib/apt/lists/*
ENV PATH=/opt/venv/bin:$PATH XDG_CACHE_HOME=/opt/swarm-cache PYTHONDONTWRITEBYTECODE=1
COPY wheels/ /wheels/
COPY pyproject.toml README.md /src/
COPY swarm /src/swarm
COPY agents /src/agents
COPY world_server /src/world_server
RUN set -eu; \
    python3 -m venv /opt/venv; \
    if ls /wheels/*.whl >/dev/null 2>&1; then from="--no-index --find-links /wheels"; else from=""; fi; \
    pip install --no-cache-dir --disable-pip-version-check $from /src setuptools; \
    swarm prepare --require-aot; \
    pip uninstall --yes --quiet setuptools

# ---- run: the base, the virtual environment and the compiled kernels; no compiler.
FROM ${BASE}
COPY --from=build /opt/venv /opt/venv
COPY --from=build /opt/swarm-cache /opt/swarm-cache
ENV PATH=/opt/venv/bin:$PATH \
    XDG_CACHE_HOME=/opt/swarm-cache \
    PYTHONUNBUFFERED=1 \
    PYTHONDONTWRITEBYTECODE=1
WORKDIR /work
CMD ["swarm", "--help"]
