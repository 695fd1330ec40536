// A Progressive Mesh at a level: the decoder's base mesh with its first `level` vertex splits
// applied (Hoppe 96), moved to any level the decoder has reached by applying or undoing
// splits, without re-fetching. The split's geometry follows the fan rule of
// engine/pm/progressive_mesh.h, as engine/pm/fan_mesh.cpp applies it:
//  - a face (vs, a, b) of vs: the next face counter-clockwise holds vs->b, the previous a->vs;
//  - with vr: start at the face holding vs->vr and turn counter-clockwise until the face
//    holding vl->vs is taken, or there is no next face (a boundary);
//  - with vl, and vr absent or that walk stopped at a boundary: start at the face holding
//    vl->vs and turn clockwise until there is no previous face.
// Positions: vs takes vsAfter, the new vertex vt = n0 + i vtAfter; undoing restores vs.
//
// Buffers for drawing: `positions` (Float32Array, 3 per vertex, every vertex the decoder has
// reached), `faces` (Uint32Array, 3 per face; the first faceCount are the level's), and with
// attributes `cornerWedges` (3 per face) and `wedgeValues` (floatsPerWedge per wedge).
import {FaceLists} from './face_lists.js';
import {fromOrdinal32, ordinal32} from './pm_decoder.js';

export class PmMesh {
  constructor(decoder) {
    const h = decoder.header, base = decoder.base;
    this.decoder = decoder;
    this.n0 = h.baseVertices;
    this.level = 0;
    this.positions = new Float32Array(3 * h.fullVertices);
    this.positions.set(base.positions);
    this.faces = new Uint32Array(3 * h.fullFaces);
    this.faces.set(base.faces);
    this.faceCount = h.baseFaces;
    // With attributes (F floats per wedge: normal, texture coordinate, colour, as present):
    // each face corner's wedge, and every wedge's values at the level shown.
    this.floatsPerWedge = h.floatsPerWedge;
    if (h.floatsPerWedge) {
      this.cornerWedges = new Uint32Array(3 * h.fullFaces);
      this.cornerWedges.set(base.cornerWedges);
      this.wedgeValues = new Float32Array(h.floatsPerWedge * Math.max(h.fullWedges, h.baseWedges));
      this.wedgeValues.set(base.wedgeValues);
    }
    // Per vertex, its faces (ids).
    this.vertexFaces = new FaceLists(h.fullVertices, 3 * h.fullFaces);
    for (let f = 0; f < h.baseFaces; f++)
      for (let k = 0; k < 3; k++) this.vertexFaces.push(base.faces[3 * f + k], f);
    // Per split applied: the faces it moved to vt, and where vs was (to undo it).
    // The faces each split moved to vt, for undoing it: split i's are
    // fanPool[fanStart[i] .. fanStart[i + 1]) (splits apply in order, so the pool grows in order).
    this.fanStart = new Uint32Array(h.splits + 1);
    this.fansKnown = 0;  // splits below this have their fans kept
    this.fanPool = new Uint32Array(Math.max(16, 6 * h.splits));
    this.vsBefore = new Float32Array(3 * h.splits);
    // Scratch of #split: the ring of vs (a and b of each face) and the faces taken.
    this.ringA = new Int32Array(64);
    this.ringB = new Int32Array(64);
    this.taken = new Uint8Array(64);
    this.fan = new Int32Array(64);
  }

  // Vertices up to the highest id in use (a selective refinement's ids are not contiguous).
  get vertexCount() {
    return this.n0 + (this.selective ? this.decoder.splitCount : this.level);
  }

  // The largest level (at most the splits decoded) with at most `faces` faces.
  levelForFaces(faces) {
    const d = this.decoder;
    let count = d.header.baseFaces, level = 0;
    while (level < d.splitCount) {
      const next = count + (d.vl[level] >= 0 ? 1 : 0) + (d.vr[level] >= 0 ? 1 : 0);
      if (next > faces) break;
      count = next;
      level++;
    }
    return level;
  }

  // Applies or undoes splits until `level` (clamped to the splits decoded).
  setLevel(level) {
    level = Math.max(0, Math.min(level, this.decoder.splitCount));
    while (this.level < level) this.#split(this.level++);
    while (this.level > level) this.#unsplit(--this.level);
  }

  // Selective refinement (Hoppe 96 section 5, as engine/pm/selective_refinement.h): from the
  // base mesh, every decoded split in order, applied where `refine(i, vs, x, y, z)` (vs's
  // position now) says so and the split fits: vs, vl and vr present (a base vertex, or one a
  // split applied created) and the fan rule finding its faces. A new PmMesh only (it leaves
  // the sequence of levels: setLevel no longer applies). Returns the splits applied.
  refineSelectively(refine) {
    if (this.level !== 0 || this.selective) throw new Error('refineSelectively: on a fresh PmMesh only');
    this.selective = true;
    const d = this.decoder, present = new Uint8Array(d.header.fullVertices), pos = this.positions;
    present.fill(1, 0, this.n0);
    let applied = 0;
    for (let i = 0; i < d.splitCount; i++) {
      const vs = d.vs[i], vl = d.vl[i], vr = d.vr[i];
      if (!present[vs] || (vl >= 0 && !present[vl]) || (vr >= 0 && !present[vr])) continue;
      if (!refine(i, vs, pos[3 * vs], pos[3 * vs + 1], pos[3 * vs + 2])) continue;
      const size = this.#findFan(i);
      if (typeof size === 'string') continue;
      this.#apply(i, size);
      present[this.n0 + i] = 1;
      applied++;
    }
    return applied;
  }

  // A geomorph between the level now and `level` (Hoppe 96, section 5): the mesh is left at
  // the finer of the two, whose every vertex moves between its own position there
  // (`finePositions`) and its ancestor's at the coarser level (`coarsePositions`: a vertex
  // created by a split between the two levels descends from that split's vs), 3 floats per
  // vertex of the finer level. Faces do not change during the morph: at t = 0 the fine faces
  // around a split lie on the coarse surface, those a split adds with no area.
  geomorph(level) {
    level = Math.max(0, Math.min(level, this.decoder.splitCount));
    const coarse = Math.min(this.level, level), fine = Math.max(this.level, level);
    this.setLevel(coarse);
    const atCoarse = this.positions.slice(0, 3 * (this.n0 + coarse));
    this.setLevel(fine);
    const n = this.n0 + fine;
    const ancestor = new Uint32Array(n);
    for (let v = 0; v < n; v++) ancestor[v] = v;
    for (let i = coarse; i < fine; i++) ancestor[this.n0 + i] = ancestor[this.decoder.vs[i]];
    const coarsePositions = new Float32Array(3 * n);
    for (let v = 0; v < n; v++)
      for (let k = 0; k < 3; k++) coarsePositions[3 * v + k] = atCoarse[3 * ancestor[v] + k];
    return {coarse, fine, coarsePositions, finePositions: this.positions.slice(0, 3 * n)};
  }

  // The vertices of the level now at (1 - t) from + t to (geomorph()'s arrays).
  morphPositions(from, to, t) {
    const pos = this.positions, n = from.length;
    if (t >= 1) return pos.set(to);  // exactly, not as rounded by the interpolation
    for (let j = 0; j < n; j++) pos[j] = from[j] + (to[j] - from[j]) * t;
  }

  // Room in the split's scratch for a ring of n faces.
  #scratchFor(n) {
    if (this.taken.length >= n) return;
    this.ringA = new Int32Array(2 * n);
    this.ringB = new Int32Array(2 * n);
    this.taken = new Uint8Array(2 * n);
    this.fan = new Int32Array(2 * n);
  }

  #corner(f, v) {
    const t = this.faces;
    return t[3 * f] === v ? 0 : t[3 * f + 1] === v ? 1 : 2;
  }

  // Where the faces of vs (rotated to start at vs: (vs, a, b)) hold `value` as a (b): the
  // first such face's index in the ring, or -1. A ring has a handful of faces.
  #findIn(keys, n, value) {
    for (let j = 0; j < n; j++) if (keys[j] === value) return j;
    return -1;
  }

  // How many faces of vs split i moves to vt (the fan rule; the faces in this.fan, and marked in
  // this.taken by their place in vs's list), or a string saying why it does not fit the mesh as
  // it is (in a selective refinement, earlier skips change neighbourhoods).
  #findFan(i) {
    const d = this.decoder, vs = d.vs[i], vl = d.vl[i], vr = d.vr[i];
    const t = this.faces, lists = this.vertexFaces, n = lists.count[vs];
    this.#scratchFor(n);
    const a = this.ringA, b = this.ringB, taken = this.taken, ring = lists.pool, s = lists.start[vs];
    for (let j = 0; j < n; j++) {
      const f = ring[s + j], k = this.#corner(f, vs);
      a[j] = t[3 * f + (k === 2 ? 0 : k + 1)];
      b[j] = t[3 * f + (k === 0 ? 2 : k - 1)];
      taken[j] = 0;
    }
    if (vl >= 0 && this.#findIn(a, n, vl) < 0 && this.#findIn(b, n, vl) < 0) return `${vl} is not adjacent to ${vs}`;
    if (vr >= 0 && this.#findIn(a, n, vr) < 0 && this.#findIn(b, n, vr) < 0) return `${vr} is not adjacent to ${vs}`;
    const fan = this.fan;
    let size = 0, hitBoundary = true;
    if (vr >= 0) {
      let j = this.#findIn(a, n, vr);
      hitBoundary = j < 0;
      while (j >= 0) {
        if (taken[j]) return `the fan around ${vs} does not close`;
        taken[j] = 1;
        fan[size++] = ring[s + j];
        if (vl >= 0 && b[j] === vl) break;
        j = this.#findIn(a, n, b[j]);
        if (j < 0) hitBoundary = true;
      }
    }
    if (vl >= 0 && hitBoundary) {
      let j = this.#findIn(b, n, vl);
      while (j >= 0) {
        if (taken[j]) return `the fan around ${vs} never reaches a boundary`;
        taken[j] = 1;
        fan[size++] = ring[s + j];
        j = this.#findIn(b, n, a[j]);
      }
    }
    return size;
  }

  #split(i) {
    if (i < this.fansKnown) return this.#redo(i);
    const size = this.#findFan(i);
    if (typeof size === 'string') throw new Error(`split ${i}: ${size}`);
    this.#keepFan(i, size);
    this.fansKnown = i + 1;
    this.#apply(i, size);
  }

  // Appends face (p, q, r) and lists it at its corners.
  #addFace(p, q, r) {
    const t = this.faces, lists = this.vertexFaces, f = this.faceCount++;
    t[3 * f] = p;
    t[3 * f + 1] = q;
    t[3 * f + 2] = r;
    lists.push(p, f);
    lists.push(q, f);
    lists.push(r, f);
  }

  // Split i again after it was undone: the mesh is the level it was split at, so its fan is the
  // one kept, not searched for again.
  #redo(i) {
    const d = this.decoder, vs = d.vs[i], lists = this.vertexFaces, pool = this.fanPool;
    const first = this.fanStart[i], size = this.fanStart[i + 1] - first, n = lists.count[vs];
    this.#scratchFor(n);
    const taken = this.taken, fan = this.fan, ring = lists.pool, s = lists.start[vs];
    for (let j = 0; j < size; j++) fan[j] = pool[first + j];
    for (let j = 0; j < n; j++) {
      const f = ring[s + j];
      let inFan = 0;
      for (let k = 0; k < size; k++) if (fan[k] === f) inFan = 1;
      taken[j] = inFan;
    }
    this.#apply(i, size);
  }

  // Kept for undoing.
  #keepFan(i, size) {
    const start = this.fanStart[i];
    if (start + size > this.fanPool.length) {
      const grown = new Uint32Array(2 * (start + size));
      grown.set(this.fanPool);
      this.fanPool = grown;
    }
    const pool = this.fanPool, fan = this.fan;
    for (let j = 0; j < size; j++) pool[start + j] = fan[j];
    this.fanStart[i + 1] = start + size;
  }

  // Split i with its fan (#findFan's: this.fan[0 .. size), marked in this.taken).
  #apply(i, size) {
    const d = this.decoder, vs = d.vs[i], vl = d.vl[i], vr = d.vr[i], vt = this.n0 + i;
    const t = this.faces, fan = this.fan, faceList = this.vertexFaces;
    for (let j = 0; j < size; j++) {
      const f = fan[j];
      t[3 * f + this.#corner(f, vs)] = vt;
    }
    // The fan leaves vs (keeping the order of the rest) for vt.
    faceList.compact(vs, this.taken);
    faceList.assign(vt, fan, size);
    if (this.floatsPerWedge) this.#applyWedges(i, vl >= 0, vr >= 0);
    if (vl >= 0) this.#addFace(vs, vt, vl);
    if (vr >= 0) this.#addFace(vt, vs, vr);
    const pos = this.positions;
    for (let k = 0; k < 3; k++) {
      this.vsBefore[3 * i + k] = pos[3 * vs + k];
      pos[3 * vs + k] = d.vsAfter[3 * i + k];
      pos[3 * vt + k] = d.vtAfter[3 * i + k];
    }
  }

  // Split i's wedges: its new faces' corners (the faces are appended next, fl then fr), its
  // new wedges' values, the changed wedges' fine values.
  #applyWedges(i, hasFl, hasFr) {
    const r = this.decoder.attributeRecords[i], F = this.floatsPerWedge, values = this.wedgeValues;
    let f = this.faceCount;
    for (const [present, first] of [[hasFl, 0], [hasFr, 3]]) {
      if (!present) continue;
      for (let k = 0; k < 3; k++) this.cornerWedges[3 * f + k] = r.corners[first + k];
      f++;
    }
    values.set(r.newValues, F * r.firstWedge);
    for (let c = 0; c < r.changed.length; c++)
      for (let k = 0; k < F; k++) values[F * r.changed[c] + k] = r.fine[F * c + k];
  }

  #unsplit(i) {
    const d = this.decoder, vs = d.vs[i], vl = d.vl[i], vr = d.vr[i], vt = this.n0 + i;
    const t = this.faces;
    const added = (vl >= 0 ? 1 : 0) + (vr >= 0 ? 1 : 0);
    const firstNew = this.faceCount - added;
    const lists = this.vertexFaces;
    lists.dropFrom(vs, firstNew);
    if (vl >= 0) lists.dropFrom(vl, firstNew);
    if (vr >= 0) lists.dropFrom(vr, firstNew);
    for (let j = this.fanStart[i]; j < this.fanStart[i + 1]; j++) {
      const f = this.fanPool[j];
      t[3 * f + this.#corner(f, vt)] = vs;
      lists.push(vs, f);
    }
    lists.count[vt] = 0;
    this.faceCount = firstNew;
    if (this.floatsPerWedge) {
      // The changed wedges back to their coarse values (exact: ordinal deltas).
      const r = d.attributeRecords[i], F = this.floatsPerWedge, values = this.wedgeValues;
      for (let c = 0; c < r.changed.length; c++)
        for (let k = 0; k < F; k++) {
          const at = F * r.changed[c] + k;
          values[at] = fromOrdinal32(ordinal32(values[at]) - r.deltas[F * c + k]);
        }
    }
    const pos = this.positions;
    for (let k = 0; k < 3; k++) pos[3 * vs + k] = this.vsBefore[3 * i + k];
  }
}
