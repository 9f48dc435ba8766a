"""The command line of secure runs: `swarm credentials`, and the `--credentials` option of every
process that opens a zenoh session (docs/security.md)."""

from __future__ import annotations

import argparse
import os
import sys

from swarm.core.credentials import POOL, CredentialsError, Identity, claim, is_number, is_pool, load
from swarm.core.tables import positive

ENV = "SWARM_CREDENTIALS"  # the default of --credentials: a container gets its folder without a new command
SLOT_ENV = "SWARM_AGENT_SLOT"  # a replica's number (Docker Swarm's {{.Task.Slot}}): its identity in a pool
INDEX_ENV = "SWARM_AGENT_INDEX"  # a replica's index from 0 (a Kubernetes StatefulSet pod's): agent<index+1>


def credentials_arg(p: argparse.ArgumentParser, who: str) -> None:
    p.add_argument("--credentials", metavar="FOLDER", default=os.environ.get(ENV),
                   help=f"this process's own credentials folder ({who}) of a secure run "
                   f"(default: ${ENV}); see `swarm credentials`")  # fmt: skip


def identity(args: argparse.Namespace) -> Identity | None:
    """The identity `--credentials` names, or None (a plain run)."""
    return load(args.credentials) if args.credentials else None


def agent_identity(args: argparse.Namespace) -> Identity | None:
    """An agent process's identity: the folder `--credentials` names, or one claimed from a pool."""
    if args.credentials and is_pool(args.credentials):
        claimed = claim(args.credentials, _slot())
        print(f"swarm: this agent process is {claimed.name} (claimed from {args.credentials})", file=sys.stderr)
        return claimed
    return identity(args)


def _slot() -> int | None:
    """The replica's number an orchestrator gives ($SWARM_AGENT_SLOT, or $SWARM_AGENT_INDEX + 1), if any."""
    for env, example, offset in ((SLOT_ENV, "{{.Task.Slot}}", 0), (INDEX_ENV, "a StatefulSet pod's index", 1)):
        if (value := os.environ.get(env)) is not None:
            if not is_number(value):
                why = " (a pod's index label needs Kubernetes 1.28 or newer)" if env == INDEX_ENV and not value else ""
                raise CredentialsError(f"${env} is {value!r}: expected the replica's number, e.g. {example}{why}")
            return int(value) + offset
    return None


def up_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--secure", action="store_true",
                   help="make this run's credentials: logins, TLS certificates and the router's access rules "
                   "(an agent may put on its own keys only)")  # fmt: skip
    p.add_argument(
        "--credentials",
        metavar="DIR",
        help="a secure run with the credentials `swarm credentials DIR` made (implies --secure)",
    )


def add_credentials_parser(sub) -> None:
    made = sub.add_parser(
        "credentials",
        help="make a secure run's credentials (a CA, and a login and a certificate per process)",
        description="Write DIR/router, DIR/world, DIR/monitor and DIR/agent1..agentN: each process's own "
        "folder, to pass with --credentials (mount only its own into its container).",
    )
    made.add_argument("dir", metavar="DIR", help="where to write them (made private to this user)")
    made.add_argument("--agent-processes", type=positive, default=1, metavar="N",
                      help="identities agent1..agentN, one per agent process (default 1)")  # fmt: skip
    made.add_argument("--host", action="append", default=[], metavar="NAME",
                      help="a name or address the router is reached by besides localhost (repeat it); "
                      "TLS clients check it")  # fmt: skip
    made.add_argument("--shared-agents", action="store_true",
                      help="also an `agents` identity for identical replicas (compose --scale): any of them "
                      "may put on any agent process's keys; the world still refuses actions for another's "
                      "agents")  # fmt: skip
    made.add_argument("--pool", action="store_true",
                      help="put agent1..agentN in DIR/agent-pool, for identical replicas (compose --scale) to "
                      "claim one each: mount the pool into every agent container")  # fmt: skip
    made.add_argument("--kubernetes", action="store_true",
                      help="also write DIR/kubernetes.yaml: each folder as a Secret and the agent identities "
                      "as one pool, for deploy/k8s-secure (kubectl apply --server-side -f DIR/kubernetes.yaml)"
                      )  # fmt: skip
    made.set_defaults(handler=cmd_credentials)


def cmd_credentials(args: argparse.Namespace) -> int:
    from swarm.core.credentials import make

    if args.kubernetes and args.shared_agents:
        raise CredentialsError("--kubernetes gives each agent pod its own identity from the pool: leave out "
                               "--shared-agents")  # fmt: skip
    folder = make(args.dir, args.agent_processes, tuple(args.host), args.shared_agents, args.pool)
    where = f" (agents in {folder / POOL})" if args.pool else ""
    print(f"swarm: credentials for {args.agent_processes} agent processes in {folder}{where}")
    if args.kubernetes:
        from swarm.core import kubernetes_secrets

        secrets = kubernetes_secrets.write(folder, args.pool)
        print(f"swarm: their Kubernetes Secrets in {secrets}: kubectl apply --server-side -f {secrets}")
    return 0
