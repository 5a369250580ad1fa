#!/usr/bin/env bash
# deploy/container/make-keys.sh DIR: the keys compose.yaml and the k8s
# manifests use (docs/cluster.md): DIR/master.key{,_secret},
# DIR/worker.key{,_secret} and DIR/allow/worker.key. Uses aafarm-keygen
# from $AAFARM_BIN (default build/bin, then PATH). Refuses to overwrite.
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: make-keys.sh DIR" >&2; exit 2; }
dir=$1
keygen=${AAFARM_BIN:-build/bin}/aafarm-keygen
[ -x "$keygen" ] || keygen=aafarm-keygen
mkdir -p "$dir/allow"
chmod 700 "$dir"
"$keygen" "$dir/master"
"$keygen" "$dir/worker"
cp "$dir/worker.key" "$dir/allow/worker.key"
