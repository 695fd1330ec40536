// `parapm lod -o X.glb|.gltf` and `parapm lods` checked by the Khronos glTF validator (npm
// gltf-validator, pinned by package-lock.json) and against the levels `parapm lod` writes as
// PLY: every committed test mesh's energy PM, a level as .glb and .gltf (no errors; the same
// corners, normals, texture coordinates and colours as the PLY level, in glTF's conventions), a
// chain of levels in one file (MSFT_lod from the finest node to the coarser ones, each level's
// faces and error bound in its node's extras).
// PARAPM_BIN: the parapm program (default: build/bin/parapm of this checkout).
import {test} from 'node:test';
import assert from 'node:assert/strict';
import {execFileSync, spawnSync} from 'node:child_process';
import {mkdtempSync, readFileSync, readdirSync, rmSync} from 'node:fs';
import {tmpdir} from 'node:os';
import {join} from 'node:path';
import validator from 'gltf-validator';

import {parapm, readPly, root, simplified} from '../../viewer/test/support.mjs';

const meshes = readdirSync(join(root, 'tests', 'data')).filter((f) => /\.(ply|obj|stl|off)(\.gz)?$/.test(f));

// Runs await fn(dir) in a fresh temporary folder, removed afterwards.
async function withTempDir(fn) {
  const dir = mkdtempSync(join(tmpdir(), 'parapm-gltf-'));
  try {
    return await fn(dir);
  } finally {
    rmSync(dir, {recursive: true, force: true});
  }
}

function run(...args) {
  return execFileSync(parapm, ['--log-level', 'error', ...args], {encoding: 'utf8'});
}

// The validator's report of a file: its errors, and its warnings for the test's log.
async function validate(path) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(path)), {uri: path, maxIssues: 50});
  const errors = report.issues.messages.filter((m) => m.severity === 0);
  return {errors, warnings: report.issues.numWarnings, report};
}

// A glTF file's JSON and its buffer (a .glb's BIN chunk, a .gltf's base64 data URI).
function parseGltf(path) {
  const bytes = readFileSync(path);
  if (path.endsWith('.gltf')) {
    const gltf = JSON.parse(bytes.toString('utf8'));
    const uri = gltf.buffers[0].uri;
    return {gltf, bin: Buffer.from(uri.slice(uri.indexOf(',') + 1), 'base64')};
  }
  assert.equal(bytes.readUInt32LE(0), 0x46546c67, 'glb magic');
  assert.equal(bytes.readUInt32LE(8), bytes.length, 'glb length');
  const jsonLength = bytes.readUInt32LE(12);
  const gltf = JSON.parse(bytes.subarray(20, 20 + jsonLength).toString('utf8'));
  const binStart = 20 + jsonLength;
  return {gltf, bin: bytes.subarray(binStart + 8, binStart + 8 + bytes.readUInt32LE(binStart))};
}

// An accessor's values as a typed array (float32 or uint32; the writer packs them tightly).
function accessor({gltf, bin}, index) {
  const a = gltf.accessors[index], view = gltf.bufferViews[a.bufferView];
  const size = {SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4}[a.type] * a.count;
  const copy = new Uint8Array(bin.subarray(view.byteOffset + (a.byteOffset || 0), view.byteOffset + (a.byteOffset || 0) + 4 * size));
  return a.componentType === 5126 ? new Float32Array(copy.buffer) : new Uint32Array(copy.buffer);
}

// Per face corner of a level's primitive: its position, and its attributes by PLY name.
function gltfCorners(file, meshIndex) {
  const primitive = file.gltf.meshes[meshIndex].primitives[0];
  const indices = accessor(file, primitive.indices);
  const attributes = {};
  for (const [name, index] of Object.entries(primitive.attributes)) attributes[name] = accessor(file, index);
  return Array.from(indices, (v) => ({
    position: Array.from(attributes.POSITION.subarray(3 * v, 3 * v + 3)),
    normal: attributes.NORMAL && Array.from(attributes.NORMAL.subarray(3 * v, 3 * v + 3)),
    uv: attributes.TEXCOORD_0 && Array.from(attributes.TEXCOORD_0.subarray(2 * v, 2 * v + 2)),
    color: attributes.COLOR_0 && Array.from(attributes.COLOR_0.subarray(4 * v, 4 * v + 4)),
  }));
}

// The same per corner from `parapm lod --ascii` PLY (positions as float32, as glTF holds them).
function plyCorners(path) {
  const ply = readPly(path), at = (name) => ply.properties.indexOf(name);
  return ply.faces.map((v) => {
    const values = ply.vertices[v];
    const pick = (names) => (names.every((n) => at(n) >= 0) ? names.map((n) => values[at(n)]) : undefined);
    return {
      position: pick(['x', 'y', 'z']).map(Math.fround),
      normal: pick(['nx', 'ny', 'nz']),
      uv: pick(['s', 't']),
      color: pick(['red', 'green', 'blue', 'alpha']),
    };
  });
}

function expectSameLevel(glb, ply, what) {
  assert.equal(glb.length, ply.length, `${what}: corners`);
  const near = (a, b, eps) => a.every((x, k) => Math.abs(x - b[k]) <= eps);
  for (let c = 0; c < glb.length; c++) {
    const g = glb[c], p = ply[c];
    assert.deepEqual(g.position, p.position, `${what}: corner ${c} position`);
    if (p.normal) {
      const length = Math.hypot(...p.normal);
      const unit = length > 0 ? p.normal.map((x) => x / length) : [0, 0, 1];
      assert.ok(near(g.normal, unit, 1e-5), `${what}: corner ${c} normal ${g.normal} vs ${unit}`);
    }
    if (p.uv) assert.ok(near(g.uv, [p.uv[0], 1 - p.uv[1]], 1e-6), `${what}: corner ${c} texcoord`);
    if (p.color) assert.ok(near(g.color, p.color.map((x) => x / 255), 0.5 / 255 + 1e-6), `${what}: corner ${c} colour`);
  }
}

for (const name of meshes) {
  test(`${name}: a level as .glb and .gltf is valid glTF with parapm lod's corners`, async () => {
    await withTempDir(async (dir) => {
      const pm = simplified(dir, name, '--metric', 'energy');
      const faces = Math.round(JSON.parse(run('info', pm, '--json')).full_faces / 3);
      run('lod', pm, '--faces', String(faces), '--ascii', '-o', join(dir, 'level.ply'));
      const expected = plyCorners(join(dir, 'level.ply'));
      for (const file of ['level.glb', 'level.gltf']) {
        const path = join(dir, file);
        run('lod', pm, '--faces', String(faces), '-o', path);
        const {errors, warnings} = await validate(path);
        assert.deepEqual(errors, [], `${file}: the validator's errors`);
        if (warnings) console.log(`${name} ${file}: ${warnings} warnings`);
        const parsed = parseGltf(path);
        assert.equal(parsed.gltf.asset.version, '2.0');
        assert.equal(parsed.gltf.nodes[0].extras.parapm.faces, expected.length / 3);
        expectSameLevel(gltfCorners(parsed, 0), expected, `${name} ${file}`);
      }
    });
  });
}

test('a chain of levels: MSFT_lod from the finest node, each level parapm lod\'s, its error bound in extras', async () => {
  await withTempDir(async (dir) => {
    const pm = simplified(dir, 'gmsh-aneurysm-20k.stl.gz');
    const counts = [8000, 2000, 500];
    for (const file of ['chain.glb', 'chain.gltf']) {
      const path = join(dir, file);
      const summary = JSON.parse(run('lods', pm, '-o', path, '--faces', '500,8000,2000', '--json'));
      assert.equal(summary.levels.length, 3);
      summary.levels.forEach((level, i) => assert.ok(level.faces <= counts[i], `level ${i} (finest first)`));
      const {errors} = await validate(path);
      assert.deepEqual(errors, [], `${file}: the validator's errors`);
      const parsed = parseGltf(path), {gltf} = parsed;
      assert.deepEqual(gltf.extensionsUsed, ['MSFT_lod']);
      assert.deepEqual(gltf.scenes[gltf.scene].nodes, [0]);
      assert.deepEqual(gltf.nodes[0].extensions.MSFT_lod.ids, [1, 2]);
      let previousError = -1;
      for (let i = 0; i < 3; i++) {
        const extras = gltf.nodes[i].extras.parapm;
        assert.ok(extras.error_bound >= previousError, 'coarser levels have larger error bounds');
        previousError = extras.error_bound;
        const ply = join(dir, `level-${i}.ply`);
        run('lod', pm, '--faces', String(counts[i]), '--ascii', '-o', ply);
        const expected = plyCorners(ply);
        assert.equal(extras.faces, expected.length / 3);
        expectSameLevel(gltfCorners(parsed, gltf.nodes[i].mesh), expected, `${file} level ${i}`);
      }
    }
    // By error bounds, the same way.
    const byError = join(dir, 'errors.glb');
    run('lods', pm, '-o', byError, '--errors', '0,1e9');
    const {gltf} = parseGltf(byError);
    assert.equal(gltf.nodes.length, 2);
    assert.equal(gltf.nodes[1].extras.parapm.level, 0, 'a huge bound is the base mesh');
  });
});

test('lods refuses an output that is not glTF, and asks for levels', async () => {
  await withTempDir((dir) => {
    const pm = simplified(dir, 'cad-featuretype-3k.stl');
    const wrongName = spawnSync(parapm, ['lods', pm, '-o', join(dir, 'x.ply'), '--faces', '100']);
    assert.equal(wrongName.status, 2);
    assert.match(wrongName.stderr.toString(), /\.glb or \.gltf/);
    const noLevels = spawnSync(parapm, ['lods', pm, '-o', join(dir, 'x.glb')]);
    assert.equal(noLevels.status, 2);
    assert.match(noLevels.stderr.toString(), /--faces or --errors/);
  });
});
