"""A secure run's credentials: a certificate authority, and a password and a certificate per process.

Every process holds only its own folder, so an agent process cannot speak as
another one or as the world:

    DIR/<name>/identity.json   {"user": name, "password": ...}            (0600)
    DIR/<name>/ca.pem          the run's CA: checks the router's certificate, and the router checks ours
    DIR/<name>/cert.pem        this process's certificate, common name = its name
    DIR/<name>/key.pem         its private key                               (0600)
    DIR/router/users.txt       every user:password, the router's dictionary  (0600)

Names: `router` (whoever hosts the router: `swarm router`, or the world of
`swarm up`), `world` (a world that joins a router), `monitor` (the launcher,
`swarm monitor`, `swarm status`), `agent1`..`agentN` (one per agent process;
the name is also its message group, so the router's rules can name its keys)
and, made only on request, `agents`: one identity shared by identical
replicas that cannot each be handed their own (compose's `--scale`).

Identical replicas can instead claim one each from a pool, DIR/agent-pool/agent<i>
(`make(..., pool=True)`): a process that is handed the pool takes the first
identity no live process holds (a lock on its file, which the kernel lets go
when the process dies, however it dies) and keeps it for its life; a replica
an orchestrator numbers (Docker Swarm's task slot, $SWARM_AGENT_SLOT, or a
Kubernetes StatefulSet pod's index + 1, $SWARM_AGENT_INDEX) takes agent<slot>,
as locks do not reach across hosts.  A pool is folders of agent<i>, or flat:
files agent<i>.identity.json, agent<i>.cert.pem, ... (a Kubernetes Secret's
keys hold no '/': swarm.core.kubernetes_secrets).  Each
replica then puts only on its own keys; every replica can read the whole pool,
so a replica that is itself hostile could still log in as another.

Passwords and keys come from the operating system's randomness, never from
the run's seed: a seed is public, a credential must not be derivable from it.
"""

from __future__ import annotations

import datetime
import ipaddress
import json
import os
import secrets
from dataclasses import dataclass
from pathlib import Path

from swarm.core.errors import RunError

ROUTER, WORLD, MONITOR, SHARED_AGENTS = "router", "world", "monitor", "agents"
POOL = "agent-pool"  # the agent identities of `make(..., pool=True)`, for replicas to claim
POOL_MARK = "POOL"  # the file that says a folder is a pool (a run's folder of agent<i> is not one)
POOL_TEXT = "agent identities for replicas to claim: swarm agent --credentials\n"  # the mark's text
LOCAL_HOSTS = ("localhost", "127.0.0.1", "::1")
IDENTITY_FILES = ("identity.json", "ca.pem", "cert.pem", "key.pem")  # an identity's files (a router's: users.txt too)
VALID_DAYS = 30


class CredentialsError(RunError):
    """Credentials missing, unreadable or too few for the run."""


def agent_name(i: int) -> str:
    """The identity (and message group) of agent process `i`, from 1."""
    return f"agent{i}"


def agent_number(name: str) -> int | None:
    """i of `agent<i>` (agent_name's inverse), or None for any other name."""
    digits = name.removeprefix("agent")
    return int(digits) if name.startswith("agent") and is_number(digits) else None


def own_group(identity: Identity | None) -> str | None:
    """The message group an agent process must use: its identity's name, which the router's rules name;
    None (any group) without credentials or with the shared `agents` identity."""
    if identity is None or identity.name == SHARED_AGENTS:
        return None
    return identity.name


@dataclass(frozen=True)
class Identity:
    """One process's credentials, as read from its folder."""

    name: str
    password: str
    folder: Path
    prefix: str = ""  # a flat pool's files are agent<i>.<file>: a Kubernetes Secret's keys hold no '/'

    def file(self, name: str) -> Path:
        return self.folder / f"{self.prefix}{name}"

    @property
    def ca(self) -> Path:
        return self.file("ca.pem")

    @property
    def cert(self) -> Path:
        return self.file("cert.pem")

    @property
    def key(self) -> Path:
        return self.file("key.pem")

    @property
    def users_file(self) -> Path:
        return self.file("users.txt")

    def users(self) -> list[str]:
        """The names in the router's dictionary (only a router's folder has one)."""
        try:
            lines = self.users_file.read_text().splitlines()
        except OSError:
            raise CredentialsError(f"{self.folder}: no users.txt; host the router with the `router` folder") from None
        return [line.split(":", 1)[0] for line in lines if ":" in line]


def load(folder: str | Path, prefix: str = "") -> Identity:
    """The identity in `folder` (DIR/<name>), or in its files named `prefix`<file> (a flat pool's
    agent<i>.), or a one-line CredentialsError."""
    folder = Path(folder)
    try:
        data = json.loads((folder / f"{prefix}identity.json").read_text())
        name, password = data["user"], data["password"]
    except (OSError, ValueError, KeyError, TypeError):
        raise CredentialsError(f"{folder}: not a credentials folder (no readable {prefix}identity.json)") from None
    missing = [prefix + f for f in IDENTITY_FILES[1:] if not (folder / f"{prefix}{f}").is_file()]
    if missing:
        raise CredentialsError(f"{folder}: missing {', '.join(missing)}")
    return Identity(str(name), str(password), folder, prefix)


_claimed: list[int] = []  # the claimed identities' locked files, open for the life of the process


def is_pool(folder: str | Path) -> bool:
    """Whether `folder` holds agent identities to claim (DIR/agent-pool, as `make` marks it)."""
    return (Path(folder) / POOL_MARK).is_file()


def is_number(text: str) -> bool:
    return text.isascii() and text.isdecimal()


def pool_members(folder: Path) -> list[tuple[str, Path, str]]:
    """(name, folder, prefix) of each agent identity in `folder`, by number: its agent<i>/ folders, or its
    agent<i>.<file> files (a flat pool, as a Kubernetes Secret mounts one)."""
    found: dict[str, tuple[Path, str]] = {}
    for path in folder.glob("agent*"):
        flat = path.name.removesuffix(".identity.json")
        if agent_number(path.name) is not None and (path / "identity.json").is_file():
            found[path.name] = (path, "")
        elif flat != path.name and agent_number(flat) is not None:
            found[flat] = (folder, f"{flat}.")
    return [(name, *found[name]) for name in sorted(found, key=agent_number)]


def claim(pool: str | Path, slot: int | None = None) -> Identity:
    """The first identity of `pool` that no live process holds, now held by this one until it exits
    (`slot`: agent<slot> alone, as an orchestrator numbers its replicas); a one-line CredentialsError
    when none is free."""
    import fcntl

    members = pool_members(Path(pool))
    if slot is not None:
        members = [m for m in members if m[0] == agent_name(slot)]
        if not members:
            raise CredentialsError(f"{pool}: no identity {agent_name(slot)} for replica {slot}; make a bigger "
                                   "pool with `swarm credentials DIR --agent-processes N` (and --pool, or "
                                   "--kubernetes and its Secrets applied again)")  # fmt: skip
    for _, folder, prefix in members:
        try:
            fd = os.open(folder / f"{prefix}identity.json", os.O_RDONLY)
        except OSError as exc:
            raise CredentialsError(f"{folder}: cannot read {prefix}identity.json ({exc.strerror})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        try:
            claimed = load(folder, prefix)
        except CredentialsError:
            os.close(fd)  # (and its lock)
            raise
        _claimed.append(fd)
        return claimed
    if slot is not None:
        raise CredentialsError(f"{pool}: {agent_name(slot)} is held by another running process (replica {slot} "
                               "twice?)")  # fmt: skip
    raise CredentialsError(f"{pool}: all {len(members)} agent identities are held by running processes; make a "
                           "bigger pool with `swarm credentials DIR --pool --agent-processes N`")  # fmt: skip


def identity_in(run_folder: str | Path, name: str) -> Identity:
    """The identity `name` of a run's credentials folder (as `make` writes it)."""
    return load(Path(run_folder) / name)


def make(folder: str | Path, agent_processes: int, hosts: tuple[str, ...] = (), shared_agents: bool = False,
         pool: bool = False) -> Path:  # fmt: skip
    """Write a run's credentials into `folder` (made, and left private to this user): a CA, the
    router's certificate for `hosts` and this machine's loopback names, and one identity per process
    (the agent processes' in `folder`/agent-pool with `pool`)."""
    from cryptography.hazmat.primitives.asymmetric import ec

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True, mode=0o700)
    agents = [agent_name(i) for i in range(1, agent_processes + 1)]
    names = [ROUTER, WORLD, MONITOR, *agents]
    names += [SHARED_AGENTS] if shared_agents else []
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca_cert = _certificate("swarm run CA", ca_key.public_key(), ca_key, None, ca=True)
    ca_pem = _pem(ca_cert)
    passwords = {name: secrets.token_urlsafe(24) for name in names}
    if pool:
        (folder / POOL).mkdir(exist_ok=True, mode=0o700)
        (folder / POOL / POOL_MARK).write_text(POOL_TEXT)
    for name in names:
        where = (folder / POOL if pool and name in agents else folder) / name
        where.mkdir(exist_ok=True, mode=0o700)
        key = ec.generate_private_key(ec.SECP256R1())
        sans = (*LOCAL_HOSTS, *hosts) if name == ROUTER else ()
        cert = _certificate(name, key.public_key(), ca_key, ca_cert, sans=sans)
        (where / "ca.pem").write_bytes(ca_pem)
        (where / "cert.pem").write_bytes(_pem(cert))
        write_private(where / "key.pem", _key_pem(key))
        write_private(where / "identity.json", json.dumps({"user": name, "password": passwords[name]}).encode())
    users = "".join(f"{name}:{passwords[name]}\n" for name in names)
    write_private(folder / ROUTER / "users.txt", users.encode())
    return folder


def write_private(path: Path, data: bytes) -> None:
    """Write a secret readable by this user only (created 0600, never world-readable in between)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    os.chmod(path, 0o600)


def _certificate(common_name: str, public_key, signing_key, issuer, ca: bool = False, sans: tuple[str, ...] = ()):
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes
    from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

    subject = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, common_name)])
    now = datetime.datetime.now(datetime.UTC)
    builder = (
        x509.CertificateBuilder()
        .subject_name(subject)
        .issuer_name(issuer.subject if issuer is not None else subject)
        .public_key(public_key)
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(minutes=5))
        .not_valid_after(now + datetime.timedelta(days=VALID_DAYS))
        .add_extension(x509.BasicConstraints(ca=ca, path_length=0 if ca else None), critical=True)
    )
    if ca:
        builder = builder.add_extension(
            x509.KeyUsage(digital_signature=True, key_cert_sign=True, crl_sign=True, content_commitment=False,
                          key_encipherment=False, data_encipherment=False, key_agreement=False,
                          encipher_only=False, decipher_only=False),
            critical=True,
        )  # fmt: skip
    else:
        usages = [ExtendedKeyUsageOID.CLIENT_AUTH, ExtendedKeyUsageOID.SERVER_AUTH]
        builder = builder.add_extension(x509.ExtendedKeyUsage(usages), critical=False)
        if sans:
            builder = builder.add_extension(x509.SubjectAlternativeName([_san(h) for h in sans]), critical=False)
    return builder.sign(signing_key, hashes.SHA256())


def _san(host: str):
    from cryptography import x509

    try:
        return x509.IPAddress(ipaddress.ip_address(host))
    except ValueError:
        return x509.DNSName(host)


def _pem(cert) -> bytes:
    from cryptography.hazmat.primitives import serialization

    return cert.public_bytes(serialization.Encoding.PEM)


def _key_pem(key) -> bytes:
    from cryptography.hazmat.primitives import serialization

    return key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                             serialization.NoEncryption())  # fmt: skip
