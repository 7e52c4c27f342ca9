// Validates every document of a rendered manifest (stdin, YAML) against the Kubernetes schemas of
// npm's kubernetes-models. Exit 1 on the first invalid document, naming it.
import fs from "node:fs";
import yaml from "js-yaml";

const modules = {
  "v1": "kubernetes-models/v1",
  "apps/v1": "kubernetes-models/apps/v1",
  "policy/v1": "kubernetes-models/policy/v1",
};
const docs = yaml.loadAll(fs.readFileSync(0, "utf8")).filter(Boolean);
let checked = 0;
for (const doc of docs) {
  const path = modules[doc.apiVersion];
  if (!path) throw new Error(`no schema module for apiVersion ${doc.apiVersion}`);
  const Model = (await import(path))[doc.kind];
  if (!Model) throw new Error(`no schema for ${doc.apiVersion} ${doc.kind}`);
  try {
    new Model(doc).validate();
  } catch (e) {
    console.error(`${doc.kind}/${doc.metadata?.name}: ${e.message}`);
    process.exit(1);
  }
  checked++;
}
console.log(`kubernetes-models: ${checked} documents valid`);
