"""Kubernetes checks of deploy_static_test.py: the manifests in docker/k8s fit together (Secret keys,
selectors, ports, probes, the claim, the worker's --server URL, the HPA's target)."""
import os
import re
from urllib.parse import urlparse

from deploy_files import Invocation, effective, flag_value, listen_port, pod_containers


def check_kubernetes(c, docs, image, flags):
    k8s = {}
    for path, ds in docs.items():
        if path.startswith("docker/k8s/") and not path.endswith("kustomization.yaml"):
            for d in ds:
                k8s.setdefault(d.get("kind"), []).append((path, d))
    kust = (docs.get("docker/k8s/kustomization.yaml") or [{}])[0]
    listed = set(kust.get("resources", []))
    present = {os.path.basename(p) for p in docs if p.startswith("docker/k8s/") and not p.endswith("kustomization.yaml")}
    c.check(listed == present, "kustomization.yaml lists every manifest in docker/k8s", f"{listed} vs {present}")
    for kind in ("Secret", "StatefulSet", "Service", "Deployment", "HorizontalPodAutoscaler"):
        c.check(len(k8s.get(kind, [])) == 1, f"k8s: one {kind}")
    try:
        secret = k8s["Secret"][0][1]
        sts = k8s["StatefulSet"][0][1]
        svc = k8s["Service"][0][1]
        dep = k8s["Deployment"][0][1]
        hpa = k8s["HorizontalPodAutoscaler"][0][1]
    except (KeyError, IndexError):
        return
    secret_keys = set((secret.get("data") or {})) | set((secret.get("stringData") or {}))
    c.check({"client-token", "worker-token"} <= secret_keys, "k8s Secret: client and worker tokens", str(secret_keys))

    def refs(node):
        if isinstance(node, dict):
            if "secretKeyRef" in node:
                yield node["secretKeyRef"]
            for v in node.values():
                yield from refs(v)
        elif isinstance(node, list):
            for v in node:
                yield from refs(v)

    for kind, items in k8s.items():
        for path, d in items:
            for r in refs(d):
                c.check(r.get("name") == secret["metadata"]["name"] and r.get("key") in secret_keys,
                        f"{path}: secretKeyRef {r.get('name')}/{r.get('key')} is defined by the Secret")

    def workload(d, label):
        spec = d["spec"]
        tmpl_labels = spec["template"]["metadata"]["labels"]
        sel = spec["selector"]["matchLabels"]
        c.check(all(tmpl_labels.get(k) == v for k, v in sel.items()), f"k8s {label}: selector matches its pod labels")
        containers = pod_containers(d)
        c.check(len(containers) == 1, f"k8s {label}: one container")
        ct = containers[0]
        entry, args = effective(ct.get("command"), ct.get("args"), *image)
        inv = Invocation(f"k8s {label}", os.path.basename(entry[0]), [str(a) for a in entry[1:] + args])
        flags.check(inv)
        env = {e["name"]: e for e in ct.get("env", [])}
        return spec, tmpl_labels, ct, inv, env

    spec, sts_labels, ct, inv, env = workload(sts, "StatefulSet")
    c.check(inv.program == "tessera-server", "k8s StatefulSet runs tessera-server", inv.program)
    c.check(spec.get("replicas") == 1, "k8s StatefulSet: exactly 1 replica (one SQLite writer)")
    ports = {p.get("name"): p["containerPort"] for p in ct.get("ports", [])}
    port = listen_port(inv.args)
    c.check(port in ports.values(), "k8s StatefulSet: containerPort is the --listen port", f"{ports} vs {port}")

    def resolve(p):
        return ports.get(p) if isinstance(p, str) else p

    for probe in ("readinessProbe", "livenessProbe") + (("startupProbe",) if "startupProbe" in ct else ()):
        get = (ct.get(probe) or {}).get("httpGet", {})
        c.check(get.get("path") == "/healthz" and resolve(get.get("port")) == port,
                f"k8s StatefulSet: {probe} GET /healthz on the container port", str(get))
    grace = spec["template"]["spec"].get("terminationGracePeriodSeconds")
    c.check(isinstance(grace, int) and 10 <= grace <= 300, "k8s StatefulSet: terminationGracePeriodSeconds 10..300",
            str(grace))
    vcts = spec.get("volumeClaimTemplates") or []
    c.check(bool(vcts) and all(v["spec"].get("accessModes") == ["ReadWriteOnce"] for v in vcts),
            "k8s StatefulSet: volumeClaimTemplates, ReadWriteOnce")
    mounts = {m["name"]: m["mountPath"] for m in ct.get("volumeMounts", [])}
    data_dir = flag_value(inv.args, "--data-dir")
    c.check(any(mounts.get(v["metadata"]["name"]) == data_dir for v in vcts),
            "k8s StatefulSet: --data-dir is the claim's mount", f"{data_dir} vs {mounts}")
    for var, key in (("TESSERA_CLIENT_TOKEN", "client-token"), ("TESSERA_WORKER_TOKEN", "worker-token")):
        ref = ((env.get(var) or {}).get("valueFrom") or {}).get("secretKeyRef") or {}
        c.check(ref.get("key") == key, f"k8s StatefulSet: {var} from the Secret's {key}")
    c.check(spec.get("serviceName") == svc["metadata"]["name"], "k8s StatefulSet: serviceName is the Service")

    sel = svc["spec"].get("selector") or {}
    c.check(bool(sel) and all(sts_labels.get(k) == v for k, v in sel.items()),
            "k8s Service selects the StatefulSet's pods", f"{sel} vs {sts_labels}")
    dep_labels = dep["spec"]["template"]["metadata"]["labels"]
    c.check(not all(dep_labels.get(k) == v for k, v in sel.items()), "k8s Service does not select the workers")
    svc_ports = svc["spec"].get("ports") or []
    c.check(len(svc_ports) == 1 and resolve(svc_ports[0].get("targetPort", svc_ports[0].get("port"))) == port,
            "k8s Service targets the coordinator's container port", str(svc_ports))

    spec, _, ct, inv, env = workload(dep, "Deployment")
    c.check(inv.program == "tessera-worker", "k8s Deployment runs tessera-worker", inv.program)
    res = ct.get("resources") or {}
    c.check({"cpu", "memory"} <= set(res.get("requests") or {}), "k8s Deployment: cpu and memory requests")
    c.check("memory" in (res.get("limits") or {}), "k8s Deployment: a memory limit")
    url = urlparse(flag_value(inv.args, "--server") or "")
    name = svc["metadata"]["name"]
    c.check(url.scheme == "http" and (url.hostname == name or (url.hostname or "").startswith(name + "."))
            and svc_ports and url.port == svc_ports[0]["port"],
            "k8s Deployment: --server names the Service and its port", url.geturl())
    ref = ((env.get("TESSERA_WORKER_TOKEN") or {}).get("valueFrom") or {}).get("secretKeyRef") or {}
    c.check(ref.get("key") == "worker-token", "k8s Deployment: TESSERA_WORKER_TOKEN from the Secret")
    c.check("TESSERA_CLIENT_TOKEN" not in env, "k8s Deployment: workers do not get the client token")
    for a in inv.args:
        for var in re.findall(r"\$\((\w+)\)", a):
            c.check(var in env, f"k8s Deployment: $({var}) in args is a container env var")

    c.check(hpa.get("apiVersion") == "autoscaling/v2", "k8s HPA: autoscaling/v2")
    target = hpa["spec"].get("scaleTargetRef", {})
    c.check(target.get("kind") == "Deployment" and target.get("name") == dep["metadata"]["name"],
            "k8s HPA targets the worker Deployment", str(target))
    c.check(any(m.get("resource", {}).get("name") == "cpu" for m in hpa["spec"].get("metrics", [])), "k8s HPA: on CPU")
    c.check(1 <= hpa["spec"].get("minReplicas", 1) <= hpa["spec"]["maxReplicas"], "k8s HPA: min <= max replicas")
