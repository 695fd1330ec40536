// Per vertex, the faces around it, all in one Int32Array: vertex v's are
// pool[start[v] .. start[v] + count[v]), with room up to start[v] + capacity[v]. A list that
// outgrows its room moves to the pool's end with twice the room (the pool doubles when full),
// so a PM's millions of splits allocate nothing per split and leave nothing to collect.
export class FaceLists {
  constructor(vertices, faceCorners) {
    this.start = new Int32Array(vertices);
    this.count = new Int32Array(vertices);
    this.capacity = new Int32Array(vertices);
    this.pool = new Int32Array(Math.max(64, 2 * faceCorners));
    this.end = 0;
  }

  // Room for `need` faces at v (keeping its faces).
  reserve(v, need) {
    if (this.capacity[v] >= need) return;
    const room = Math.max(need, 2 * this.capacity[v], 8);
    if (this.end + room > this.pool.length) {
      const grown = new Int32Array(Math.max(2 * this.pool.length, this.end + room));
      grown.set(this.pool.subarray(0, this.end));
      this.pool = grown;
    }
    if (this.count[v]) this.pool.copyWithin(this.end, this.start[v], this.start[v] + this.count[v]);
    this.start[v] = this.end;
    this.capacity[v] = room;
    this.end += room;
  }

  push(v, f) {
    if (this.count[v] === this.capacity[v]) this.reserve(v, this.count[v] + 1);
    this.pool[this.start[v] + this.count[v]++] = f;
  }

  // v's faces become `faces[0 .. n)`.
  assign(v, faces, n) {
    this.count[v] = 0;
    this.reserve(v, n + 4);  // (a new vertex gains fl and fr at once, and more as its neighbours split)
    const pool = this.pool, s = this.start[v];
    for (let j = 0; j < n; j++) pool[s + j] = faces[j];
    this.count[v] = n;
  }

  // Keeps the faces of v whose `drop` mark is 0 (marks indexed by position in v's list), in order.
  compact(v, drop) {
    const pool = this.pool, s = this.start[v], n = this.count[v];
    let kept = 0;
    for (let j = 0; j < n; j++) if (!drop[j]) pool[s + kept++] = pool[s + j];
    this.count[v] = kept;
  }

  // Drops the faces numbered `first` and above from v's list, in order.
  dropFrom(v, first) {
    const pool = this.pool, s = this.start[v], n = this.count[v];
    let kept = 0;
    for (let j = 0; j < n; j++) if (pool[s + j] < first) pool[s + kept++] = pool[s + j];
    this.count[v] = kept;
  }
}
