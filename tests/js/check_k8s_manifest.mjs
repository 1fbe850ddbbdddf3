// Checks deploy/k8s/bake-job.yaml (issue 23) against the Kubernetes API schema
// (kubernetes-models: the OpenAPI schema of each kind, validated with ajv),
// then what the bake needs of it: an Indexed Job whose completions and
// parallelism equal the N of `--shard "${JOB_COMPLETION_INDEX}/N"`.
// The validator must also refuse three broken copies (a string count, an
// unknown pull policy, a nameless container), so a check that cannot fail
// does not pass. Like the API's own schema it allows unknown fields (only
// `kubectl --validate=strict` against a server refuses those).
// Usage: node check_k8s_manifest.mjs MANIFEST.yaml; exits 1 naming what failed,
// 2 when the npm packages are missing (scripts/install-deps.sh installs them).
import fs from "node:fs";

let Job, yaml;
try {
  ({ Job } = await import("kubernetes-models/batch/v1"));
  yaml = (await import("js-yaml")).default;
} catch (e) {
  console.error(`check_k8s_manifest: npm packages missing (run scripts/install-deps.sh): ${e.message}`);
  process.exit(2);
}

const fail = (what) => {
  console.error(`check_k8s_manifest: ${what}`);
  process.exit(1);
};
const schemaError = (doc) => {
  try {
    new Job(doc).validate();
    return null;
  } catch (e) {
    return e.message.split("\n")[0];
  }
};

const path = process.argv[2];
const docs = yaml.loadAll(fs.readFileSync(path, "utf8")).filter((d) => d);
const jobs = docs.filter((d) => d.apiVersion === "batch/v1" && d.kind === "Job");
if (jobs.length !== 1) fail(`${path}: expected one batch/v1 Job, found ${jobs.length} in ${docs.length} documents`);
const job = jobs[0];
const error = schemaError(job);
if (error) fail(`${path}: not a valid Job: ${error}`);

const spec = job.spec;
if (spec.completionMode !== "Indexed") fail(`${path}: completionMode is ${spec.completionMode}, not Indexed`);
const command = [...(spec.template.spec.containers[0].command ?? []), ...(spec.template.spec.containers[0].args ?? [])].join(" ");
const shard = command.match(/--shard "?\$\{JOB_COMPLETION_INDEX\}\/(\d+)"?/);
if (!shard) fail(`${path}: the container does not run ldc bake --shard "\${JOB_COMPLETION_INDEX}/N"`);
const n = Number(shard[1]);
if (spec.completions !== n || spec.parallelism !== n)
  fail(`${path}: completions ${spec.completions} and parallelism ${spec.parallelism} must equal the shard count ${n}`);

for (const [name, broken] of [
  ["completions as a string", (d) => (d.spec.completions = "many")],
  ["an unknown imagePullPolicy", (d) => (d.spec.template.spec.containers[0].imagePullPolicy = "Sometimes")],
  ["a container without a name", (d) => delete d.spec.template.spec.containers[0].name],
]) {
  const copy = structuredClone(job);
  broken(copy);
  if (!schemaError(copy)) fail(`the schema check accepted a Job with ${name}: it cannot fail`);
}
console.log(`ok: ${path}: a valid Indexed Job of ${n} shards (kubernetes-models schema; 3 broken copies refused)`);
