#!/usr/bin/python3
"""Consistency checks of the rendered geodex manifests (stdin, YAML) that a schema cannot see:
selectors match pod labels, Services point at named container ports, ConfigMaps exist, probes run
`geodex health`, the grace period outlasts geodexd's, the memory limit holds the mesh budget and
the result cache, the PodDisruptionBudget covers the replicas, and the gateway's upstreams are
exactly the StatefulSet's pods. Prints one line per failure; exit 1 if any."""
import re
import sys

import yaml

docs = [d for d in yaml.safe_load_all(sys.stdin) if d]
by_kind = {}
for d in docs:
    by_kind.setdefault(d["kind"], {})[d["metadata"]["name"]] = d
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def quantity_bytes(q):
    units = {"Ki": 2**10, "Mi": 2**20, "Gi": 2**30, "Ti": 2**40}
    m = re.fullmatch(r"(\d+)(Ki|Mi|Gi|Ti)?", str(q))
    return int(m.group(1)) * units.get(m.group(2), 1)


for name in ("geodex",):
    check(name in by_kind.get("StatefulSet", {}), "no StatefulSet geodex")
sts = by_kind["StatefulSet"]["geodex"]
pod = sts["spec"]["template"]
container = pod["spec"]["containers"][0]
labels = pod["metadata"]["labels"]
check(sts["spec"]["selector"]["matchLabels"].items() <= labels.items(),
      "StatefulSet selector does not match its pod labels")
check(sts["spec"]["serviceName"] in by_kind.get("Service", {}), "serviceName has no Service")
headless = by_kind["Service"][sts["spec"]["serviceName"]]
check(headless["spec"].get("clusterIP") == "None", "the StatefulSet's Service is not headless")
port_names = {p["name"] for p in container["ports"]}
for svc in by_kind["Service"].values():
    selected = [d for d in docs if d["kind"] in ("StatefulSet", "Deployment") and
                svc["spec"]["selector"].items() <= d["spec"]["template"]["metadata"]["labels"].items()]
    check(len(selected) == 1, f"Service {svc['metadata']['name']} selects {len(selected)} workloads")
    for w in selected:
        names = {p["name"] for c in w["spec"]["template"]["spec"]["containers"] for p in c["ports"]}
        for p in svc["spec"]["ports"]:
            check(p["targetPort"] in names,
                  f"Service {svc['metadata']['name']} targets missing port {p['targetPort']}")
for w in docs:
    if w["kind"] not in ("StatefulSet", "Deployment"):
        continue
    for v in w["spec"]["template"]["spec"].get("volumes", []):
        if "configMap" in v:
            check(v["configMap"]["name"] in by_kind.get("ConfigMap", {}),
                  f"{w['metadata']['name']} mounts missing ConfigMap {v['configMap']['name']}")

# geodexd: probes, grace, memory.
flags = dict(line.lstrip("-").split("=", 1) for line in
             by_kind["ConfigMap"]["geodexd-flags"]["data"]["flags"].split() if "=" in line)
for probe in ("startupProbe", "readinessProbe", "livenessProbe"):
    cmd = container.get(probe, {}).get("exec", {}).get("command", [])
    check(cmd[:1] == ["geodex"] and "health" in cmd, f"{probe} does not run geodex health")
check(container["args"][0] == "--flagfile=/etc/geodex/flags", "geodexd does not read the flag file")
check(any(m["mountPath"] == "/etc/geodex" for m in container["volumeMounts"]), "flags not mounted")
check(any(m["mountPath"] == flags["data_dir"] for m in container["volumeMounts"]),
      "the data directory is not a mounted volume")
check(sts["spec"]["volumeClaimTemplates"][0]["metadata"]["name"] == "data", "no per-pod volume")
check(pod["spec"]["terminationGracePeriodSeconds"] > float(flags["shutdown_grace_seconds"]),
      "terminationGracePeriodSeconds does not outlast --shutdown_grace_seconds")
limit = quantity_bytes(container["resources"]["limits"]["memory"])
need = int(flags["mesh_budget_bytes"]) + int(flags["result_cache_bytes"])
check(limit > need * 1.2, f"memory limit {limit} leaves under 20% over budget + cache ({need})")
check(flags["listen"].endswith(":50051") and any(p["containerPort"] == 50051 for p in container["ports"]),
      "the gRPC port does not match --listen")
check(pod["spec"]["securityContext"].get("runAsNonRoot") is True, "geodexd may run as root")

# PDB and gateway.
pdb = by_kind["PodDisruptionBudget"]["geodex"]
check(pdb["spec"]["selector"]["matchLabels"].items() <= labels.items(), "PDB selects no geodexd pod")
conf = by_kind["ConfigMap"]["geodex-gateway"]["data"]["nginx.conf"]
def upstream(name):
    block = re.search(r"upstream\s+" + name + r"\s*\{([^}]*)\}", conf)
    return re.findall(r"server\s+([\w.-]+):(\d+)", block.group(1)) if block else []
pods = [f"geodex-{i}.{sts['spec']['serviceName']}" for i in range(sts["spec"]["replicas"])]
expected = [(pod, "50051") for pod in pods]
check(upstream("geodex") == expected, f"gateway upstreams {upstream('geodex')} != the StatefulSet's pods {expected}")
# HTTP/JSON: the replicas' HTTP ports, whose calls come back to the gateway's gRPC Service.
http_port = flags.get("http_listen", ":").rsplit(":", 1)[1]
check(upstream("geodex_http") == [(pod, http_port) for pod in pods],
      f"gateway HTTP upstreams {upstream('geodex_http')} != the pods' --http_listen port {http_port}")
check(any(p["containerPort"] == int(http_port or 0) for p in container["ports"]),
      "no container port for --http_listen")
gateway_svc = by_kind["Service"]["geodex-gateway"]
check(flags.get("http_grpc_target") == f"geodex-gateway:{[p['port'] for p in gateway_svc['spec']['ports'] if p['name'] == 'grpc'][0]}",
      "--http_grpc_target is not the gateway's gRPC Service")
check("hash $http_x_mesh_id consistent" in conf, "gateway does not hash x-mesh-id consistently")
check(re.search(r"client_max_body_size\s+(\d+)m", conf) and
      int(re.search(r"client_max_body_size\s+(\d+)m", conf).group(1)) * 2**20 >=
      int(flags["max_upload_bytes"]), "gateway body limit below --max_upload_bytes")
check(re.search(r"grpc_read_timeout\s+(\d+)s", conf) and
      int(re.search(r"grpc_read_timeout\s+(\d+)s", conf).group(1)) >= 600,
      "gateway read timeout under 10 minutes (long solves)")

for f in failures:
    print("FAIL:", f)
print(f"k8s consistency: {len(docs)} documents, {len(failures)} failures")
sys.exit(1 if failures else 0)
