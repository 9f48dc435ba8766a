"""The deployments beside compose.yaml: the Kubernetes manifests (deploy/k8s/) against Kubernetes'
API schemas, and stack.yaml and the manifests running compose.yaml's commands with its defaults,
so the three do not drift apart.  stack.yaml on a real Docker Swarm: tests/test_compose.py."""

from __future__ import annotations

import re
from pathlib import Path

import kubernetes_validate
import pytest
import yaml

ROOT = Path(__file__).resolve().parent.parent
K8S = ROOT / "deploy" / "k8s"
KUBERNETES = "1.30"  # the oldest minor version the manifests are checked against


def manifests() -> list[tuple[str, dict]]:
    return [(path.name, doc) for path in sorted(K8S.glob("*.yaml")) if path.name != "kustomization.yaml"
            for doc in yaml.safe_load_all(path.read_text()) if doc]  # fmt: skip


def by_name(kind: str, name: str) -> dict:
    return next(doc for _, doc in manifests() if doc["kind"] == kind and doc["metadata"]["name"] == name)


def compose_command(file: str, service: str) -> list[str]:
    """A service's command with every ${VAR:-default} at its default and --connect's value left out."""
    command = yaml.safe_load((ROOT / file).read_text())["services"][service]["command"]
    return _without_connect([re.sub(r"\$\{\w+:-([^}]*)\}", r"\1", arg) for arg in command])


def k8s_command(kind: str, name: str) -> list[str]:
    """A container's args with every $(VAR) at the settings ConfigMap's value."""
    settings = by_name("ConfigMap", "swarm-settings")["data"]
    (container,) = by_name(kind, name)["spec"]["template"]["spec"]["containers"]
    return _without_connect([re.sub(r"\$\((\w+)\)", lambda m: settings[m[1]], arg) for arg in container["args"]])


def _without_connect(args: list[str]) -> list[str]:
    if "--connect" in args:
        i = args.index("--connect")
        return args[:i] + args[i + 2 :]
    return args


@pytest.mark.parametrize(("file", "kind", "name"), [(f, d["kind"], d["metadata"]["name"]) for f, d in manifests()])
def test_each_manifest_is_valid_for_kubernetes(file, kind, name):
    """Strict: a misspelt or misplaced field fails, not only a missing one."""
    assert kubernetes_validate.validate(by_name(kind, name), KUBERNETES, strict=True)


def test_the_kustomization_lists_every_manifest():
    listed = yaml.safe_load((K8S / "kustomization.yaml").read_text())["resources"]
    assert sorted(listed) == sorted({file for file, _ in manifests()})


def test_a_misplaced_field_fails_the_schema():
    agent = by_name("Deployment", "agent")
    agent["spec"]["template"]["spec"]["containers"][0]["replicas"] = 3
    with pytest.raises(kubernetes_validate.ValidationError, match="'replicas' was unexpected"):
        kubernetes_validate.validate(agent, KUBERNETES, strict=True)


@pytest.mark.parametrize(("service", "kind", "name"), [("router", "DaemonSet", "router"),
                         ("world", "Deployment", "world"), ("agent", "Deployment", "agent"),
                         ("swarm", "Job", "monitor"), ("viewer", "Deployment", "viewer")])  # fmt: skip
def test_stack_and_kubernetes_run_compose_commands(service, kind, name):
    """Only where each process finds its router differs (and the routers' --mesh)."""
    expected = compose_command("compose.yaml", service)
    mesh = ["--mesh", "tcp/router:7447"] if service == "router" else []
    assert compose_command("stack.yaml", service) == expected + mesh
    assert k8s_command(kind, name) == expected + mesh


def test_agents_and_the_world_join_their_own_nodes_router():
    stack = yaml.safe_load((ROOT / "stack.yaml").read_text())["services"]
    for service in ("world", "agent", "swarm"):
        command = stack[service]["command"]
        assert command[command.index("--connect") + 1] == "${LINK:-tcp}/host.docker.internal:${ROUTER_PORT:-7447}"
        assert stack[service]["extra_hosts"] == ["host.docker.internal:host-gateway"]
    assert stack["router"]["deploy"] == {"mode": "global", "endpoint_mode": "dnsrr"}
    assert stack["router"]["ports"][0]["mode"] == "host"
    assert by_name("Service", "router-local")["spec"]["internalTrafficPolicy"] == "Local"
    assert by_name("Service", "router")["spec"]["clusterIP"] == "None"
