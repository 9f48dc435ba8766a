"""A secure run's credentials as Kubernetes Secrets, for deploy/k8s-secure (docs/deploy.md).

Each process's folder becomes one Secret, `swarm-<name>`, whose keys are the folder's files, mounted
at $SWARM_CREDENTIALS in that process's pod.  The agent identities become one Secret,
`swarm-agent-pool`, mounted into every agent pod: a Secret's keys hold no '/', so the pool is flat
(agent<i>.identity.json, agent<i>.cert.pem, ...; swarm.core.credentials reads both layouts), and a
pod takes agent<index+1> by its StatefulSet index ($SWARM_AGENT_INDEX).
"""

from __future__ import annotations

import base64
from pathlib import Path

import yaml

from swarm.core.credentials import (
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

FILE = "kubernetes.yaml"  # written beside the folders: kubectl apply -f DIR/kubernetes.yaml
POOL_SECRET = "swarm-agent-pool"
SECRET_LIMIT = 1024 * 1024  # bytes of data one Secret may hold (Kubernetes refuses more)
FILES = ("identity.json", "ca.pem", "cert.pem", "key.pem")


def secret_name(identity: str) -> str:
    return f"swarm-{identity}"


def _secret(name: str, files: dict[str, bytes]) -> dict:
    data = {key: base64.b64encode(content).decode() for key, content in files.items()}
    return {"apiVersion": "v1", "kind": "Secret", "type": "Opaque",
            "metadata": {"name": name, "labels": {"app.kubernetes.io/name": "swarm"}}, "data": data}  # fmt: skip


def secrets(folder: str | Path) -> list[dict]:
    """The Secrets of the credentials `swarm credentials` wrote into `folder`: the router's, the
    world's, the monitor's, and the agent identities as one flat pool (from DIR/agent-pool, or the
    agent<i> folders of DIR)."""
    folder = Path(folder)
    out = []
    for name in (ROUTER, WORLD, MONITOR):
        try:
            files = {f.name: f.read_bytes() for f in sorted((folder / name).iterdir()) if f.is_file()}
        except OSError:
            files = {}
        if "identity.json" not in files:
            raise CredentialsError(f"{folder / name}: not a credentials folder; write it with `swarm credentials`")
        out.append(_secret(secret_name(name), files))
    agents = pool_members(folder / POOL if (folder / POOL).is_dir() else folder)
    if not agents:
        raise CredentialsError(f"{folder}: no agent identities; write them with `swarm credentials`")
    pool = {f"{name}.{file}": (where / f"{prefix}{file}").read_bytes() for name, where, prefix in agents
            for file in FILES}  # fmt: skip
    out.append(_secret(POOL_SECRET, {**pool, POOL_MARK: POOL_TEXT.encode()}))
    size = sum(map(len, out[-1]["data"].values()))
    if size > SECRET_LIMIT:
        raise CredentialsError(f"{POOL_SECRET} would hold {size} bytes, over the {SECRET_LIMIT} a Kubernetes Secret "
                               f"may: make at most {SECRET_LIMIT * len(agents) // size} agent identities")  # fmt: skip
    return out


def write(folder: str | Path) -> Path:
    """Write `folder`/kubernetes.yaml (private to this user: it holds every key) and return it."""
    path = Path(folder) / FILE
    write_private(path, yaml.safe_dump_all(secrets(folder), sort_keys=False).encode())
    return path
