#!/usr/bin/env python3
"""tests/master/deploy/check_manifests.py ROOT: checks what cannot run here
(no container engine, no Kubernetes): the compose file and the Kubernetes
manifests parse as YAML and agree with each other and with the programs'
options (every key file an argument names is mounted, the Service selects
the master's pods, the workers connect to the Service's port), and the
Dockerfile is multi-stage on Debian 12 and copies only paths that exist.
Prints what it checked; exits 1 with the reasons when something is off."""
import os
import re
import sys

import yaml

root = sys.argv[1]
errors = []


def check(cond, what):
    if not cond:
        errors.append(what)


def arg_after(args, opt):
    return args[args.index(opt) + 1] if opt in args else None


# --- Kubernetes ---
workers = list(yaml.safe_load_all(open(os.path.join(root, "deploy/k8s/workers.yaml"))))
master = list(yaml.safe_load_all(open(os.path.join(root, "deploy/k8s/master.yaml"))))
kinds = {d["kind"]: d for d in workers + master}
for k in ("Deployment", "Service", "Job", "PersistentVolumeClaim"):
    check(k in kinds, f"k8s: no {k}")
dep, svc, job = kinds["Deployment"], kinds["Service"], kinds["Job"]


def mounted_files(pod):
    """paths of the secret's items as the container sees them"""
    files = set()
    c = pod["containers"][0]
    vols = {v["name"]: v for v in pod["volumes"]}
    for m in c["volumeMounts"]:
        v = vols[m["name"]]
        if "secret" in v:
            check(v["secret"].get("defaultMode") == 0o400, f"k8s: secret volume {v['name']} is not 0400")
            for it in v["secret"]["items"]:
                files.add(os.path.join(m["mountPath"], it["path"]))
    return files


wpod = dep["spec"]["template"]["spec"]
wargs = wpod["containers"][0]["args"]
check(wargs[0] == "aafarm-worker", "k8s: the Deployment does not run aafarm-worker")
wfiles = mounted_files(wpod)
for opt in ("--curve-secret", "--master-key"):
    check(arg_after(wargs, opt) in wfiles, f"k8s: worker {opt} {arg_after(wargs, opt)} is not mounted")
port = svc["spec"]["ports"][0]["port"]
check(arg_after(wargs, "--connect") == f"tcp://{svc['metadata']['name']}:{port}",
      "k8s: the workers do not connect to the master's Service")
check(dep["spec"]["selector"]["matchLabels"].items() <= dep["spec"]["template"]["metadata"]["labels"].items(),
      "k8s: the Deployment's selector does not match its pods")

mpod = job["spec"]["template"]["spec"]
margs = mpod["containers"][0]["args"]
check(margs[0] == "aafarm-master", "k8s: the Job does not run aafarm-master")
mfiles = mounted_files(mpod)
check(arg_after(margs, "--curve-secret") in mfiles, "k8s: the master's secret key is not mounted")
allow = arg_after(margs, "--allow-keys")
check(any(f.startswith(allow + "/") and f.endswith(".key") for f in mfiles),
      "k8s: no worker key in the master's --allow-keys folder")
check(svc["spec"]["selector"].items() <= job["spec"]["template"]["metadata"]["labels"].items(),
      "k8s: the Service does not select the master's pod")
check(arg_after(margs, "--bind").endswith(f":{svc['spec']['ports'][0]['targetPort']}"),
      "k8s: the master binds another port than the Service's targetPort")
print(f"k8s: {len(workers) + len(master)} objects parsed; worker args, master args, secret items, "
      "Service selector and ports agree")

# --- compose ---
compose = yaml.safe_load(open(os.path.join(root, "deploy/container/compose.yaml")))
svcs = compose["services"]
check(set(svcs) == {"master", "worker"}, "compose: services are not master and worker")
cm, cw = svcs["master"]["command"], svcs["worker"]["command"]
check(cm[0] == "aafarm-master" and cw[0] == "aafarm-worker", "compose: wrong programs")
check(arg_after(cw, "--connect") == "tcp://master:" + arg_after(cm, "--bind").rsplit(":", 1)[1],
      "compose: the workers do not connect to the master's port")
for s, opts in (("master", ("--curve-secret", "--allow-keys")), ("worker", ("--curve-secret", "--master-key"))):
    vols = svcs[s]["volumes"]
    check(any(v.endswith(":/keys:ro") for v in vols), f"compose: {s} does not mount the keys read-only")
    for o in opts:
        check(arg_after(svcs[s]["command"], o).startswith("/keys/"), f"compose: {s} {o} outside /keys")
check(svcs["master"]["build"]["dockerfile"] == "deploy/container/Dockerfile", "compose: wrong Dockerfile")
# the image follows the scene: no fixed -o, the master runs in its writable
# output mount and writes the scene's Display name there
check("-o" not in cm and "--output" not in cm, "compose: the master's -o names one image whatever the scene")
out_mounts = [v.split(":")[1] for v in svcs["master"]["volumes"] if not v.endswith(":ro")]
check(svcs["master"].get("working_dir") in out_mounts,
      "compose: the master does not run in its writable output mount (working_dir)")
print("compose: parsed; services, commands, key mounts and ports agree")

# --- Dockerfile ---
df = open(os.path.join(root, "deploy/container/Dockerfile")).read()
froms = re.findall(r"^FROM\s+(\S+)(?:\s+AS\s+(\S+))?", df, re.M)
check(len(froms) == 2, "Dockerfile: not two stages")
check(froms[0][0] == "debian:bookworm" and froms[1][0] == "debian:bookworm-slim",
      "Dockerfile: not Debian 12 (bookworm, bookworm-slim)")
check(re.search(r"^COPY --from=" + froms[0][1] + r"\s", df, re.M) is not None,
      "Dockerfile: the runtime stage copies nothing from the build stage")
for src in re.findall(r"^COPY\s+(?!--from)(\S+)", df, re.M):
    check(src == "." or os.path.exists(os.path.join(root, src)), f"Dockerfile: COPY {src}: no such path")
programs = ("aafarm-master", "aafarm-worker", "aafarm-slc", "aafarm-maketx", "aafarm-keygen")
targets = " ".join(re.findall(r"--target((?:\s+[\w-]+)+)", df))
for prog in programs:
    check(prog in targets.split(), f"Dockerfile: {prog} is not built (--target)")
    check(prog in df[:df.index("FROM ")], f"Dockerfile: its comment does not name {prog}")
check(re.search(r"cmake --install /build --prefix (\S+)", df) is not None,
      "Dockerfile: the build stage does not cmake --install")
print(f"Dockerfile: stages {[f[0] for f in froms]}; COPY sources exist; the five programs built and installed")

if errors:
    print("\n".join("error: " + e for e in errors), file=sys.stderr)
    sys.exit(1)
