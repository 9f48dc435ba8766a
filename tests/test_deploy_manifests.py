"""The deployments beside compose.yaml: the Kubernetes manifests (deploy/k8s/) against Kubernetes'
API schemas, and stack.yaml and the manifests running compose.yaml's commands with its defaults,
so the three do not drift apart; the secure overlay (deploy/k8s-secure/), built by kubectl's
kustomize, differing from them only by credentials and TLS.  stack.yaml on a real Docker Swarm:
tests/test_compose.py; the secure overlay's wiring in a real run: tests/test_secure.py."""

from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import kubernetes_validate
import pytest
import yaml
from cryptography import x509

from swarm.core import credentials, kubernetes_secrets

ROOT = Path(__file__).resolve().parent.parent
K8S = ROOT / "deploy" / "k8s"
K8S_SECURE = ROOT / "deploy" / "k8s-secure"
KUBECTL = shutil.which("kubectl")
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


def _secure_build() -> dict[tuple[str, str], dict]:
    built = subprocess.run([KUBECTL, "kustomize", str(K8S_SECURE)], capture_output=True, text=True, timeout=120)
    assert built.returncode == 0, built.stderr
    return {(d["kind"], d["metadata"]["name"]): d for d in yaml.safe_load_all(built.stdout) if d}


def _without_security(doc: dict) -> dict:
    """`doc` with tcp/ for tls/ and without the credentials' volume, mount and variables."""
    doc = json.loads(json.dumps(doc).replace('"tls/', '"tcp/').replace(" tls/", " tcp/"))
    pod = doc["spec"]["template"]["spec"]
    pod["volumes"] = [v for v in pod["volumes"] if v["name"] != "credentials"] or None
    for c in pod["containers"]:
        c["volumeMounts"] = [m for m in c["volumeMounts"] if m["name"] != "credentials"] or None
        c["env"] = [e for e in c["env"] if e["name"] not in ("SWARM_CREDENTIALS", "SWARM_AGENT_INDEX")] or None
    return _dropping_none(doc)


def _dropping_none(value):
    if isinstance(value, dict):
        return {k: _dropping_none(v) for k, v in value.items() if v is not None}
    return [_dropping_none(v) for v in value] if isinstance(value, list) else value


SECRET_OF = {"router": credentials.ROUTER, "world": credentials.WORLD, "monitor": credentials.MONITOR}


@pytest.mark.skipif(KUBECTL is None, reason="needs kubectl, whose kustomize builds the overlay")
def test_the_secure_overlay_is_the_plain_manifests_with_credentials_and_tls(tmp_path):
    """Each process mounts its own Secret of `swarm credentials --kubernetes` and links over TLS; the
    agents are a StatefulSet (an index per pod, for its identity) with the Deployment's pod; nothing else
    differs, and every resource is valid for Kubernetes."""
    built, plain = _secure_build(), {(d["kind"], d["metadata"]["name"]): d for _, d in manifests()}
    assert set(built) == set(plain) - {("Deployment", "agent")} | {("StatefulSet", "agent"), ("Service", "agent")}
    for doc in built.values():
        assert kubernetes_validate.validate(doc, KUBERNETES, strict=True)
    made = kubernetes_secrets.secrets(credentials.make(tmp_path, 2))
    secrets = {name: kubernetes_secrets.secret_name(who) for name, who in SECRET_OF.items()}
    secrets["agent"] = kubernetes_secrets.POOL_SECRET
    assert sorted(secrets.values()) == sorted(s["metadata"]["name"] for s in made)
    for (kind, name), doc in built.items():
        if name in secrets and kind != "Service":
            pod = doc["spec"]["template"]["spec"]
            (volume,) = [v for v in pod["volumes"] if v["name"] == "credentials"]
            assert volume["secret"]["secretName"] == secrets[name], name
            assert all("tcp/" not in arg for c in pod["containers"] for arg in c["args"]), name
    for key, doc in built.items():
        if key[1] in SECRET_OF and key[0] != "Service":
            assert _without_security(doc) == plain[key], key
        elif key[1] != "agent":
            assert doc == plain[key], key
    agents = built["StatefulSet", "agent"]
    assert _without_security(agents)["spec"]["template"] == plain["Deployment", "agent"]["spec"]["template"]
    assert agents["spec"]["replicas"] == plain["Deployment", "agent"]["spec"]["replicas"]
    (index,) = [e for e in agents["spec"]["template"]["spec"]["containers"][0]["env"]
                if e["name"] == "SWARM_AGENT_INDEX"]  # fmt: skip
    assert index["valueFrom"]["fieldRef"]["fieldPath"] == "metadata.labels['apps.kubernetes.io/pod-index']"


def test_the_kubernetes_secrets_are_valid_and_a_pool_too_big_for_one_is_one_line(tmp_path, monkeypatch):
    made = kubernetes_secrets.secrets(credentials.make(tmp_path, 2, pool=True), pool=True)
    for secret in made:
        assert kubernetes_validate.validate(secret, KUBERNETES, strict=True)
    assert set(made[-1]["data"]) == {credentials.POOL_MARK} | {f"agent{i}.{f}" for i in (1, 2)
                                                                for f in credentials.IDENTITY_FILES}  # fmt: skip
    monkeypatch.setattr(kubernetes_secrets, "SECRET_LIMIT", sum(map(len, made[-1]["data"].values())) * 3 // 5)
    with pytest.raises(credentials.CredentialsError, match=r"swarm-agent-pool would hold \d+ bytes, over the \d+ a "
                       r"Kubernetes Secret may: make at most 1 agent identities"):  # fmt: skip
        kubernetes_secrets.secrets(tmp_path, pool=True)


def test_swarm_credentials_writes_the_secrets_private_and_refuses_a_shared_identity_for_them(tmp_path):
    made = subprocess.run([sys.executable, "-m", "swarm", "credentials", str(tmp_path / "c"), "--agent-processes",
                           "2", "--pool", "--host", "router-local", "--kubernetes"], capture_output=True, text=True,
                          timeout=60)  # fmt: skip
    assert made.returncode == 0, made.stderr
    written = tmp_path / "c" / kubernetes_secrets.FILE
    assert f"kubectl apply --server-side -f {written}" in made.stdout
    assert written.stat().st_mode & 0o777 == 0o600
    secrets = list(yaml.safe_load_all(written.read_text()))
    assert secrets == kubernetes_secrets.secrets(tmp_path / "c", pool=True)
    router = x509.load_pem_x509_certificate(base64.b64decode(secrets[0]["data"]["cert.pem"]))
    names = router.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert "router-local" in names.get_values_for_type(x509.DNSName)
    shared = subprocess.run([sys.executable, "-m", "swarm", "credentials", str(tmp_path / "d"), "--shared-agents",
                             "--kubernetes"], capture_output=True, text=True, timeout=60)  # fmt: skip
    assert shared.returncode == 2 and shared.stderr.strip().splitlines() == [
        "swarm: error: --kubernetes gives each agent pod its own identity from the pool: leave out --shared-agents"
    ]
