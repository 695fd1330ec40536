// Decoder of the .pm format, version 1 (docs/PM-FORMAT.md), for bytes that arrive in pieces:
// push() what came, and the header, the base mesh and each split record are decoded as soon
// as their last byte is there. The one module that knows the format (a later compressed format
// replaces it here). Works in browsers and in node.
//
// Decoded data, in the PM's numbering (base vertices 0..n0-1, split i creates n0+i):
//   header: {flags, baseVertices, baseFaces, baseWedges, splits, fullVertices, fullFaces,
//            fullWedges, boxMin, boxMax, metric, float64, floatsPerWedge, layout}
//   base:   {positions: Float64Array (3 per vertex), faces: Uint32Array (3 per face),
//            cornerWedges: Uint32Array | null, wedgeVertex: Uint32Array | null,
//            wedgeValues: Float32Array | null}
//   splits (growing): vs, vl, vr (Int32Array, -1 for an absent vl / vr), error
//            (Float32Array), vsAfter, vtAfter (Float64Array, 3 per split),
//            with attributes, attributeRecords[i]: {corners (6 corner wedges of fl (vs, vt,
//            vl) then fr (vt, vs, vr), -1 absent), firstWedge and newWedges (the ids it
//            introduces), newValues, changed (wedge ids), deltas (float32 ordinal deltas, fine
//            - coarse) and fine (the changed wedges' values after the split)}.
// Every check the C++ reader makes that the viewer's correctness needs is made here too:
// magic, version, flags, counts, ids in range, the base CRC and the varints' lengths. A bad
// byte throws PmFormatError naming its offset.

export class PmFormatError extends Error {
  constructor(offset, what) {
    super(`byte ${offset}: ${what}`);
    this.offset = offset;
  }
}

const MAGIC = [0x89, 0x50, 0x41, 0x52, 0x41, 0x50, 0x4d, 0x0a];
const HEADER_BYTES = 116;
const NO_ID = 0xffffffff;

// Thrown inside a parse step when the bytes end: the step is retried once more arrive.
class NeedMore extends Error {}
const NEED_MORE = new NeedMore('more bytes needed');

const CRC_TABLE = (() => {
  const table = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    table[n] = c >>> 0;
  }
  return table;
})();

function crc32(bytes, start, end) {
  let c = 0xffffffff;
  for (let i = start; i < end; i++) c = CRC_TABLE[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

// float32 / float64 ordinals (PM-FORMAT.md, "Exact deltas"): exact, through their bits.
const f32 = new Float32Array(1);
const u32 = new Uint32Array(f32.buffer);
const i32 = new Int32Array(f32.buffer);
function ordinal32(x) {
  f32[0] = x;
  const bits = u32[0];
  return bits & 0x80000000 ? ~(bits & 0x7fffffff) : i32[0];
}
function fromOrdinal32(o) {
  o |= 0;
  if (o < 0) u32[0] = (~o & 0x7fffffff) | 0x80000000;
  else i32[0] = o;
  return f32[0];
}
const f64 = new Float64Array(1);
const u64 = new BigUint64Array(f64.buffer);
const MASK63 = (1n << 63n) - 1n;
const TWO64 = 1n << 64n;
function ordinal64(x) {
  f64[0] = x;
  const bits = u64[0];
  return bits >> 63n ? -((bits & MASK63) + 1n) : bits;  // ~(bits & MASK63), as a signed value
}
function fromOrdinal64(o) {
  o = BigInt.asIntN(64, o);
  u64[0] = o < 0n ? (-o - 1n) | (1n << 63n) : o;
  return f64[0];
}

export class PmDecoder {
  constructor() {
    this.bytes = new Uint8Array(1 << 16);
    this.length = 0; // bytes received
    this.offset = 0; // bytes decoded
    this.header = null;
    this.base = null;
    this.splitCount = 0; // records decoded
    this.splitsEnd = 0; // offset after the last decoded record
  }

  // Appends `chunk` (Uint8Array) and decodes what is complete. Returns how many split records
  // this call decoded. Throws PmFormatError on bad bytes.
  push(chunk) {
    if (this.length + chunk.length > this.bytes.length) {
      let size = this.bytes.length;
      while (size < this.length + chunk.length) size *= 2;
      const grown = new Uint8Array(size);
      grown.set(this.bytes.subarray(0, this.length));
      this.bytes = grown;
    }
    this.bytes.set(chunk, this.length);
    this.length += chunk.length;
    const before = this.splitCount;
    try {
      if (!this.header) this.#parseHeader();
      if (!this.base) this.#parseBase();
      while (this.splitCount < this.header.splits) this.#parseSplit();
    } catch (e) {
      if (!(e instanceof NeedMore)) throw e;
    }
    return this.splitCount - before;
  }

  get done() {
    return this.header !== null && this.base !== null && this.splitCount === this.header.splits;
  }

  // --- reading primitives; each throws NEED_MORE at the end of the bytes -------------------
  #need(n) {
    if (this.pos + n > this.length) throw NEED_MORE;
  }
  #u8() {
    this.#need(1);
    return this.bytes[this.pos++];
  }
  #u32() {
    this.#need(4);
    const b = this.bytes, p = this.pos;
    this.pos += 4;
    return (b[p] | (b[p + 1] << 8) | (b[p + 2] << 16) | (b[p + 3] << 24)) >>> 0;
  }
  #u64() {
    const lo = this.#u32(), hi = this.#u32();
    return hi * 4294967296 + lo;
  }
  #view() {
    if (!this._view || this._view.buffer !== this.bytes.buffer)
      this._view = new DataView(this.bytes.buffer);
    return this._view;
  }
  #f32() {
    this.#need(4);
    const v = this.#view().getFloat32(this.pos, true);
    this.pos += 4;
    return v;
  }
  #f64() {
    this.#need(8);
    const v = this.#view().getFloat64(this.pos, true);
    this.pos += 8;
    return v;
  }
  #varint32() {
    const b = this.bytes;
    let p = this.pos;
    if (p + 5 <= this.length) {
      // The whole varint is here: no check per byte.
      let byte = b[p++];
      let value = byte & 0x7f;
      if (byte & 0x80) {
        byte = b[p++];
        value |= (byte & 0x7f) << 7;
        if (byte & 0x80) {
          byte = b[p++];
          value |= (byte & 0x7f) << 14;
          if (byte & 0x80) {
            byte = b[p++];
            value |= (byte & 0x7f) << 21;
            if (byte & 0x80) {
              byte = b[p++];
              if (byte >= 0x10) throw new PmFormatError(p - 1, 'varint overflows 32 bits');
              value += byte * 268435456;
            }
          }
        }
      }
      this.pos = p;
      return value;
    }
    let value = 0, shift = 0;
    for (let i = 0; i < 5; i++) {
      const byte = this.#u8();
      if (i === 4 && byte >= 0x10) throw new PmFormatError(this.pos - 1, 'varint overflows 32 bits');
      value += (byte & 0x7f) * 2 ** shift;
      if (!(byte & 0x80)) return value;
      shift += 7;
    }
    throw new PmFormatError(this.pos - 1, 'varint longer than 5 bytes');
  }
  #varint64() {
    let value = 0n, shift = 0n;
    for (let i = 0; i < 10; i++) {
      const byte = this.#u8();
      if (i === 9 && byte > 1) throw new PmFormatError(this.pos - 1, 'varint overflows 64 bits');
      value |= BigInt(byte & 0x7f) << shift;
      if (!(byte & 0x80)) return value;
      shift += 7n;
    }
    throw new PmFormatError(this.pos - 1, 'varint longer than 10 bytes');
  }
  #zigzag32() {
    const v = this.#varint32();
    return v % 2 === 0 ? v / 2 : -(v + 1) / 2;
  }
  #zigzag64() {
    const v = this.#varint64();
    return v & 1n ? -((v + 1n) >> 1n) : v >> 1n;
  }

  // --- sections ------------------------------------------------------------------------------
  #parseHeader() {
    this.pos = 0;
    for (let i = 0; i < 8; i++)
      if (this.#u8() !== MAGIC[i]) throw new PmFormatError(i, 'not a .pm file (bad magic)');
    const version = this.#u32();
    if (version !== 1) throw new PmFormatError(8, `version ${version}, this viewer reads 1`);
    const flags = this.#u32();
    if (flags & ~0x7f) throw new PmFormatError(12, `unknown flags 0x${flags.toString(16)}`);
    const h = {flags};
    h.baseVertices = this.#u32();
    h.baseFaces = this.#u32();
    h.baseWedges = this.#u32();
    h.splits = this.#u32();
    h.fullVertices = this.#u32();
    h.fullFaces = this.#u32();
    h.fullWedges = this.#u32();
    h.vertexCopies = this.#u32();
    h.inputVertices = this.#u64();
    h.inputFaces = this.#u64();
    h.boxMin = [this.#f64(), this.#f64(), this.#f64()];
    h.boxMax = [this.#f64(), this.#f64(), this.#f64()];
    const metricLength = this.#u32();
    if (metricLength > 255) throw new PmFormatError(112, 'metric name longer than 255 bytes');
    this.#need(metricLength);
    h.metric = new TextDecoder().decode(this.bytes.subarray(this.pos, this.pos + metricLength));
    this.pos += metricLength;
    h.float64 = (flags & 1) !== 0;
    h.layout = {normal: (flags & 2) !== 0, texcoord: (flags & 4) !== 0, color: (flags & 8) !== 0};
    h.floatsPerWedge = (h.layout.normal ? 3 : 0) + (h.layout.texcoord ? 2 : 0) + (h.layout.color ? 4 : 0);
    if (h.fullVertices !== h.baseVertices + h.splits)
      throw new PmFormatError(32, 'full vertex count is not base vertices + splits');
    if (h.fullFaces < h.baseFaces + h.splits || h.fullFaces > h.baseFaces + 2 * h.splits)
      throw new PmFormatError(36, 'full face count out of range');
    if (h.floatsPerWedge === 0 && (h.baseWedges || h.fullWedges))
      throw new PmFormatError(24, 'wedges without attributes');
    this.header = h;
    this.offset = this.pos;
    this.#allocateSplits();
  }

  #allocateSplits() {
    const n = this.header.splits;
    this.vs = new Int32Array(n);
    this.vl = new Int32Array(n);
    this.vr = new Int32Array(n);
    this.error = new Float32Array(n);
    this.vsAfter = new Float64Array(3 * n);
    this.vtAfter = new Float64Array(3 * n);
    this.attributeRecords = this.header.floatsPerWedge ? new Array(n) : null;
  }

  #parseBase() {
    const h = this.header;
    this.pos = this.offset;
    const n0 = h.baseVertices, f0 = h.baseFaces, w0 = h.baseWedges, F = h.floatsPerWedge;
    const size = n0 * 3 * (h.float64 ? 8 : 4) + f0 * 12 + (F ? f0 * 12 + w0 * (4 + 4 * F) : 0) + 4;
    this.#need(size);
    const positions = new Float64Array(3 * n0);
    for (let i = 0; i < 3 * n0; i++) positions[i] = h.float64 ? this.#f64() : this.#f32();
    const faces = new Uint32Array(3 * f0);
    for (let i = 0; i < 3 * f0; i++) {
      const v = this.#u32();
      if (v >= n0) throw new PmFormatError(this.pos - 4, `base face ${(i / 3) | 0} names vertex ${v} of ${n0}`);
      faces[i] = v;
    }
    let cornerWedges = null, wedgeVertex = null, wedgeValues = null;
    if (F) {
      cornerWedges = new Uint32Array(3 * f0);
      for (let i = 0; i < 3 * f0; i++) {
        const w = this.#u32();
        if (w >= w0) throw new PmFormatError(this.pos - 4, `corner wedge ${w} of ${w0}`);
        cornerWedges[i] = w;
      }
      wedgeVertex = new Uint32Array(w0);
      wedgeValues = new Float32Array(w0 * F);
      for (let w = 0; w < w0; w++) {
        wedgeVertex[w] = this.#u32();
        for (let k = 0; k < F; k++) wedgeValues[w * F + k] = this.#f32();
      }
    }
    const crcOffset = this.pos;
    const stored = this.#u32();
    if (crc32(this.bytes, 0, crcOffset) !== stored)
      throw new PmFormatError(crcOffset, 'CRC of the header and base mesh does not match');
    this.base = {positions, faces, cornerWedges, wedgeVertex, wedgeValues};
    this.offset = this.pos;
    this.splitsEnd = this.pos;
    // Current positions (for the deltas) and wedge values, as split records change them.
    this.current = new Float64Array(3 * h.fullVertices);
    this.current.set(positions);
    this.wedgeCount = w0;
    // Every wedge's values as of the last decoded split (the coarse values the next split's
    // changes are deltas from).
    if (F) {
      this.currentWedges = new Float32Array(F * Math.max(h.fullWedges, w0));
      this.currentWedges.set(wedgeValues);
    }
  }

  #parseSplit() {
    const h = this.header, i = this.splitCount, start = this.splitsEnd;
    this.pos = start;
    const V = h.baseVertices + i;
    const vs = this.#varint32(), vl1 = this.#varint32(), vr1 = this.#varint32();
    if (vs >= V) throw new PmFormatError(start, `split ${i}: vs ${vs} of ${V} vertices`);
    if (vl1 > V || vr1 > V) throw new PmFormatError(start, `split ${i}: vl or vr out of range`);
    if (vl1 === 0 && vr1 === 0) throw new PmFormatError(start, `split ${i}: neither vl nor vr`);
    const error = this.#f32();
    if (!Number.isFinite(error) || error < 0) throw new PmFormatError(this.pos - 4, `split ${i}: bad error bound`);
    // Into the record's slots at once: a record cut short is decoded again from its start.
    const cur = this.current, after = this.vsAfter, vt = this.vtAfter;
    for (let k = 0; k < 6; k++) {
      const before = cur[3 * vs + (k % 3)];
      const value = h.float64
        ? fromOrdinal64(ordinal64(before) + this.#zigzag64())
        : fromOrdinal32(ordinal32(before) + this.#zigzag32());
      if (k < 3) after[3 * i + k] = value;
      else vt[3 * i + k - 3] = value;
    }
    let attributes = null;
    if (h.floatsPerWedge) attributes = this.#parseSplitAttributes(i, vl1 !== 0, vr1 !== 0);
    // The record is whole: commit.
    this.vs[i] = vs;
    this.vl[i] = vl1 - 1;
    this.vr[i] = vr1 - 1;
    this.error[i] = error;
    for (let k = 0; k < 3; k++) {
      cur[3 * vs + k] = after[3 * i + k];
      cur[3 * V + k] = vt[3 * i + k];
    }
    if (attributes) {
      const F = h.floatsPerWedge, values = this.currentWedges;
      if (F * (this.wedgeCount + attributes.newWedges) > values.length)
        throw new PmFormatError(start, `split ${i}: more wedges than the header's ${h.fullWedges}`);
      values.set(attributes.newValues, F * this.wedgeCount);
      attributes.firstWedge = this.wedgeCount;
      for (let c = 0; c < attributes.changed.length; c++)
        for (let k = 0; k < F; k++) {
          const at = F * attributes.changed[c] + k;
          values[at] = attributes.fine[F * c + k] = fromOrdinal32(ordinal32(values[at]) + attributes.deltas[F * c + k]);
        }
      this.attributeRecords[i] = attributes;
      this.wedgeCount += attributes.newWedges;
    }
    this.splitCount = i + 1;
    this.splitsEnd = this.pos;
  }

  // Corner codes, new wedges' values and changed wedges (PM-FORMAT.md, "Split records").
  // Changed values are kept as fine values (the coarse ones are what the level had).
  #parseSplitAttributes(i, hasFl, hasFr) {
    const F = this.header.floatsPerWedge, W = this.wedgeCount;
    const corners = new Int32Array(6).fill(-1);
    const newValues = [];
    let introduced = 0;
    const slots = [...(hasFl ? [0, 1, 2] : []), ...(hasFr ? [3, 4, 5] : [])];
    for (const slot of slots) {
      const code = this.#varint32();
      if (code === 0) {
        corners[slot] = W + introduced++;
        for (let k = 0; k < F; k++) newValues.push(this.#f32());
      } else {
        if (code - 1 >= W + introduced) throw new PmFormatError(this.pos - 1, `split ${i}: corner wedge out of range`);
        corners[slot] = code - 1;
      }
    }
    const changes = this.#varint32();
    if (changes > W) throw new PmFormatError(this.pos - 1, `split ${i}: ${changes} changed wedges of ${W}`);
    const changed = new Uint32Array(changes);
    const deltas = new Int32Array(changes * F);
    for (let c = 0; c < changes; c++) {
      const w = this.#varint32();
      if (w >= W) throw new PmFormatError(this.pos - 1, `split ${i}: changed wedge ${w} of ${W}`);
      changed[c] = w;
      for (let k = 0; k < F; k++) deltas[c * F + k] = this.#zigzag32();
    }
    // fine: the changed wedges' values after the split (filled when the record is committed).
    return {corners, newWedges: introduced, newValues: Float32Array.from(newValues), changed, deltas,
      fine: new Float32Array(changes * F), firstWedge: 0};
  }
}

export {ordinal32, fromOrdinal32, ordinal64, fromOrdinal64, NO_ID};
