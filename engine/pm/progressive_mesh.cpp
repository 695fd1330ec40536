// Counts derived from a Progressive Mesh, and validate_pm(): the invariant checker every
// untrusted PM (a .pm file, a stream) goes through before anything applies its splits, and
// that tests call on every PM they build. It replays the splits' bookkeeping (positions,
// wedge counts and values) without building any adjacency, in O(vertices + wedges + splits);
// whether each split's fan exists is checked by PmCursor when it is applied.
#include "pm/progressive_mesh.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "util/chunked_loops.h"
#include "util/error.h"

namespace parapm {

size_t ProgressiveMesh::full_face_count() const {
  size_t count = base.face_count();
  for (const VertexSplit& s : splits) count += size_t(s.new_faces());
  return count;
}

size_t ProgressiveMesh::full_wedge_count() const {
  size_t count = base.wedge_count();
  for (const VertexSplit& s : splits) count += s.new_wedge_count;
  return count;
}

namespace {

// Ids are uint32 with kNoId reserved: no PM may hold more elements than this.
constexpr uint64_t kMaxElements = uint64_t(kNoId) - 1;

std::string str(uint64_t value) { return std::to_string(value); }

[[noreturn]] void fail(const std::string& what) {
  throw_invalid("invalid progressive mesh: " + what);
}

bool is_float(double x) { return round_to_float(x) == x; }

// `describe` names the position in messages; it is called only on failure.
template <typename Describe>
void check_position(const Vec3& p, bool must_be_float, const Describe& describe) {
  for (double c : p) {
    if (!std::isfinite(c)) fail(describe() + " has a non-finite coordinate");
    if (must_be_float && !is_float(c))
      fail(describe() + " is not a float32 although the PM's positions are float32");
  }
}

bool same_bits(const Vec3& a, const Vec3& b) {
  for (int k = 0; k < 3; ++k)
    if (std::bit_cast<uint64_t>(a[k]) != std::bit_cast<uint64_t>(b[k])) return false;
  return true;
}

void validate_base(const Mesh& base) {
  const size_t n0 = base.vertex_count();
  if (n0 > kMaxElements || base.face_count() > kMaxElements || base.wedge_count() > kMaxElements)
    fail("base mesh too large for 32-bit ids");
  for (VertexId v = 0; v < n0; ++v)
    check_position(base.positions[v], base.positions_are_float,
                   [v] { return "base vertex " + str(v); });
  for (FaceId f = 0; f < base.face_count(); ++f) {
    const Triangle& t = base.faces[f];
    for (VertexId v : t)
      if (v >= n0) fail("base face " + str(f) + " names vertex " + str(v) + " of " + str(n0));
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
      fail("base face " + str(f) + " is degenerate (a vertex repeats)");
  }
  const size_t fpw = size_t(base.layout.floats_per_wedge());
  if (!base.layout.any()) {
    if (base.wedge_count() != 0 || !base.wedge_values.empty() || !base.face_wedges.empty())
      fail("base mesh has wedges but no attribute channel");
    return;
  }
  const size_t w0 = base.wedge_count();
  if (base.wedge_values.size() != w0 * fpw)
    fail("base mesh has " + str(base.wedge_values.size()) + " wedge values for " + str(w0) +
         " wedges of " + str(fpw) + " floats");
  if (base.face_wedges.size() != base.face_count())
    fail("base mesh has " + str(base.face_wedges.size()) + " face wedge triples for " +
         str(base.face_count()) + " faces");
  for (WedgeId w = 0; w < w0; ++w)
    if (base.wedge_vertex[w] >= n0)
      fail("base wedge " + str(w) + " belongs to vertex " + str(base.wedge_vertex[w]) + " of " +
           str(n0));
  for (FaceId f = 0; f < base.face_count(); ++f)
    for (WedgeId w : base.face_wedges[f])
      if (w >= w0) fail("base face " + str(f) + " names wedge " + str(w) + " of " + str(w0));
}

// The corner wedges of split i: present faces name wedges that exist after the split; the
// split's new wedges are first used in id order, each at least once (the .pm encoding names
// a new wedge as "the next new one").
void validate_corner_wedges(const VertexSplit& s, size_t i, bool attributes, uint64_t w_before) {
  const auto where = [i] { return "vsplit " + str(i); };  // messages only on failure
  const bool present[2] = {s.has_fl(), s.has_fr()};
  if (!attributes) {
    for (WedgeId w : s.corner_wedges)
      if (w != kNoId) fail(where() + " names a corner wedge but the PM has no attributes");
    if (s.new_wedge_count != 0 || s.wedge_changes_count != 0)
      fail(where() + " introduces or changes wedges but the PM has no attributes");
    return;
  }
  if (s.new_wedge_count > 6) fail(where() + " introduces more than 6 wedges");
  const uint64_t w_after = w_before + s.new_wedge_count;
  uint64_t next_new = w_before;
  for (int k = 0; k < 6; ++k) {
    const WedgeId w = s.corner_wedges[k];
    if (!present[k / 3]) {
      if (w != kNoId) fail(where() + ": corner " + str(k) + " of an absent face names a wedge");
      continue;
    }
    if (w >= w_after)
      fail(where() + ": corner " + str(k) + " names wedge " + str(w) + " but only " + str(w_after) +
           " exist after the split");
    if (w >= next_new) {
      if (w != next_new)
        fail(where() + ": new wedge " + str(w) + " is used before new wedge " + str(next_new));
      ++next_new;
    }
  }
  if (next_new != w_after)
    fail(where() + " introduces " + str(s.new_wedge_count) + " wedges but its corners use " +
         str(next_new - w_before));
}

void validate_copies_and_orders(const ProgressiveMesh& pm, const std::vector<Vec3>& full) {
  const size_t n = full.size();
  // Copies: distinct copies, no chains, the copy sits exactly where its original is.
  std::vector<uint8_t> is_copy(pm.vertex_copies.empty() ? 0 : n, 0);
  for (const auto& [copy, original] : pm.vertex_copies) {
    if (copy >= n || original >= n)
      fail("vertex copy (" + str(copy) + ", " + str(original) + ") out of range (" + str(n) +
           " vertices)");
    if (copy == original) fail("vertex " + str(copy) + " is listed as a copy of itself");
    if (is_copy[copy]) fail("vertex " + str(copy) + " is listed as a copy twice");
    is_copy[copy] = 1;
  }
  for (const auto& [copy, original] : pm.vertex_copies) {
    if (is_copy[original])
      fail("vertex " + str(copy) + " is a copy of " + str(original) + ", itself a copy");
    if (!same_bits(full[copy], full[original]))
      fail("vertex copy " + str(copy) + " is not at the position of its original " + str(original) +
           " at full resolution");
  }

  // Orders: an injective map into the input's indices (a permutation when the repair step
  // removed nothing); copies map to their original's index.
  if (!pm.input_vertex_order.empty()) {
    if (pm.input_vertex_order.size() != n)
      fail("input vertex order has " + str(pm.input_vertex_order.size()) + " entries for " +
           str(n) + " vertices");
    std::vector<uint32_t> values;
    values.reserve(n - pm.vertex_copies.size());
    for (VertexId v = 0; v < n; ++v) {
      const uint32_t in = pm.input_vertex_order[v];
      if (in >= pm.info.input_vertices)
        fail("input vertex order maps vertex " + str(v) + " to " + str(in) + " but the input had " +
             str(pm.info.input_vertices) + " vertices");
      if (is_copy.empty() || !is_copy[v]) values.push_back(in);
    }
    for (const auto& [copy, original] : pm.vertex_copies)
      if (pm.input_vertex_order[copy] != pm.input_vertex_order[original])
        fail("input vertex order maps copy " + str(copy) + " and its original " + str(original) +
             " to different input vertices");
    std::sort(values.begin(), values.end());
    const auto dup = std::adjacent_find(values.begin(), values.end());
    if (dup != values.end()) fail("input vertex order names input vertex " + str(*dup) + " twice");
  }
  if (!pm.input_face_order.empty()) {
    const size_t faces = pm.full_face_count();
    if (pm.input_face_order.size() != faces)
      fail("input face order has " + str(pm.input_face_order.size()) + " entries for " +
           str(faces) + " faces");
    std::vector<uint32_t> values(pm.input_face_order);
    for (FaceId f = 0; f < faces; ++f)
      if (values[f] >= pm.info.input_faces)
        fail("input face order maps face " + str(f) + " to " + str(values[f]) +
             " but the input had " + str(pm.info.input_faces) + " faces");
    std::sort(values.begin(), values.end());
    const auto dup = std::adjacent_find(values.begin(), values.end());
    if (dup != values.end()) fail("input face order names input face " + str(*dup) + " twice");
  }
}

// What the splits before split i added: the wedges and wedge changes its checks count from.
struct SplitsBefore {
  uint64_t wedges = 0;   // wedges present before the split, the base's included
  uint64_t changes = 0;  // wedge changes the splits before it own
};

// Split i's checks that need no replay of the splits before it: ids in range, errors, positions,
// corner wedges, where its wedge changes and new wedge values lie. Throws naming the violation.
void check_split_alone(const ProgressiveMesh& pm, size_t i, const SplitsBefore& before) {
  const Mesh& base = pm.base;
  const size_t fpw = size_t(base.layout.floats_per_wedge());
  const VertexSplit& s = pm.splits[i];
  // A function, not a string: messages are built only on failure (this runs per split).
  const auto where = [i] { return "vsplit " + str(i); };
  const uint64_t n = base.vertex_count() + i;  // vertices present before the split
  if (s.vs >= n) fail(where() + ": vs " + str(s.vs) + " out of range (" + str(n) + " vertices)");
  if (s.vl != kNoId && s.vl >= n)
    fail(where() + ": vl " + str(s.vl) + " out of range (" + str(n) + " vertices)");
  if (s.vr != kNoId && s.vr >= n)
    fail(where() + ": vr " + str(s.vr) + " out of range (" + str(n) + " vertices)");
  if (!s.has_fl() && !s.has_fr()) fail(where() + " has neither vl nor vr");
  if (s.vl == s.vr) fail(where() + ": vl and vr are both " + str(s.vl));
  if (s.vl == s.vs || s.vr == s.vs) fail(where() + ": vl or vr equals vs " + str(s.vs));
  if (!std::isfinite(s.error) || s.error < 0)
    fail(where() + ": error " + std::to_string(s.error) + " is not a finite non-negative number");
  if (i > 0 && s.error > pm.splits[i - 1].error)
    fail(where() + ": error " + std::to_string(s.error) + " exceeds the previous split's " +
         std::to_string(pm.splits[i - 1].error) + " (errors must not increase)");
  check_position(s.vs_before, base.positions_are_float, [&] { return where() + " vs_before"; });
  check_position(s.vs_after, base.positions_are_float, [&] { return where() + " vs_after"; });
  check_position(s.vt_after, base.positions_are_float, [&] { return where() + " vt_after"; });

  validate_corner_wedges(s, i, base.layout.any(), before.wedges);
  if (s.wedge_changes_begin != before.changes)
    fail(where() + ": its wedge changes begin at " + str(s.wedge_changes_begin) + ", expected " +
         str(before.changes) + " (changes are stored in split order)");
  if (uint64_t(s.wedge_changes_count) > pm.wedge_changes.size() - before.changes)
    fail(where() + ": wedge changes run past the end of the list");
  for (uint32_t c = 0; c < s.wedge_changes_count; ++c) {
    const WedgeChange& change = pm.wedge_changes[before.changes + c];
    if (change.wedge >= before.wedges)
      fail(where() + ": changes wedge " + str(change.wedge) + " but only " + str(before.wedges) +
           " existed before it");
    if (uint64_t(change.values_offset) + 2 * fpw > pm.wedge_change_values.size())
      fail(where() + ": wedge change values out of range");
  }
  const uint64_t wedges_after = before.wedges + s.new_wedge_count;
  if (wedges_after > kMaxElements) fail("too many wedges for 32-bit ids");
  if ((wedges_after - base.wedge_count()) * fpw > pm.new_wedge_values.size())
    fail(where() + ": new wedge values missing");
}

// The splits' bookkeeping replayed in order, one split at a time after its own checks passed
// (check_split_alone): every split's vs_before is where vs is at that level, every wedge change's
// coarse values are the wedge's values there, and no split changes a wedge twice. Ends with
// every vertex's full-resolution position.
class SplitReplay {
 public:
  explicit SplitReplay(const ProgressiveMesh& pm)
      : pm_(pm),
        fpw_(size_t(pm.base.layout.floats_per_wedge())),
        position_(pm.base.positions),
        // A wedge is read only once it exists: every wedge's value as created, up front.
        wedge_value_(pm.base.wedge_values),
        changed_in_(pm.base.wedge_count() + pm.new_wedge_values.size() / std::max<size_t>(fpw_, 1),
                    ~uint64_t(0)) {
    position_.reserve(pm.base.vertex_count() + pm.splits.size());
    wedge_value_.insert(wedge_value_.end(), pm.new_wedge_values.begin(), pm.new_wedge_values.end());
  }

  void step(size_t i) {
    const VertexSplit& s = pm_.splits[i];
    if (!same_bits(s.vs_before, position_[s.vs]))
      fail("vsplit " + str(i) + ": vs_before is not the position of vertex " + str(s.vs) +
           " at that level");
    position_[s.vs] = s.vs_after;
    position_.push_back(s.vt_after);
    for (uint32_t c = 0; c < s.wedge_changes_count; ++c) {
      const WedgeChange& change = pm_.wedge_changes[s.wedge_changes_begin + c];
      if (changed_in_[change.wedge] == i)
        fail("vsplit " + str(i) + " changes wedge " + str(change.wedge) + " twice");
      changed_in_[change.wedge] = i;
      const float* coarse = pm_.wedge_change_values.data() + change.values_offset;
      float* current = wedge_value_.data() + size_t(change.wedge) * fpw_;
      for (size_t k = 0; k < fpw_; ++k)
        if (std::bit_cast<uint32_t>(coarse[k]) != std::bit_cast<uint32_t>(current[k]))
          fail("vsplit " + str(i) + ": the coarse value of wedge " + str(change.wedge) +
               " is not its value at that level");
      std::copy(coarse + fpw_, coarse + 2 * fpw_, current);
    }
  }

  const std::vector<Vec3>& positions() const { return position_; }

 private:
  const ProgressiveMesh& pm_;
  size_t fpw_;
  std::vector<Vec3> position_;
  std::vector<float> wedge_value_;
  std::vector<uint64_t> changed_in_;  // per wedge: the split that last changed it
};

// The checks after the last split: the totals the splits add up to.
void check_totals(const ProgressiveMesh& pm, const SplitsBefore& all, uint64_t faces) {
  const size_t fpw = size_t(pm.base.layout.floats_per_wedge());
  const uint64_t base_wedges = pm.base.wedge_count();
  if (faces > kMaxElements) fail("too many faces for 32-bit ids");
  if (all.changes != pm.wedge_changes.size())
    fail("the splits own " + str(all.changes) + " wedge changes but the PM lists " +
         str(pm.wedge_changes.size()));
  if ((all.wedges - base_wedges) * fpw != pm.new_wedge_values.size())
    fail("the splits introduce " + str(all.wedges - base_wedges) + " wedges but the PM holds " +
         str(pm.new_wedge_values.size()) + " new wedge values");
}

void check_split_count(const ProgressiveMesh& pm) {
  if (pm.base.vertex_count() + pm.splits.size() > kMaxElements)
    fail("too many vertices for 32-bit ids");
}

}  // namespace

void validate_pm(const ProgressiveMesh& pm) {
  validate_base(pm.base);
  check_split_count(pm);
  SplitsBefore before{pm.base.wedge_count(), 0};
  uint64_t faces = pm.base.face_count();
  SplitReplay replay(pm);
  for (size_t i = 0; i < pm.splits.size(); ++i) {
    const VertexSplit& s = pm.splits[i];
    check_split_alone(pm, i, before);
    replay.step(i);
    before.wedges += s.new_wedge_count;
    before.changes += s.wedge_changes_count;
    faces += uint64_t(s.new_faces());
  }
  check_totals(pm, before, faces);
  validate_copies_and_orders(pm, replay.positions());
}

void validate_pm(const ProgressiveMesh& pm, ChunkedLoops& loops) {
  const size_t n = pm.splits.size();
  const size_t ranges = loops.ranges(n);
  if (ranges <= 1) return validate_pm(pm);
  validate_base(pm.base);
  check_split_count(pm);
  // Per range, what the splits before it added.
  std::vector<SplitsBefore> before(ranges + 1);
  std::vector<uint64_t> faces(ranges + 1, 0);
  loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
    SplitsBefore& added = before[range + 1];
    for (size_t i = begin; i < end; ++i) {
      added.wedges += pm.splits[i].new_wedge_count;
      added.changes += pm.splits[i].wedge_changes_count;
      faces[range + 1] += uint64_t(pm.splits[i].new_faces());
    }
  });
  before[0] = {pm.base.wedge_count(), 0};
  faces[0] = pm.base.face_count();
  for (size_t r = 0; r < ranges; ++r) {
    before[r + 1].wedges += before[r].wedges;
    before[r + 1].changes += before[r].changes;
    faces[r + 1] += faces[r];
  }
  try {
    loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
      SplitsBefore at = before[range];
      for (size_t i = begin; i < end; ++i) {
        check_split_alone(pm, i, at);
        at.wedges += pm.splits[i].new_wedge_count;
        at.changes += pm.splits[i].wedge_changes_count;
      }
    });
  } catch (const Error&) {
    validate_pm(pm);  // names the first violation in split order, as one thread does
    throw;
  }
  // Every split passed its own checks: the replay's first violation is the first of all.
  SplitReplay replay(pm);
  for (size_t i = 0; i < n; ++i) replay.step(i);
  check_totals(pm, before[ranges], faces[ranges]);
  validate_copies_and_orders(pm, replay.positions());
}

}  // namespace parapm
