// Validates rendered Kubernetes manifests offline (no cluster): each object against the JSON
// schema of its apiVersion and kind, as kubernetes-models compiles them from the Kubernetes
// OpenAPI spec (types, required fields, enums, formats), and strictly: a field the API does
// not define is an error too (a misspelt field passes the schemas, which allow extra ones),
// found by walking each object beside the type declarations kubernetes-models ships.
// Usage: node validate-k8s.mjs FILE.yaml...   ("-" reads standard input). Exit 1 on any error.
import { readFileSync, readdirSync, existsSync } from "node:fs";
import { join, dirname } from "node:path";
import { fileURLToPath } from "node:url";
import { parseAllDocuments } from "yaml";

const here = dirname(fileURLToPath(import.meta.url));
const modelsDir = join(here, "node_modules", "kubernetes-models");
const machineryDir = join(here, "node_modules", "@kubernetes-models", "apimachinery");

// The type declarations: interface name -> { prop: type text }, under the global names the
// files export them as (IIoK8sApiCoreV1Container) and per file under their own (IContainer).
const globalTypes = new Map();
const fileTypes = new Map();
function walk(dir, out) {
  for (const entry of readdirSync(dir, { withFileTypes: true })) {
    if (entry.name === "node_modules") continue;
    const path = join(dir, entry.name);
    if (entry.isDirectory()) walk(path, out);
    else if (entry.name.endsWith(".d.ts")) out.push(path);
  }
  return out;
}
for (const file of [...walk(modelsDir, []), ...walk(machineryDir, [])]) {
  const lines = readFileSync(file, "utf8").split("\n");
  const locals = new Map();
  for (let i = 0; i < lines.length; i++) {
    const start = /^export interface (\w+)(?: extends [\w, ]+)? \{$/.exec(lines[i]);
    if (!start) continue;
    const props = {};
    for (i++; i < lines.length && lines[i] !== "}"; i++) {
      const prop = /^ {4}"([^"]+)"\??: (.*);?$/.exec(lines[i]);
      if (!prop) continue;
      let type = prop[2].replace(/;$/, "");
      if (type === "{") {
        const value = /^ {8}\[key: string\]: (.*);$/.exec(lines[i + 1] ?? "");
        type = value ? `Map<${value[1]}>` : "any";
      }
      props[prop[1]] = type;
    }
    locals.set(start[1], props);
  }
  fileTypes.set(file, locals);
  for (const line of lines) {
    const exported = /^export type \{ (.*) \};$/.exec(line);
    if (!exported) continue;
    for (const pair of exported[1].split(", ")) {
      const [local, global] = pair.split(" as ");
      if (locals.has(local)) globalTypes.set(global, { props: locals.get(local), file });
    }
  }
}

// The fields of `value` that its type does not define, as JSON paths.
function unknownFields(value, type, file, path, out) {
  if (value === null || typeof value !== "object") return out;
  let m;
  if ((m = /^Array<(.*)>$/.exec(type))) {
    if (Array.isArray(value)) value.forEach((v, i) => unknownFields(v, m[1], file, `${path}[${i}]`, out));
    return out;
  }
  if ((m = /^Map<(.*)>$/.exec(type))) {
    for (const [k, v] of Object.entries(value)) unknownFields(v, m[1], file, `${path}.${k}`, out);
    return out;
  }
  const known = globalTypes.get(type) ?? { props: fileTypes.get(file)?.get(type), file };
  if (!known.props || Array.isArray(value)) return out;  // a scalar, a union, an open object
  for (const [k, v] of Object.entries(value)) {
    if (!(k in known.props)) out.push(`${path}.${k}`);
    else unknownFields(v, known.props[k], known.file, `${path}.${k}`, out);
  }
  return out;
}

let objects = 0;
let errors = 0;
const inputs = process.argv.slice(2);
if (inputs.length === 0) {
  console.error("usage: node validate-k8s.mjs FILE.yaml... (- for standard input)");
  process.exit(2);
}
for (const input of inputs) {
  const text = readFileSync(input === "-" ? 0 : input, "utf8");
  for (const doc of parseAllDocuments(text)) {
    if (doc.errors.length) {
      console.error(`${input}: YAML: ${doc.errors[0].message}`);
      errors++;
      continue;
    }
    const obj = doc.toJS();
    if (obj === null) continue;
    objects++;
    const name = `${input}: ${obj.kind ?? "?"}/${obj.metadata?.name ?? "?"}`;
    const group = String(obj.apiVersion ?? "");
    const file = join(modelsDir, group, `${obj.kind}.js`);
    if (!group || !obj.kind || group.includes("..") || !existsSync(file)) {
      console.error(`${name}: no schema for apiVersion ${group} kind ${obj.kind}`);
      errors++;
      continue;
    }
    const Model = (await import(file))[obj.kind];
    const problems = [];
    try {
      new Model(obj).validate();
    } catch (e) {
      for (const err of e.errors ?? [{ instancePath: "", message: e.message }])
        problems.push(`${err.instancePath || "/"} ${err.message}`);
    }
    const decl = join(modelsDir, group, `${obj.kind}.d.ts`);
    if (!fileTypes.get(decl)?.has(`I${obj.kind}`)) problems.push(`no type declarations in ${decl}`);
    for (const path of unknownFields(obj, `I${obj.kind}`, decl, "", []))
      problems.push(`${path.slice(1)}: unknown field`);
    for (const p of problems) console.error(`${name}: ${p}`);
    if (problems.length) errors++;
  }
}
console.log(`validate-k8s: ${objects} objects, ${errors} invalid`);
process.exit(errors || objects === 0 ? 1 : 0);
