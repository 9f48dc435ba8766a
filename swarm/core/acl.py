"""The router's access control for a secure run: who may put, subscribe and ask on which keys.

Everything not allowed here is denied at the router, before it reaches the
world: an agent process puts only on its own group's keys (its actions, mark
writes, plans and records, and its own observation key, where it wakes
itself), subscribes only to its own observations, and may ask the world's
queryables (join, info, shared spaces) and declare liveliness tokens.  The
world may do anything in the run's key space; a monitor only reads.  Rules
name every run (`swarm/*/...`), so one router serves any run id.

Routers meshed over TLS forward to each other whatever their own rules let in:
each router checks the processes that log in to it, and a peer is known by the
`router` certificate of the run's CA.  That certificate is the only way to know
it: a link a router opens carries no login to the router that opened it, so a
mesh of secure routers needs `tls/` links.
"""

from __future__ import annotations

from swarm.core import credentials
from swarm.core.wire import Keys

ANY = Keys("*", every_run=True)
WORLD_MESSAGES = ["put", "delete", "declare_subscriber", "declare_queryable", "query", "reply",
                  "liveliness_token", "declare_liveliness_subscriber", "liveliness_query"]  # fmt: skip


def _rule(rule_id: str, messages: list[str], flows: list[str], keys: list[str]) -> dict:
    return {"id": rule_id, "messages": messages, "flows": flows, "permission": "allow", "key_exprs": keys}


def _reader(name: str) -> list[dict]:
    """Ask the world's queryables and hear their replies (join, info, marks, shared spaces)."""
    return [_rule(f"{name}-ask", ["query", "liveliness_query"], ["ingress"], [f"{ANY.prefix}/**"]),
            _rule(f"{name}-answers", ["reply"], ["egress"], [f"{ANY.prefix}/**"])]  # fmt: skip


def _agent(name: str, group: str) -> list[dict]:
    """An agent process whose messages travel as `group` (`*`: any group, a shared identity)."""
    own = [ANY.act(group), ANY.mark(group), f"{ANY.mark(group)}/**", ANY.plan(group), ANY.record(group)]
    return [
        _rule(f"{name}-put", ["put"], ["ingress"], [*own, ANY.obs(group)]),
        # A declared publisher sends only once it has heard of a matching subscriber: the world's
        # declarations (key expressions such as `act/*`, no data) must reach the agent.
        _rule(f"{name}-matched", ["declare_subscriber"], ["egress"], [f"{ANY.prefix}/**"]),
        _rule(f"{name}-subscribe", ["declare_subscriber"], ["ingress"], [ANY.obs(group)]),
        _rule(f"{name}-hear", ["put"], ["egress"], [ANY.obs(group)]),
        _rule(f"{name}-alive", ["liveliness_token"], ["ingress"], [ANY.alive_all]),
        *_reader(name),
    ]


def _rules_of(name: str, tls: bool) -> list[dict]:
    # a peer router carries what its own rules let in; it is known by its certificate, so only over TLS
    if name == credentials.WORLD or (name == credentials.ROUTER and tls):
        return [_rule(f"{name}-all", WORLD_MESSAGES, ["ingress", "egress"], [f"{ANY.prefix}/**"])]
    if name == credentials.MONITOR:
        return [_rule(f"{name}-subscribe", ["declare_subscriber"], ["ingress"], [ANY.state]),
                _rule(f"{name}-hear", ["put"], ["egress"], [ANY.state]), *_reader(name)]  # fmt: skip
    if name == credentials.SHARED_AGENTS:
        return _agent(name, "*")
    if credentials.agent_number(name) is not None:
        return _agent(name, name)
    return []  # the router's name over TCP, or one this version does not know: nothing


def access_control(users: list[str], tls: bool) -> dict:
    """zenoh's `access_control` section for these users; over TLS a subject must also show the
    certificate of its name (both must match: a password alone, or a certificate alone, is not enough),
    save a peer router, known by its certificate alone (module docstring)."""
    rules, subjects, policies = [], [], []
    for name in users:
        mine = _rules_of(name, tls)
        if not mine:
            continue
        rules += mine
        subject: dict = {"id": name} if tls and name == credentials.ROUTER else {"id": name, "usernames": [name]}
        if tls:
            subject["cert_common_names"] = [name]
        subjects.append(subject)
        policies.append({"id": name, "rules": [r["id"] for r in mine], "subjects": [name]})
    return {"enabled": True, "default_permission": "deny", "rules": rules, "subjects": subjects,
            "policies": policies}  # fmt: skip
