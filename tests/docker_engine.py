"""A real Docker engine for the compose test, and the image built without a registry.

These machines ship the docker client only: the engine is started here
(`dockerd`, root), and since no registry is reachable, the base image is
debootstrapped (docker/local-base.sh) and the project installs from a wheelhouse
built on the host (the Dockerfile's offline path).  See
../shared/docs/docker-on-these-machines.md and docs/docker.md.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BASE_TAG = "localpy:3.11"
# the Dockerfile's stages that hold the dependencies, tagged so that removing the app image and
# `docker image prune` keep them: a build after a source change redoes only the project's install
CACHED_STAGES = {"build-deps": "swarm-cache:build-deps", "runtime-deps": "swarm-cache:runtime-deps"}


def engine_answers() -> bool:
    return shutil.which("docker") is not None and subprocess.run(
        ["docker", "info"], capture_output=True, timeout=60).returncode == 0  # fmt: skip


def why_no_engine() -> str | None:
    """None if an engine can be had here, else why not."""
    if shutil.which("docker") is None:
        return "no docker client (make test installs docker.io as root)"
    if engine_answers():
        return None
    if shutil.which("dockerd") is None or os.geteuid() != 0:
        return "no Docker engine running and none can be started here (needs root and dockerd)"
    for tool in ("docker-compose", "debootstrap"):
        if shutil.which(tool) is None:
            return f"{tool} is missing (make test installs it as root)"
    return None


@contextlib.contextmanager
def docker_engine():
    """The running engine, or one started for the test (overlay2, else vfs) and stopped after it."""
    if engine_answers():
        yield
        return
    proc = None
    for driver in ("overlay2", "vfs"):  # overlay2 makes containers in ~0 s; vfs copies the image for each
        log = open(f"/tmp/swarm-dockerd-{driver}.log", "w")  # noqa: SIM115 (kept open for the daemon)
        proc = subprocess.Popen(["dockerd", f"--storage-driver={driver}"], stdout=log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 30
        while proc.poll() is None and time.monotonic() < deadline and not engine_answers():
            time.sleep(0.5)
        if proc.poll() is None and engine_answers():
            break
        proc.terminate()
        proc.wait(30)
        proc = None
    if proc is None:
        raise RuntimeError("dockerd did not start; see /tmp/swarm-dockerd-*.log")
    try:
        yield
    finally:
        proc.terminate()
        with contextlib.suppress(subprocess.TimeoutExpired):
            proc.wait(30)


def project_dependencies() -> list[str]:
    """[project] dependencies of pyproject.toml, as the Dockerfile's requirements stage reads them."""
    with open(ROOT / "pyproject.toml", "rb") as f:
        return tomllib.load(f)["project"]["dependencies"]


def build_wheelhouse() -> None:
    """wheels/: every dependency's wheel and the build backend's, not the project's own.

    The image installs the project from its sources; its wheel (new bytes on every build)
    would change wheels/ and so miss the cache of the Dockerfile's deps stage.  The
    dependencies' wheels are the same bytes from run to run (pip's cache makes it quick).
    """
    wheels = ROOT / "wheels"
    for old in wheels.glob("*.whl"):
        old.unlink()
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check"]
    subprocess.run([*pip, "wheel", "--quiet", "-w", str(wheels), *project_dependencies()], check=True, timeout=900)
    subprocess.run([*pip, "download", "--quiet", "-d", str(wheels), "setuptools", "wheel"], check=True, timeout=300)


def build_base() -> None:
    subprocess.run(["bash", str(ROOT / "docker" / "local-base.sh"), BASE_TAG], check=True, timeout=900)


def build_cached_stages(base: str = BASE_TAG) -> None:
    """Build (from the cache, if it has them) and tag the dependency stages of the Dockerfile.

    A new tag leaves the layers of the one it replaces dangling, for `docker image prune`.
    The classic builder, which compose v1 uses, shares its layer cache with these builds.
    """
    env = {**os.environ, "DOCKER_BUILDKIT": "0"}
    for target, tag in CACHED_STAGES.items():
        out = subprocess.run(["docker", "build", "--build-arg", f"BASE={base}", "--target", target, "-t", tag,
                              str(ROOT)], env=env, capture_output=True, text=True, timeout=900)  # fmt: skip
        if out.returncode != 0:
            raise RuntimeError(f"docker build --target {target} failed:\n{out.stdout[-4000:]}\n{out.stderr[-2000:]}")
