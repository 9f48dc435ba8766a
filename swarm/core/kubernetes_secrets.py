"""A secure run's credentials as Kubernetes Secrets, for deploy/k8s-secure (docs/deploy.md).

Each process's folder becomes one Secret, `swarm-<name>`, whose keys are the folder's files, mounted
at $SWARM_CREDENTIALS in that process's pod.  The agent identities become one Secret,
`swarm-agent-pool`, mounted into every agent pod: a Secret's keys hold no '/', so the pool is flat
(agent<i>.identity.json, agent<i>.cert.pem, ...; swarm.core.credentials reads both layouts), and a
pod takes agent<index+1> by its StatefulSet index ($SWARM_AGENT_INDEX).

A Secret holds at most 1 MiB (about 700 agent identities).  `kubectl apply` without --server-side
copies the whole object into an annotation of at most 256 KiB (about 140 identities), so the file is
applied server-side.
"""

from __future__ import annotations

import base64
from pathlib import Path

import yaml

from swarm.core.credentials import (
    IDENTITY_FILES,
    MONITOR,
    POOL,
    POOL_MARK,
    POOL_TEXT,
    ROUTER,
    WORLD,
    CredentialsError,
    pool_members,
    write_private,
)

FILE = "kubernetes.yaml"  # written beside the folders: kubectl apply --server-side -f DIR/kubernetes.yaml
POOL_SECRET = "swarm-agent-pool"
SECRET_LIMIT = 1024 * 1024  # bytes of data one Secret may hold, decoded (Kubernetes refuses more)


def secret_name(identity: str) -> str:
    return f"swarm-{identity}"


def _secret(name: str, files: dict[str, bytes]) -> dict:
    data = {key: base64.b64encode(content).decode() for key, content in files.items()}
    return {"apiVersion": "v1", "kind": "Secret", "type": "Opaque",
            "metadata": {"name": name, "labels": {"app.kubernetes.io/name": "swarm"}}, "data": data}  # fmt: skip


def secrets(folder: str | Path, pool: bool = False) -> list[dict]:
    """The Secrets of the credentials `swarm credentials` wrote into `folder`: the router's, the
    world's, the monitor's, and the agent identities as one flat pool (from DIR/agent-pool with `pool`,
    else the agent<i> folders of DIR)."""
    folder = Path(folder)
    out = [_secret(secret_name(name), _files(folder / name)) for name in (ROUTER, WORLD, MONITOR)]
    agents = pool_members(folder / POOL if pool else folder)
    if not agents:
        raise CredentialsError(f"{folder}: no agent identities; write them with `swarm credentials`")
    flat = {f"{name}.{file}": _read(where / f"{prefix}{file}") for name, where, prefix in agents
            for file in IDENTITY_FILES}  # fmt: skip
    size = sum(map(len, flat.values()))
    if size > SECRET_LIMIT:
        raise CredentialsError(f"{POOL_SECRET} would hold {size} bytes, over the {SECRET_LIMIT} a Kubernetes Secret "
                               f"may: make at most {SECRET_LIMIT * len(agents) // size} agent identities")  # fmt: skip
    out.append(_secret(POOL_SECRET, {**flat, POOL_MARK: POOL_TEXT.encode()}))
    return out


def _files(folder: Path) -> dict[str, bytes]:
    """An identity folder's files by name, or a one-line CredentialsError."""
    if not (folder / "identity.json").is_file():
        raise CredentialsError(f"{folder}: not a credentials folder; write it with `swarm credentials`")
    return {path.name: _read(path) for path in sorted(folder.iterdir()) if path.is_file()}


def _read(path: Path) -> bytes:
    try:
        return path.read_bytes()
    except OSError as exc:
        raise CredentialsError(f"{path}: cannot read it ({exc.strerror})") from None


def write(folder: str | Path, pool: bool = False) -> Path:
    """Write `folder`/kubernetes.yaml (private to this user: it holds every key) and return it."""
    path = Path(folder) / FILE
    write_private(path, yaml.safe_dump_all(secrets(folder, pool), sort_keys=False).encode())
    return path
