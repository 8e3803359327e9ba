"""Offline checks of deploy/: the Kubernetes manifests validate against the
Kubernetes schemas (kubernetes-validate, strict), their settings agree with
each other and with the image, and the registry Dockerfile's final stage is
the podman Containerfile; the podman rendering (deploy/k8s/podman_render.py,
run by deploy/k8s/play.sh) changes only what podman does not support.

    python tests/deploy/check_deploy.py      # needs kubernetes-validate, pyyaml
"""
from __future__ import annotations

import copy
import re
import sys
from pathlib import Path

import kubernetes_validate
import yaml

ROOT = Path(__file__).resolve().parents[2]
K8S_VERSION = "1.30.0"  # oldest supported release with native gRPC probes GA (1.27+)


def final_stage(dockerfile: str) -> list[str]:
    """Instructions after the last FROM, continuation lines joined, comments and
    the COPY of the root filesystem dropped (its source differs by design)."""
    text = re.sub(r"\\\n\s*", " ", dockerfile)
    lines = [l.strip() for l in text.splitlines() if l.strip() and not l.lstrip().startswith("#")]
    last_from = max(i for i, l in enumerate(lines) if l.upper().startswith("FROM "))
    return [l for l in lines[last_from + 1 :] if not l.upper().startswith("COPY ")]


def main() -> int:
    failures: list[str] = []
    checks = 0

    def check(ok: bool, message: str) -> None:
        nonlocal checks
        checks += 1
        if not ok:
            failures.append(message)

    docker = (ROOT / "deploy/Dockerfile").read_text()
    container = (ROOT / "deploy/image/Containerfile").read_text()
    check(
        final_stage(docker) == final_stage(container),
        "deploy/Dockerfile's final stage differs from deploy/image/Containerfile:\n"
        f"  {final_stage(docker)}\n  {final_stage(container)}",
    )
    for name, text in (("Dockerfile", docker), ("Containerfile", container)):
        check(bool(re.search(r"^FROM scratch\s*$", text, re.M)), f"{name}: the final image is not FROM scratch")
    image_user = re.search(r"^USER (\d+)", container, re.M)

    docs = [d for d in yaml.safe_load_all((ROOT / "deploy/k8s/kinplan.yaml").read_text()) if d]
    for doc in docs:
        try:
            kubernetes_validate.validate(doc, K8S_VERSION, strict=True)
            check(True, "")
        except kubernetes_validate.ValidationError as err:
            check(False, f"{doc['kind']}/{doc['metadata']['name']}: {err.message}")
    kinds = {d["kind"] for d in docs}
    for needed in ("Deployment", "Service", "HorizontalPodAutoscaler", "PodDisruptionBudget"):
        check(needed in kinds, f"no {needed} in deploy/k8s/kinplan.yaml")

    deployment = next(d for d in docs if d["kind"] == "Deployment")
    pod = deployment["spec"]["template"]["spec"]
    c = pod["containers"][0]
    env = {e["name"]: e["value"] for e in c.get("env", [])}
    for probe in ("readinessProbe", "livenessProbe"):
        check("grpc" in c.get(probe, {}), f"{probe} is not a native gRPC probe")
    cpu = str(c["resources"]["requests"]["cpu"])
    check(
        env.get("KINPLAN_CPU_THREADS") == cpu,
        f"CPU pool KINPLAN_CPU_THREADS={env.get('KINPLAN_CPU_THREADS')} != cpu request {cpu}",
    )
    sc = c["securityContext"]
    for key, want in (("runAsNonRoot", True), ("readOnlyRootFilesystem", True), ("allowPrivilegeEscalation", False)):
        check(sc.get(key) == want, f"securityContext.{key} is {sc.get(key)!r}, want {want!r}")
    check(
        image_user is not None and str(sc.get("runAsUser")) == image_user.group(1),
        f"runAsUser {sc.get('runAsUser')} != the image's USER",
    )
    headless = [d for d in docs if d["kind"] == "Service" and d["spec"].get("clusterIP") == "None"]
    check(bool(headless), "no headless Service for client-side balancing")
    grace = pod.get("terminationGracePeriodSeconds", 30)
    check(
        float(env.get("KINPLAN_DRAIN_DELAY_SECS", 0)) < grace,
        "drain delay is not shorter than terminationGracePeriodSeconds",
    )

    # deploy/k8s/play.sh runs podman_render.py's rendering: it may only drop
    # what podman does not run (Services, HPA, PDB, container ports, gRPC
    # probes) and pin the pull policy; every other field is the manifest's.
    sys.path.insert(0, str(ROOT / "deploy/k8s"))
    import podman_render

    try:
        rendered = podman_render.render(copy.deepcopy(docs))
    except SystemExit as err:
        rendered = []
        check(False, f"podman_render.py: {err}")
    want = copy.deepcopy(deployment)
    for wc in want["spec"]["template"]["spec"]["containers"]:
        wc.pop("ports", None)
        for probe in ("readinessProbe", "livenessProbe", "startupProbe"):
            if "grpc" in wc.get(probe, {}):
                del wc[probe]
        wc.setdefault("imagePullPolicy", "Never")
    check(
        rendered == [want],
        "podman_render.py changes more than ports, gRPC probes and the pull policy, or keeps another kind",
    )

    for f in failures:
        print("FAIL:", f)
    print(f"deploy: {checks - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
