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
// reached), `faces` (Uint32Array, 3 per face; the first faceCount are the level's).

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
    // Per vertex, its faces (ids), as plain arrays: a vertex has a handful.
    this.vertexFaces = new Array(h.fullVertices);
    for (let v = 0; v < h.fullVertices; v++) this.vertexFaces[v] = [];
    for (let f = 0; f < h.baseFaces; f++)
      for (let k = 0; k < 3; k++) this.vertexFaces[base.faces[3 * f + k]].push(f);
    // Per split applied: the faces it moved to vt, and where vs was (to undo it).
    this.fans = new Array(h.splits);
    this.vsBefore = new Float32Array(3 * h.splits);
  }

  get vertexCount() {
    return this.n0 + this.level;
  }

  // Faces after `level` splits (the faces count of each split: 1 or 2).
  facesAt(level) {
    const d = this.decoder;
    let faces = d.header.baseFaces;
    for (let i = 0; i < level; i++) faces += (d.vl[i] >= 0 ? 1 : 0) + (d.vr[i] >= 0 ? 1 : 0);
    return faces;
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

  #corner(f, v) {
    const t = this.faces;
    return t[3 * f] === v ? 0 : t[3 * f + 1] === v ? 1 : 2;
  }

  #split(i) {
    const d = this.decoder, vs = d.vs[i], vl = d.vl[i], vr = d.vr[i], vt = this.n0 + i;
    const t = this.faces, ring = this.vertexFaces[vs];
    // (a, b) of each face of vs, rotated to start at vs.
    const a = new Array(ring.length), b = new Array(ring.length);
    for (let j = 0; j < ring.length; j++) {
      const f = ring[j], k = this.#corner(f, vs);
      a[j] = t[3 * f + ((k + 1) % 3)];
      b[j] = t[3 * f + ((k + 2) % 3)];
    }
    const taken = new Uint8Array(ring.length);
    const fan = [];
    let hitBoundary = true;
    if (vr >= 0) {
      let j = a.indexOf(vr);
      hitBoundary = j < 0;
      while (j >= 0) {
        if (taken[j]) throw new Error(`split ${i}: the fan around ${vs} does not close`);
        taken[j] = 1;
        fan.push(ring[j]);
        if (vl >= 0 && b[j] === vl) break;
        j = a.indexOf(b[j]);
        if (j < 0) hitBoundary = true;
      }
    }
    if (vl >= 0 && hitBoundary) {
      let j = b.indexOf(vl);
      while (j >= 0) {
        if (taken[j]) throw new Error(`split ${i}: the fan around ${vs} never reaches a boundary`);
        taken[j] = 1;
        fan.push(ring[j]);
        j = b.indexOf(a[j]);
      }
    }
    for (const f of fan) t[3 * f + this.#corner(f, vs)] = vt;
    this.vertexFaces[vs] = ring.filter((_, j) => !taken[j]);
    this.vertexFaces[vt] = fan.slice();
    const addFace = (p, q, r) => {
      const f = this.faceCount++;
      t[3 * f] = p;
      t[3 * f + 1] = q;
      t[3 * f + 2] = r;
      this.vertexFaces[p].push(f);
      this.vertexFaces[q].push(f);
      this.vertexFaces[r].push(f);
    };
    if (vl >= 0) addFace(vs, vt, vl);
    if (vr >= 0) addFace(vt, vs, vr);
    this.fans[i] = fan;
    const pos = this.positions;
    for (let k = 0; k < 3; k++) {
      this.vsBefore[3 * i + k] = pos[3 * vs + k];
      pos[3 * vs + k] = d.vsAfter[3 * i + k];
      pos[3 * vt + k] = d.vtAfter[3 * i + k];
    }
  }

  #unsplit(i) {
    const d = this.decoder, vs = d.vs[i], vl = d.vl[i], vr = d.vr[i], vt = this.n0 + i;
    const t = this.faces;
    const added = (vl >= 0 ? 1 : 0) + (vr >= 0 ? 1 : 0);
    const firstNew = this.faceCount - added;
    const notNew = (f) => f < firstNew;
    this.vertexFaces[vs] = this.vertexFaces[vs].filter(notNew);
    if (vl >= 0) this.vertexFaces[vl] = this.vertexFaces[vl].filter(notNew);
    if (vr >= 0) this.vertexFaces[vr] = this.vertexFaces[vr].filter(notNew);
    for (const f of this.fans[i]) {
      t[3 * f + this.#corner(f, vt)] = vs;
      this.vertexFaces[vs].push(f);
    }
    this.vertexFaces[vt] = [];
    this.faceCount = firstNew;
    const pos = this.positions;
    for (let k = 0; k < 3; k++) pos[3 * vs + k] = this.vsBefore[3 * i + k];
  }
}
