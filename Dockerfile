# One image for every service of compose.yaml: router, world, agent, viewer, swarm.
#
#   docker compose build                  # users: BASE is pulled from their registry
#   docker compose build --build-arg BASE=localpy:3.11    # no registry: see docker/local-base.sh
#
# wheels/ is empty in the repository: the image then installs from the package
# index.  Filled with the dependencies' wheels and the build backend's
# (tests/docker_engine.py build_wheelhouse), it installs from there alone, with
# no network (tests/test_compose.py does this).
#
# Stages, in order; everything up to runtime-deps depends on pyproject.toml's
# dependency list and wheels/ only, never on the sources, so Docker's layer
# cache keeps it across source changes (tests/test_compose.py tags build-deps
# and runtime-deps so that pruning the app image leaves them):
#   toolchain     BASE + gcc, g++ (numba's pycc checks for both), Python's headers
#   requirements  the dependency list read from pyproject.toml (/requirements.txt)
#   deps          toolchain + /opt/venv with the dependencies alone
#   runtime-deps  BASE + deps' /opt/venv: what the image runs, less the project
#   build-deps    deps + setuptools, for numba's pycc
#   build         build-deps + the sources: the project installed with --no-deps, then
#                 `swarm prepare --require-aot`; what these two added to the
#                 venv, and /opt/swarm-cache, are gathered under /opt/project
#   (last)        runtime-deps + /opt/project: no compiler
ARG BASE=python:3.11-slim

# ---- toolchain: C and C++ compilers; Python's headers where the base lacks them.
FROM ${BASE} AS toolchain
RUN apt-get update \
 && packages="gcc g++ libc6-dev" \
 && if [ ! -f "$(python3 -c 'import sysconfig; print(sysconfig.get_paths()["include"])')/Python.h" ]; then \
        packages="$packages python3-dev"; fi \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends $packages \
 && rm -rf /var/lib/apt/lists/*
ENV PATH=/opt/venv/bin:$PATH XDG_CACHE_HOME=/opt/swarm-cache PYTHONDONTWRITEBYTECODE=1

# ---- requirements: [project] dependencies of pyproject.toml, one a line.  The
# file is the same bytes while the list is, whatever else pyproject.toml changes.
FROM ${BASE} AS requirements
COPY pyproject.toml /src/
RUN python3 -c 'import tomllib; print(*tomllib.load(open("/src/pyproject.toml", "rb"))["project"]["dependencies"], sep="\n")' \
    > /requirements.txt

# ---- deps: the virtual environment with the dependencies alone (from /wheels
# when it holds wheels, else from the index).  No setuptools in it: the
# project's build brings its own, and the image does without.
FROM toolchain AS deps
COPY wheels/ /wheels/
COPY --from=requirements /requirements.txt /requirements.txt
RUN set -eu; \
    python3 -m venv /opt/venv; \
    if ls /wheels/*.whl >/dev/null 2>&1; then from="--no-index --find-links /wheels"; else from=""; fi; \
    pip install --no-cache-dir --disable-pip-version-check $from -r /requirements.txt; \
    pip uninstall --yes --quiet setuptools 2>/dev/null || true

# ---- runtime-deps: the base and the dependencies' venv; the last stage adds the project.
FROM ${BASE} AS runtime-deps
COPY --from=deps /opt/venv /opt/venv
ENV PATH=/opt/venv/bin:$PATH \
    XDG_CACHE_HOME=/opt/swarm-cache \
    PYTHONUNBUFFERED=1 \
    PYTHONDONTWRITEBYTECODE=1
WORKDIR /work
CMD ["swarm", "--help"]

# ---- build-deps: setuptools, which numba's pycc uses; it stays in the build stages.
FROM deps AS build-deps
RUN set -eu; \
    if ls /wheels/*.whl >/dev/null 2>&1; then from="--no-index --find-links /wheels"; else from=""; fi; \
    pip install --no-cache-dir --disable-pip-version-check $from setuptools

# ---- build: install the project, then compile every kernel and the agents'
# ahead-of-time step, so containers start at once and agents run without numba
# (~47 MB).
FROM build-deps AS build
COPY pyproject.toml README.md /src/
COPY swarm /src/swarm
COPY agents /src/agents
COPY world_server /src/world_server
# /opt/project: the files that the install and `swarm prepare` added to the venv
# (the packages swarm, agents and world_server, their dist-info, bin/swarm) and
# /opt/swarm-cache, at their paths.
RUN set -eu; \
    if ls /wheels/*.whl >/dev/null 2>&1; then from="--no-index --find-links /wheels"; else from=""; fi; \
    find /opt/venv ! -type d | sort > /tmp/venv-before; \
    pip install --no-cache-dir --disable-pip-version-check --no-deps $from /src; \
    swarm prepare --require-aot; \
    find /opt/venv ! -type d | sort > /tmp/venv-after; \
    comm -13 /tmp/venv-before /tmp/venv-after > /tmp/venv-added; \
    mkdir /opt/project; \
    xargs -d '\n' cp -a --parents -t /opt/project < /tmp/venv-added; \
    cp -a --parents /opt/swarm-cache /opt/project; \
    echo "added to /opt/venv by the project:"; \
    sed -E 's#^/opt/venv/(lib/[^/]+/site-packages/)?([^/]+).*#  \2#' /tmp/venv-added | sort | uniq -c

# ---- the image: runtime-deps and the project's files; no compiler.
FROM runtime-deps
COPY --from=build /opt/project/ /
