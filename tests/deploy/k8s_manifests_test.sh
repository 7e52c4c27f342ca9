#!/usr/bin/env bash
# deploy/k8s renders offline (kubectl kustomize) and the consistency checks of k8s_check.py pass
# (`consistency`, the default), or every document passes the Kubernetes schemas (`schemas`: npm
# kubernetes-models, when npm can install it within 2 minutes; otherwise the script exits 77, which
# ctest reports as skipped, not passed). A deliberately broken copy must fail each check (the checks
# can fail). Usage: k8s_manifests_test.sh [consistency|schemas]. Env: K8S (deploy/k8s), HERE (tests/deploy).
set -u
# shellcheck source-path=SCRIPTDIR source=../util/test_preamble.sh
source "$(dirname "${BASH_SOURCE[0]}")/../util/test_preamble.sh"

if command -v kubectl >/dev/null; then
  kubectl kustomize "$K8S" >"$tmp/all.yaml"
  check "kubectl kustomize renders" test $? -eq 0
else
  # No kubectl: render the listed resources as they are (this kustomization only adds labels).
  /usr/bin/python3 - "$K8S" >"$tmp/all.yaml" <<'PY'
import sys, yaml
k = yaml.safe_load(open(f"{sys.argv[1]}/kustomization.yaml"))
print("\n---\n".join(open(f"{sys.argv[1]}/{r}").read() for r in k["resources"]))
PY
  echo "note: kubectl not found; rendered the resources without kustomize"
fi
check "7 documents" test "$(grep -c '^kind:' "$tmp/all.yaml")" -eq 7
step="${1:-consistency}"

if [ "$step" = "consistency" ]; then

/usr/bin/python3 "$HERE/k8s_check.py" <"$tmp/all.yaml"
check "consistency checks pass" test $? -eq 0
# A broken copy: the grace period shorter than geodexd's and a port renamed.
sed -e 's/terminationGracePeriodSeconds: 35/terminationGracePeriodSeconds: 5/' \
    -e 's/targetPort: grpc$/targetPort: grpcx/' "$tmp/all.yaml" >"$tmp/broken.yaml"
/usr/bin/python3 "$HERE/k8s_check.py" <"$tmp/broken.yaml" >"$tmp/broken.txt"
check "consistency check catches a broken copy" test $? -ne 0
check "it names the grace period" grep -q terminationGracePeriodSeconds "$tmp/broken.txt"

  finish "k8s manifests (consistency)"
  exit
fi

models="${GEODEX_NPM_CACHE:-$HOME/.cache/geodex-k8s-models}"
if command -v npm >/dev/null && command -v node >/dev/null &&
  { [ -d "$models/node_modules/kubernetes-models" ] ||
    (mkdir -p "$models" && cd "$models" &&
     timeout 120 npm install --silent --no-audit --no-fund kubernetes-models@5 js-yaml@4 >/dev/null 2>&1); }; then
  cp "$HERE/k8s_validate.mjs" "$models/validate.mjs"
  node "$models/validate.mjs" <"$tmp/all.yaml"
  check "schemas (kubernetes-models)" test $? -eq 0
  sed -e 's/replicas: 3/replicas: "three"/' "$tmp/all.yaml" | node "$models/validate.mjs" >/dev/null 2>&1
  check "schema check catches replicas: \"three\"" test $? -ne 0
else
  echo "note: npm could not provide kubernetes-models here; the schema check is skipped"
  exit 77  # ctest: SKIP_RETURN_CODE
fi

finish "k8s manifests (schemas)"
