"""Renders deploy/k8s/kinplan.yaml into what `podman kube play` (4.3, Debian
12) runs, changing only what podman does not support; everything else
(replicas, image, args, env, resources, securityContext, grace period) is the
manifest's own. Used by deploy/k8s/play.sh.

    python deploy/k8s/podman_render.py [deploy/k8s/kinplan.yaml] > kinplan.podman.yaml

What podman does not do, and the bridge:
- Services (ClusterIP and headless): ignored by `kube play`; no cluster DNS.
  play.sh does the headless Service's job: it lists the pods' IPs (label
  app=kinplan) and gives the clients `ip:50051,...`, the address list the
  headless name would resolve to.
- HorizontalPodAutoscaler, PodDisruptionBudget: no controller; dropped.
- `ports`: podman publishes every containerPort on the host under the same
  port (no hostPort needed), so replicas 2 and 3 fail with "address already in
  use". Dropped: each pod keeps its own IP with the server on :50051, as in
  a cluster.
- Native gRPC probes (`grpc: {port}`): ignored by podman 4.3 (no health
  check at all), and podman turns an exec probe into a `CMD-SHELL` health
  check, which needs /bin/sh, absent from the FROM scratch image (always
  "unhealthy"); without systemd nothing runs health checks periodically
  anyway, and podman has no readiness gate. Dropped: play.sh probes each
  replica as the kubelet's gRPC probe does, grpc.health.v1 on the pod's IP and
  the probe's port (`kinplan health --target IP:50051`), and waits until every
  replica is SERVING.
- `imagePullPolicy` unset with a `:latest` tag means Always in Kubernetes;
  the image is built locally (build.sh), so the rendering says Never.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import yaml

DROPPED = {"Service", "HorizontalPodAutoscaler", "PodDisruptionBudget"}


def render(docs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    out = []
    for doc in docs:
        if doc["kind"] in DROPPED:
            continue
        if doc["kind"] != "Deployment":
            raise SystemExit(f"podman_render: no rendering for {doc['kind']}")
        for c in doc["spec"]["template"]["spec"]["containers"]:
            c.pop("ports", None)
            for name in ("readinessProbe", "livenessProbe", "startupProbe"):
                if "grpc" in c.get(name, {}):
                    del c[name]
            c.setdefault("imagePullPolicy", "Never")
        out.append(doc)
    return out


def main() -> None:
    src = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).with_name("kinplan.yaml"))
    docs = [d for d in yaml.safe_load_all(src.read_text()) if d]
    print(f"# rendered for podman kube play from {src.name} by podman_render.py")
    print(yaml.safe_dump_all(render(docs), sort_keys=False), end="")


if __name__ == "__main__":
    main()
