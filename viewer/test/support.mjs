// What the viewer's tests share: the parapm program (PARAPM_BIN, default build/bin/parapm of
// this checkout), a temporary folder per test, PMs built from the committed test meshes, and
// ASCII PLY files as `parapm lod --ascii` writes them.
import {execFileSync} from 'node:child_process';
import {mkdtempSync, readFileSync, rmSync} from 'node:fs';
import {tmpdir} from 'node:os';
import {join, dirname} from 'node:path';
import {fileURLToPath} from 'node:url';

export const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const parapm = process.env.PARAPM_BIN || join(root, 'build', 'bin', 'parapm');

export function testMesh(name) {
  return join(root, 'tests', 'data', name);
}

// Runs fn(dir) in a fresh temporary folder, removed afterwards.
export function withTempDir(fn) {
  const dir = mkdtempSync(join(tmpdir(), 'parapm-js-'));
  try {
    return fn(dir);
  } finally {
    rmSync(dir, {recursive: true, force: true});
  }
}

// `parapm simplify` of a committed test mesh into dir/x.pm (more options in `args`); its path.
export function simplified(dir, name, ...args) {
  const pm = join(dir, 'x.pm');
  execFileSync(parapm, ['--log-level', 'error', 'simplify', testMesh(name), '-o', pm, ...args]);
  return pm;
}

// An ASCII PLY: its vertex properties' names, each vertex's values (in the properties' order)
// and its faces (a flat array of vertex ids, three per face).
export function readPly(path) {
  const lines = readFileSync(path, 'utf8').split('\n');
  let vertexCount = 0, faceCount = 0, i = 0, element = '';
  const properties = [];
  for (; lines[i] !== 'end_header'; i++) {
    const m = lines[i].match(/^element (vertex|face) (\d+)/);
    if (m) {
      element = m[1];
      m[1] === 'vertex' ? (vertexCount = +m[2]) : (faceCount = +m[2]);
    }
    const p = lines[i].match(/^property (\w+) (\w+)$/);
    if (p && element === 'vertex') properties.push(p[2]);
  }
  const vertices = [], faces = [];
  for (let v = 0; v < vertexCount; v++) vertices.push(lines[i + 1 + v].trim().split(/\s+/).map(Number));
  for (let f = 0; f < faceCount; f++)
    faces.push(...lines[i + 1 + vertexCount + f].trim().split(/\s+/).slice(1, 4).map(Number));
  return {properties, vertices, faces};
}
