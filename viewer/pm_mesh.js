// A Progressive Mesh at a level: the decoder's base mesh with its first `level` vertex splits
// applied (Hoppe 96), moved to any level the decoder has reached by applying or undoing
// splits, without re-fetching. The split's geometry follows the fan rule of
// engine/pm/progressive_mesh.h, as engine/pm/fan_mesh.cpp applies it:
//  - a face (vs, a, b) of vs: the next face counter-clockwise holds vs->b, the previous a->vs;
//  - with vr: start at the face holding vs->vr and turn counter-clockwise until the face
//    holding vl->vs is taken, or there is no next face (a boundary);
//  - with vl, and vr absent or that walk stopped at a boundary: start at the face holding
//    vl->vs and turn clockwise until there is no previous face;
//  - a vs without faces (nor vl, vr) has an empty fan: the split brings a component back.
// Positions: vs takes vsAfter, the new vertex vt = n0 + i vtAfter; undoing restores vs.
//
// Buffers for drawing: `positions` (Float32Array, 3 per vertex, every vertex the decoder has
// reached), `faces` (Uint32Array, 3 per face; the first faceCount are the level's), and with
// attributes `cornerWedges` (3 per face) and `wedgeValues` (floatsPerWedge per wedge).
import {CornerLists} from './corner_lists.js';
import {fromOrdinal32, ordinal32} from './pm_decoder.js';

// Where corner 4 f + k (CornerLists' id) is in `faces`.
function cornerIndex(c) {
  return 3 * (c >> 2) + (c & 3);
}

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
    // Per vertex, the face corners at it (corner k of face f is 4 f + k: cornerIndex).
    this.vertexCorners = new CornerLists(h.fullVertices, 3 * h.fullFaces);
    for (let f = 0; f < h.baseFaces; f++)
      for (let k = 0; k < 3; k++) this.vertexCorners.push(base.faces[3 * f + k], 4 * f + k);
    // Per split applied, for undoing it: the corners it moved from vs to vt, split i's at
    // fanPool[fanStart[i] .. fanStart[i + 1]) (splits apply in order, so the pool grows in
    // order), and where vs was.
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

  // Selective refinement (Hoppe 96 section 5, Hoppe 97's dependencies): from the base mesh,
  // the decoded splits `want(i)` asks for and those they depend on (the splits that create
  // their vs, vl and vr, and the split of their vs before them, recursively), applied in order
  // where the fan rule finds their faces. Every vertex is then either where the full sequence
  // puts it or, when its next split is not applied, where that split finds it. A new PmMesh
  // only (it leaves the sequence of levels: setLevel no longer applies). Returns the splits
  // applied.
  refineSelectively(want) {
    if (this.level !== 0 || this.selective) throw new Error('refineSelectively: on a fresh PmMesh only');
    this.selective = true;
    const d = this.decoder, n = d.splitCount, n0 = this.n0;
    // Each split's previous split of the same vs (-1: none).
    const previous = new Int32Array(n), lastSplit = new Int32Array(d.header.fullVertices).fill(-1);
    for (let i = 0; i < n; i++) {
      previous[i] = lastSplit[d.vs[i]];
      lastSplit[d.vs[i]] = i;
    }
    const wanted = new Uint8Array(n);
    for (let i = 0; i < n; i++) wanted[i] = want(i) ? 1 : 0;
    for (let i = n - 1; i >= 0; i--) {
      if (!wanted[i]) continue;
      if (previous[i] >= 0) wanted[previous[i]] = 1;
      const vs = d.vs[i], vl = d.vl[i], vr = d.vr[i];
      if (vs >= n0) wanted[vs - n0] = 1;
      if (vl >= n0) wanted[vl - n0] = 1;
      if (vr >= n0) wanted[vr - n0] = 1;
    }
    let applied = 0;
    for (let i = 0; i < n; i++) {
      if (!wanted[i]) continue;
      const size = this.#findFan(i);
      if (typeof size === 'string') continue;
      this.#apply(i, size);
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
  // With attributes, the wedge values likewise (engine/pm/geomorph.h's rule): a wedge that
  // exists at the coarser level moves from its value there (`coarseWedgeValues`) to its value
  // at the finer one (`fineWedgeValues`); a wedge introduced between them keeps its value (only
  // faces the splits add use it, and they start with no area). Null without attributes.
  geomorph(level) {
    level = Math.max(0, Math.min(level, this.decoder.splitCount));
    const coarse = Math.min(this.level, level), fine = Math.max(this.level, level);
    const F = this.floatsPerWedge;
    this.setLevel(coarse);
    const atCoarse = this.positions.slice(0, 3 * (this.n0 + coarse));
    const wedgesAtCoarse = F ? this.wedgeValues.slice(0, F * this.#wedgesAt(coarse)) : null;
    this.setLevel(fine);
    const n = this.n0 + fine;
    const ancestor = new Uint32Array(n);
    for (let v = 0; v < n; v++) ancestor[v] = v;
    for (let i = coarse; i < fine; i++) ancestor[this.n0 + i] = ancestor[this.decoder.vs[i]];
    const coarsePositions = new Float32Array(3 * n);
    for (let v = 0; v < n; v++)
      for (let k = 0; k < 3; k++) coarsePositions[3 * v + k] = atCoarse[3 * ancestor[v] + k];
    let coarseWedgeValues = null, fineWedgeValues = null;
    if (F) {
      fineWedgeValues = this.wedgeValues.slice(0, F * this.#wedgesAt(fine));
      coarseWedgeValues = fineWedgeValues.slice();
      coarseWedgeValues.set(wedgesAtCoarse);
    }
    return {coarse, fine, coarsePositions, finePositions: this.positions.slice(0, 3 * n),
      coarseWedgeValues, fineWedgeValues};
  }

  // Wedges in use at `level`: the base's and those the splits before it introduced.
  #wedgesAt(level) {
    const d = this.decoder;
    return level < d.splitCount ? d.attributeRecords[level].firstWedge : d.wedgeCount;
  }

  // The wedge values of the level now at (1 - t) from + t to (geomorph()'s arrays); at t = 1
  // exactly `to`.
  morphWedgeValues(from, to, t) {
    const values = this.wedgeValues, n = from.length;
    if (t >= 1) return values.set(to);
    for (let j = 0; j < n; j++) values[j] = from[j] + (to[j] - from[j]) * t;
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

  // Where the faces of vs (rotated to start at vs: (vs, a, b)) hold `value` as a (b): the
  // first such face's index in the ring, or -1. A ring has a handful of faces.
  #findIn(keys, n, value) {
    for (let j = 0; j < n; j++) if (keys[j] === value) return j;
    return -1;
  }

  // How many faces of vs split i moves to vt (the fan rule; their corners at vs in this.fan,
  // and marked in this.taken by their place in vs's list), or a string saying why it does not
  // fit the mesh as it is (in a selective refinement, earlier skips change neighbourhoods).
  #findFan(i) {
    const d = this.decoder, vs = d.vs[i], vl = d.vl[i], vr = d.vr[i];
    const t = this.faces, lists = this.vertexCorners, n = lists.count(vs);
    if (n === 0) {
      // A component coming back: vs, vl and vr are faceless, joined by the new faces alone.
      if (vl >= 0 && lists.count(vl) > 0) return `${vl} has faces but ${vs} has none`;
      if (vr >= 0 && lists.count(vr) > 0) return `${vr} has faces but ${vs} has none`;
      return 0;
    }
    this.#scratchFor(n);
    const a = this.ringA, b = this.ringB, taken = this.taken, ring = lists.pool, s = lists.start(vs);
    for (let j = 0; j < n; j++) {
      const c = ring[s + j], k = c & 3, f3 = 3 * (c >> 2);
      a[j] = t[f3 + (k === 2 ? 0 : k + 1)];
      b[j] = t[f3 + (k === 0 ? 2 : k - 1)];
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

  // Appends face (p, q, r) and lists its corners.
  #addFace(p, q, r) {
    const t = this.faces, lists = this.vertexCorners, f = this.faceCount++;
    t[3 * f] = p;
    t[3 * f + 1] = q;
    t[3 * f + 2] = r;
    lists.push(p, 4 * f);
    lists.push(q, 4 * f + 1);
    lists.push(r, 4 * f + 2);
  }

  // Split i again after it was undone: the mesh is the level it was split at, so its fan is the
  // one kept, not searched for again.
  #redo(i) {
    const d = this.decoder, vs = d.vs[i], lists = this.vertexCorners, pool = this.fanPool;
    const first = this.fanStart[i], size = this.fanStart[i + 1] - first, n = lists.count(vs);
    this.#scratchFor(n);
    const taken = this.taken, fan = this.fan, ring = lists.pool, s = lists.start(vs);
    for (let j = 0; j < size; j++) fan[j] = pool[first + j];
    for (let j = 0; j < n; j++) {
      const c = ring[s + j];
      let inFan = 0;
      for (let k = 0; k < size; k++) if (fan[k] === c) inFan = 1;
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
    const t = this.faces, fan = this.fan, lists = this.vertexCorners;
    for (let j = 0; j < size; j++) t[cornerIndex(fan[j])] = vt;
    // The fan leaves vs (keeping the order of the rest) for vt.
    lists.compact(vs, this.taken);
    lists.assign(vt, fan, size);
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
    const lists = this.vertexCorners;
    lists.dropFrom(vs, firstNew);
    if (vl >= 0) lists.dropFrom(vl, firstNew);
    if (vr >= 0) lists.dropFrom(vr, firstNew);
    for (let j = this.fanStart[i]; j < this.fanStart[i + 1]; j++) {
      const c = this.fanPool[j];
      t[cornerIndex(c)] = vs;
      lists.push(vs, c);
    }
    lists.clear(vt);
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
