// Per vertex, the face corners at it (corner k of face f is 4 f + k), all in one
// Int32Array: vertex v's are pool[start(v) .. start(v) + count(v)), with room up to
// start(v) + capacity(v). start, count and capacity sit side by side in `meta` (3 per vertex),
// so that a vertex's list costs one cache miss to find. A list that outgrows its room moves to
// the pool's end with twice the room (the pool doubles when full), so a PM's millions of
// splits allocate nothing per split and leave nothing to collect.
export class CornerLists {
  constructor(vertices, faceCorners) {
    this.meta = new Int32Array(3 * vertices);
    this.pool = new Int32Array(Math.max(64, 2 * faceCorners));
    this.end = 0;
  }

  start(v) {
    return this.meta[3 * v];
  }

  count(v) {
    return this.meta[3 * v + 1];
  }

  // Room for `need` corners at v (keeping its corners).
  reserve(v, need) {
    const meta = this.meta, m = 3 * v;
    if (meta[m + 2] >= need) return;
    const room = Math.max(need, 2 * meta[m + 2], 8);
    if (this.end + room > this.pool.length) {
      const grown = new Int32Array(Math.max(2 * this.pool.length, this.end + room));
      grown.set(this.pool.subarray(0, this.end));
      this.pool = grown;
    }
    if (meta[m + 1]) this.pool.copyWithin(this.end, meta[m], meta[m] + meta[m + 1]);
    meta[m] = this.end;
    meta[m + 2] = room;
    this.end += room;
  }

  push(v, corner) {
    const meta = this.meta, m = 3 * v;
    if (meta[m + 1] === meta[m + 2]) this.reserve(v, meta[m + 1] + 1);
    this.pool[meta[m] + meta[m + 1]++] = corner;
  }

  // v's corners become `corners[0 .. n)`.
  assign(v, corners, n) {
    const meta = this.meta, m = 3 * v;
    meta[m + 1] = 0;
    this.reserve(v, n + 4);  // (a new vertex gains fl and fr at once, and more as its neighbours split)
    const pool = this.pool, s = meta[m];
    for (let j = 0; j < n; j++) pool[s + j] = corners[j];
    meta[m + 1] = n;
  }

  // Keeps the corners of v whose `drop` mark is 0 (marks indexed by position in v's list), in order.
  compact(v, drop) {
    const meta = this.meta, m = 3 * v, pool = this.pool, s = meta[m], n = meta[m + 1];
    let kept = 0;
    for (let j = 0; j < n; j++) if (!drop[j]) pool[s + kept++] = pool[s + j];
    meta[m + 1] = kept;
  }

  // Drops the corners of faces numbered `firstFace` and above from v's list, in order.
  dropFrom(v, firstFace) {
    const meta = this.meta, m = 3 * v, pool = this.pool, s = meta[m], n = meta[m + 1];
    const first = 4 * firstFace;
    let kept = 0;
    for (let j = 0; j < n; j++) if (pool[s + j] < first) pool[s + kept++] = pool[s + j];
    meta[m + 1] = kept;
  }

  clear(v) {
    this.meta[3 * v + 1] = 0;
  }
}
