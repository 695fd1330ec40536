// What each vertex split refines, for view-dependent refinement (Hoppe 97's bounding spheres
// and deviations): for split i, a sphere (center, radius) holding, at their positions in the
// finest mesh decoded, vs and every vertex that descends from vs through splits i and after
// (vt = n0 + i, and theirs, recursively); and its reach, how far those vertices are from where
// split i finds vs (|vs before split i - center| + radius), in model units.
//
// Why the reach bounds what a skipped split hides: a selective refinement is the finest mesh
// with each vertex moved to its ancestor there (a geomorph at t = 0), so a point of a face moves
// by at most its corners' moves, and a vertex whose next split i is not applied stands where
// split i finds it (PmMesh.refineSelectively), within reach[i] of each of its descendants.
// Projected at the sphere's nearest depth, that is the screen-space error in pixels.
export class SplitRegions {
  // The regions of the decoder's splits decoded so far (splitCount of them).
  constructor(decoder) {
    const h = decoder.header, n0 = h.baseVertices, n = decoder.splitCount;
    this.splits = n;
    this.center = new Float64Array(3 * n);
    this.radius = new Float64Array(n);
    this.reach = new Float64Array(n);
    // Every vertex at its finest position (the base's, then each split's vsAfter and vtAfter),
    // and where each split finds its vs.
    const sphere = new Float64Array(4 * (n0 + n));  // per vertex: x, y, z, radius
    const before = new Float64Array(3 * n);
    const base = decoder.base.positions;
    for (let v = 0; v < n0; v++) for (let k = 0; k < 3; k++) sphere[4 * v + k] = base[3 * v + k];
    for (let i = 0; i < n; i++) {
      const vs = decoder.vs[i], vt = n0 + i;
      for (let k = 0; k < 3; k++) {
        before[3 * i + k] = sphere[4 * vs + k];
        sphere[4 * vs + k] = decoder.vsAfter[3 * i + k];
        sphere[4 * vt + k] = decoder.vtAfter[3 * i + k];
      }
    }
    // Finest split first: vs's sphere after split i and vt's merge into vs's before it.
    for (let i = n - 1; i >= 0; i--) {
      const s = 4 * decoder.vs[i];
      enclose(sphere, s, 4 * (n0 + i));
      const c = this.center, j = 3 * i;
      for (let k = 0; k < 3; k++) c[j + k] = sphere[s + k];
      this.radius[i] = sphere[s + 3];
      this.reach[i] = Math.hypot(before[j] - c[j], before[j + 1] - c[j + 1], before[j + 2] - c[j + 2]) + sphere[s + 3];
    }
  }
}

// Sphere a (at s[a .. a + 4)) becomes the smallest sphere holding spheres a and b.
function enclose(s, a, b) {
  const dx = s[b] - s[a], dy = s[b + 1] - s[a + 1], dz = s[b + 2] - s[a + 2];
  const d = Math.hypot(dx, dy, dz), ra = s[a + 3], rb = s[b + 3];
  if (d + rb <= ra) return;  // b inside a
  if (d + ra <= rb) {  // a inside b
    for (let k = 0; k < 4; k++) s[a + k] = s[b + k];
    return;
  }
  const r = (d + ra + rb) / 2, t = (r - ra) / d;
  s[a] += dx * t;
  s[a + 1] += dy * t;
  s[a + 2] += dz * t;
  s[a + 3] = r;
}
