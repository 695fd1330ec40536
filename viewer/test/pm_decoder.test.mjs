// The JS decoder and mesh against the C++ writer and reader: every committed test mesh's PM
// (built by `parapm simplify --metric energy`), fed to the decoder in uneven pieces as a
// network would, gives at several face counts, refining, coarsening and refining again, the
// faces `parapm lod` writes, with their corners' attributes.
// PARAPM_BIN: the parapm program (default: build/bin/parapm of this checkout).
import {test} from 'node:test';
import assert from 'node:assert/strict';
import {execFileSync} from 'node:child_process';
import {readFileSync, readdirSync, writeFileSync} from 'node:fs';
import {join} from 'node:path';

import {PmDecoder, PmFormatError} from '../pm_decoder.js';
import {PmMesh} from '../pm_mesh.js';
import {SplitRegions} from '../split_regions.js';
import {parapm, readPly, root, simplified, withTempDir} from './support.mjs';

const meshes = readdirSync(join(root, 'tests', 'data')).filter((f) => /\.(ply|obj|stl|off)(\.gz)?$/.test(f));

// The level `parapm lod` wrote: its vertex count, its faces, and per face corner its position
// as float32 and its values by property name (a mesh with attributes has a PLY vertex per
// wedge, so its ids are not the PM's vertices; the corners' positions compare either way).
function lodLevel(path) {
  const ply = readPly(path);
  const corners = [], attributes = [];
  for (const v of ply.faces) {
    const values = ply.vertices[v];
    corners.push(...values.slice(0, 3).map(Math.fround));
    const named = {};
    ply.properties.forEach((name, k) => (named[name] = values[k]));
    attributes.push(named);
  }
  return {vertices: ply.vertices.length, faces: ply.faces, corners, attributes};
}

// The mesh's corners' attributes against the PLY's (normals and texture coordinates as
// printed, colours as the bytes the writer rounds them to).
function expectSameAttributes(mesh, layout, expected, what) {
  const F = mesh.floatsPerWedge;
  for (let c = 0; c < 3 * mesh.faceCount; c++) {
    const w = mesh.cornerWedges[c], values = mesh.wedgeValues.subarray(F * w, F * w + F);
    const ply = expected.attributes[c];
    let k = 0;
    const near = (a, b, name) =>
      assert.ok(Math.abs(a - b) <= 2e-6 * Math.max(1, Math.abs(b)), `${what}: corner ${c} ${name} ${a} != ${b}`);
    if (layout.normal) {
      near(values[0], ply.nx, 'nx');
      near(values[1], ply.ny, 'ny');
      near(values[2], ply.nz, 'nz');
      k = 3;
    }
    if (layout.texcoord) {
      near(values[k], ply.s, 's');
      near(values[k + 1], ply.t, 't');
      k += 2;
    }
    if (layout.color)
      ['red', 'green', 'blue', 'alpha'].forEach((name, j) =>
        assert.ok(Math.abs(Math.round(Math.min(1, Math.max(0, values[k + j])) * 255) - ply[name]) <= 1,
          `${what}: corner ${c} ${name} ${values[k + j]} against ${ply[name]}`));
  }
}

function cornerPositions(mesh) {
  const out = [];
  for (let c = 0; c < 3 * mesh.faceCount; c++) {
    const v = mesh.faces[c];
    out.push(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]);
  }
  return out;
}

function decodeInPieces(bytes, seed) {
  const decoder = new PmDecoder();
  let state = seed;
  for (let at = 0; at < bytes.length;) {
    state = (state * 1103515245 + 12345) % 2147483648;
    const n = 1 + (state % 4096);
    decoder.push(bytes.subarray(at, at + n));
    at += n;
  }
  return decoder;
}

// The decoded PM at several face counts, refining, coarsening and refining again, against the
// levels `parapm lod` writes.
function expectLodLevels(dir, pm, seed) {
  const bytes = new Uint8Array(readFileSync(pm));
  const decoder = decodeInPieces(bytes, seed);
  assert.ok(decoder.done, 'every split decoded');
  const mesh = new PmMesh(decoder);
  const h = decoder.header;
  const counts = [h.baseFaces, Math.round(h.fullFaces * 0.1), Math.round(h.fullFaces * 0.5), h.fullFaces,
    Math.round(h.fullFaces * 0.3), h.baseFaces, Math.round(h.fullFaces * 0.7)];  // up, down, up again
  for (const count of counts) {
    const level = join(dir, `l${count}.ply`);
    execFileSync(parapm, ['--log-level', 'error', 'lod', pm, '--faces', String(count), '--ascii', '-o', level]);
    const expected = lodLevel(level);
    mesh.setLevel(mesh.levelForFaces(count));
    assert.equal(mesh.faceCount * 3, expected.faces.length, `${count} faces`);
    assert.deepEqual(cornerPositions(mesh), expected.corners, `${count} faces: the corners`);
    if (!h.floatsPerWedge) {
      assert.equal(mesh.vertexCount, expected.vertices, `${count} faces: vertices`);
      assert.deepEqual(Array.from(mesh.faces.subarray(0, 3 * mesh.faceCount)), expected.faces);
    } else {
      expectSameAttributes(mesh, h.layout, expected, `${count} faces`);
    }
  }
  return h;
}

for (const name of meshes) {
  test(`${name}: the decoded levels are parapm lod's`, () => withTempDir((dir) => {
    // The energy: its attributes' values change at splits (E_scalar), the quadric's do not.
    expectLodLevels(dir, simplified(dir, name, '--metric', 'energy'), name.length);
  }));
}

// A ground square under 60 small open parts (each a separate component of two triangles): the
// parts' last triangles collapse away at coarse levels, and the splits that bring them back
// start from faceless vertices.
test('parts that vanish at coarse levels come back as parapm lod has them', () => withTempDir((dir) => {
  const lines = ['v 0 0 0', 'v 100 0 0', 'v 100 100 0', 'v 0 100 0', 'f 1 2 3', 'f 1 3 4'];
  let state = 7;
  const uniform = (lo, hi) => {
    state = (state * 1103515245 + 12345) % 2147483648;
    return lo + (hi - lo) * state / 2147483648;
  };
  const parts = 60;
  for (let k = 0; k < parts; k++) {
    const x = uniform(1, 98), y = uniform(1, 98), z = uniform(0.1, 2), side = uniform(0.2, 1);
    lines.push(`v ${x} ${y} ${z}`, `v ${x + side} ${y} ${z}`, `v ${x + side} ${y + side} ${z + side / 3}`,
      `v ${x} ${y + side} ${z}`);
    const o = 4 + 4 * k;
    lines.push(`f ${o + 1} ${o + 2} ${o + 3}`, `f ${o + 1} ${o + 3} ${o + 4}`);
  }
  const scene = join(dir, 'scene.obj');
  writeFileSync(scene, lines.join('\n') + '\n');
  for (const metric of ['quadric', 'energy']) {
    const pm = join(dir, `${metric}.pm`);
    execFileSync(parapm, ['--log-level', 'error', 'simplify', scene, '-o', pm, '--metric', metric]);
    const h = expectLodLevels(dir, pm, 3);
    assert.ok(h.baseFaces < parts, `${metric}: ${h.baseFaces} faces at the base, ${parts + 1} components`);
  }
}));

test('a damaged file is an error naming its byte, not a wrong mesh', () => {
  withTempDir((dir) => {
    const pm = simplified(dir, 'cad-featuretype-3k.stl');
    const bytes = new Uint8Array(readFileSync(pm));
    const wrongMagic = bytes.slice();
    wrongMagic[1] ^= 0xff;
    assert.throws(() => new PmDecoder().push(wrongMagic), PmFormatError);
    const flipped = bytes.slice();
    flipped[200] ^= 0x01;  // inside the base mesh: its CRC
    assert.throws(() => new PmDecoder().push(flipped), /byte \d+/);
    // Cut anywhere: what arrived decodes, nothing more, no error.
    const decoder = new PmDecoder();
    decoder.push(bytes.subarray(0, Math.floor(bytes.length / 2)));
    assert.ok(decoder.splitCount > 0 && !decoder.done);
  });
});

test('a geomorph starts on the coarse level\'s surface and ends on the fine level', () => {
  withTempDir((dir) => {
    const pm = simplified(dir, 'gmsh-aneurysm-20k.stl.gz');
    const decoder = decodeInPieces(new Uint8Array(readFileSync(pm)), 7);
    const mesh = new PmMesh(decoder);
    const coarse = 2000, fine = 6000;
    mesh.setLevel(coarse);
    const coarseCorners = cornerPositions(mesh);
    const g = mesh.geomorph(fine);
    assert.equal(mesh.level, fine);
    const fineCorners = cornerPositions(mesh);
    // At t = 0 every face of the fine level lies on the coarse level: its corners are coarse
    // vertices' positions, and the faces the splits add have no area.
    mesh.morphPositions(g.coarsePositions, g.finePositions, 0);
    const coarseSet = new Set();
    for (let c = 0; c < coarseCorners.length; c += 3) coarseSet.add(coarseCorners.slice(c, c + 3).join(','));
    const atStart = cornerPositions(mesh);
    for (let c = 0; c < atStart.length; c += 3)
      assert.ok(coarseSet.has(atStart.slice(c, c + 3).join(',')), `corner ${c / 3} is not a coarse vertex's position`);
    mesh.morphPositions(g.coarsePositions, g.finePositions, 1);
    assert.deepEqual(cornerPositions(mesh), fineCorners);
    // Coarsening: the same arrays the other way, then the splits undone.
    const back = mesh.geomorph(coarse);
    mesh.morphPositions(back.finePositions, back.coarsePositions, 1);
    mesh.setLevel(coarse);
    assert.deepEqual(cornerPositions(mesh), coarseCorners);
  });
});

test('a geomorph of a textured PM moves the wedge values too: the coarse level\'s at the start, the fine level\'s at the end', () => {
  withTempDir((dir) => {
    const pm = simplified(dir, 'pymeshlab-bunny-textured-10k.obj', '--metric', 'energy');
    const decoder = decodeInPieces(new Uint8Array(readFileSync(pm)), 11);
    const mesh = new PmMesh(decoder), F = mesh.floatsPerWedge;
    assert.ok(F > 0);
    // Each face corner: position and values, as text.
    const corners = () => {
      const out = [];
      for (let c = 0; c < 3 * mesh.faceCount; c++) {
        const v = mesh.faces[c], w = mesh.cornerWedges[c];
        out.push([...mesh.positions.subarray(3 * v, 3 * v + 3), ...mesh.wedgeValues.subarray(F * w, F * w + F)].join(','));
      }
      return out;
    };
    const coarse = 800, fine = 3000;
    mesh.setLevel(coarse);
    const coarseCorners = new Set(corners());
    const g = mesh.geomorph(fine);
    const fineCorners = corners();
    // At t = 0 every face with area is a coarse face: its corners, values included, are the
    // coarse level's (faces the splits added have two corners on one vertex: no area).
    mesh.morphPositions(g.coarsePositions, g.finePositions, 0);
    mesh.morphWedgeValues(g.coarseWedgeValues, g.fineWedgeValues, 0);
    const atStart = corners();
    let faces = 0;
    for (let f = 0; f < mesh.faceCount; f++) {
      const [a, b, c] = [0, 1, 2].map((k) => mesh.faces[3 * f + k]);
      const p = (v) => Array.from(mesh.positions.subarray(3 * v, 3 * v + 3)).join(',');
      if (p(a) === p(b) || p(b) === p(c) || p(a) === p(c)) continue;
      faces++;
      for (let k = 0; k < 3; k++) assert.ok(coarseCorners.has(atStart[3 * f + k]), `face ${f} corner ${k}`);
    }
    assert.ok(faces > 0);
    mesh.morphPositions(g.coarsePositions, g.finePositions, 1);
    mesh.morphWedgeValues(g.coarseWedgeValues, g.fineWedgeValues, 1);
    assert.deepEqual(corners(), fineCorners);
    // Undoing the splits from there gives the coarse level back exactly.
    mesh.setLevel(coarse);
    assert.deepEqual(new Set(corners()), coarseCorners);
  });
});

test('selective refinement: everything is the full mesh, nothing the base, a region stays a valid mesh', () => {
  withTempDir((dir) => {
    const pm = simplified(dir, 'stratocaster-9k.ply');
    const decoder = decodeInPieces(new Uint8Array(readFileSync(pm)), 3);
    const full = new PmMesh(decoder);
    full.setLevel(decoder.splitCount);
    const all = new PmMesh(decoder);
    assert.equal(all.refineSelectively(() => true), decoder.splitCount);
    assert.deepEqual(cornerPositions(all), cornerPositions(full));
    const none = new PmMesh(decoder);
    assert.equal(none.refineSelectively(() => false), 0);
    assert.equal(none.faceCount, decoder.header.baseFaces);
    // Refined where vs goes to x < 0 only: fewer faces than the full mesh, more than the base, and every
    // edge of the result has at most two faces (no split applied out of its neighbourhood).
    const half = new PmMesh(decoder);
    half.refineSelectively((i) => decoder.vsAfter[3 * i] < 0);
    assert.ok(half.faceCount > decoder.header.baseFaces && half.faceCount < decoder.header.fullFaces);
    const edges = new Map();
    for (let f = 0; f < half.faceCount; f++)
      for (let k = 0; k < 3; k++) {
        const a = half.faces[3 * f + k], b = half.faces[3 * f + ((k + 1) % 3)];
        const key = a < b ? `${a},${b}` : `${b},${a}`;
        edges.set(key, (edges.get(key) || 0) + 1);
      }
    for (const [edge, count] of edges) assert.ok(count <= 2, `edge ${edge} has ${count} faces`);
  });
});

test('a split\'s region holds every vertex it refines into, and a view\'s refinement stays within reach', () => {
  withTempDir((dir) => {
    const pm = simplified(dir, 'stratocaster-9k.ply');
    const decoder = decodeInPieces(new Uint8Array(readFileSync(pm)), 5);
    const regions = new SplitRegions(decoder), n0 = decoder.header.baseVertices, n = decoder.splitCount;
    const full = new PmMesh(decoder);
    full.setLevel(n);
    const at = (p, v) => [p[3 * v], p[3 * v + 1], p[3 * v + 2]];
    const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    // Split i's descendants, by brute force: vs, and every vt of a later split of one of them.
    for (let i = 0; i < n; i += 13) {
      const family = new Set([decoder.vs[i]]);
      for (let j = i; j < n; j++) if (family.has(decoder.vs[j])) family.add(n0 + j);
      const center = Array.from(regions.center.subarray(3 * i, 3 * i + 3));
      for (const v of family)
        assert.ok(distance(at(full.positions, v), center) <= regions.radius[i] * (1 + 1e-9) + 1e-12,
          `split ${i}: vertex ${v} lies outside its region`);
    }
    // A refinement that skips the splits whose reach is below a tolerance: every vertex of the
    // full mesh is within the tolerance of its ancestor in it (the geomorph's correspondence).
    const box = decoder.header.boxMax.map((x, k) => x - decoder.header.boxMin[k]);
    const tolerance = 0.01 * Math.hypot(...box);
    const cut = new PmMesh(decoder);
    cut.refineSelectively((i) => regions.reach[i] > tolerance);
    assert.ok(cut.faceCount > decoder.header.baseFaces && cut.faceCount < decoder.header.fullFaces);
    const present = new Uint8Array(n0 + n), ancestor = new Int32Array(n0 + n);
    present.fill(1, 0, n0);
    for (let v = 0; v < n0 + n; v++) ancestor[v] = v;
    for (let f = 0; f < cut.faceCount; f++) for (let k = 0; k < 3; k++) present[cut.faces[3 * f + k]] = 1;
    for (let j = 0; j < n; j++) if (!present[n0 + j]) ancestor[n0 + j] = ancestor[decoder.vs[j]];
    for (let v = 0; v < n0 + n; v++)
      assert.ok(distance(at(full.positions, v), at(cut.positions, ancestor[v])) <= tolerance * (1 + 1e-6),
        `vertex ${v} is farther than the tolerance from its ancestor ${ancestor[v]}`);
  });
});
