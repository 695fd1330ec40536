// The binary codec of the parallel build's messages; job_codec.h documents the layout.
//
// What the decoded state must look like, and why (the imports index arrays with its ids):
//  - QuadricPriority::import_local/global: vertices in range (ids+ below the bound).
//  - EnergyPriority::import_local: point faces and parked vertices in range, each face's
//    points in one run and each vertex's parked sample once (checked there: its chunks fill
//    one list each, guaranteed here by writing points under their faces). import_global
//    (the master, from a summary) checks the state's face and vertex lists, and relinks each
//    point under its face: a point must name a listed face or vertex (guaranteed here by
//    writing points under them), and point ids must be distinct (a repeated id links a point
//    to itself: an endless list).
//  - SharpCurves::import_local indexes per vertex with the state's vertices, its begin
//    arrays and listed indices (built here from counts, indices below the sample count); a
//    vertex listed as its own sharp neighbour makes SharpCurves::collapsed() modify the list
//    it iterates.
//  - ScalarAttributes::import_local sizes its wedges from the state's values: a job whose
//    module runs E_scalar needs the state of exactly its W wedges (0..W-1) with its layout's
//    floats, else the simplifier reads wedges past the end.
#include "parallel/job_codec.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <istream>
#include <sstream>

#include "pm/byte_io.h"
#include "simplify/scalar_attributes.h"
#include "util/error.h"
#include "util/view_buffer.h"

namespace parapm {
namespace {

constexpr uint8_t kVersion = 10;
constexpr char kJobMagic[4] = {'P', 'P', 'J', 'B'};
constexpr char kRecordsMagic[4] = {'P', 'P', 'C', 'R'};
constexpr char kSummaryMagic[4] = {'P', 'P', 'S', 'S'};
constexpr size_t kMaxStopReason = 4096;

// Mesh flags (job header).
constexpr uint8_t kPositionsAreFloat = 1, kNormals = 2, kTexcoords = 4, kColors = 8,
                  kCornerWedges = 16, kPositionsAsF32 = 32;
// Per-vertex flags. kGrouped: SubsetJob::copy_group follows, as a varint.
constexpr uint8_t kOwned = 1, kLocked = 2, kGrouped = 4;
// Record flags.
constexpr uint8_t kRecordPositionsAsF32 = 1;
// Energy state flags.
constexpr uint8_t kResiduals = 1;
constexpr uint8_t kPositions = 2;   // EnergyState::positions
constexpr uint8_t kPointsF32 = 4;   // every point's position is exactly a float (an input vertex's)
constexpr uint8_t kSamplesF32 = 8;  // every curve sample's position is exactly a float

// The fewest bytes an element can take, for ByteReader::check_fits: a count that cannot fit
// in what remains is refused before anything is reserved.
constexpr uint64_t kMinVertexBytes = 12 + 1 + 1;   // f32 position, flags, global id
constexpr uint64_t kMinFaceBytes = 3 + 1;          // corners, global id
constexpr uint64_t kMinWedgeBytes = 1 + 1;         // its vertex, global id
constexpr uint64_t kMinKeyBytes = 1 + 1 + 8;       // a's gap, b's span, cost
constexpr uint64_t kMinDeferredBytes = 1 + 1 + 4;  // a's gap, b's span, key
// A record: flags, vs vt, fl fr, 3 f32, cost, error, change count.
constexpr uint64_t kMinRecordBytes = 1 + 2 + 2 + 12 + 8 + 4 + 1;
constexpr uint64_t kMinSampleBytes = 1 + 24 + 8 + 1 + 1;  // id, position, distance, u, w
constexpr uint64_t kQuadricBytes = 11 * 8;

// ---- Reading from a view ----------------------------------------------------------------

struct ViewReader {
  ViewReader(std::string_view bytes, const char* name)
      : buffer(bytes), stream(&buffer), in(stream, name) {}
  ViewBuffer buffer;
  std::istream stream;
  ByteReader in;
};

void read_magic(ByteReader& in, const char (&magic)[4], const char* kind) {
  in.set_context("header");
  char got[4];
  in.bytes(got, 4);
  if (std::memcmp(got, magic, 4) != 0) in.fail_at(0, std::string("not a ") + kind + " message");
  const uint8_t version = in.u8();
  if (version != kVersion)
    in.fail_at(4, "version " + std::to_string(version) + ", expected " + std::to_string(kVersion));
}

void expect_end(ByteReader& in) {
  in.set_context("end");
  if (!in.at_end()) in.fail("trailing bytes after the message");
}

// A count, refused unless `limit` allows it and `min_bytes` per element can still follow.
uint64_t read_count(ByteReader& in, uint64_t min_bytes, const char* what,
                    uint64_t limit = kNoId - 1) {
  const uint64_t start = in.offset();
  const uint64_t n = in.varint64();
  in.check_fits(n, min_bytes, what);
  if (n > limit) in.fail_at(start, std::string("too many ") + what + ": " + std::to_string(n));
  return n;
}

// n strictly increasing ids below `bound` (<= kNoId, so never kNoId), as first id then gaps.
void read_increasing(ByteReader& in, uint64_t n, uint64_t bound, std::vector<uint32_t>& ids) {
  ids.clear();
  ids.reserve(n);
  uint64_t next = 0;  // the least id the next one may take
  for (uint64_t i = 0; i < n; ++i) {
    const uint64_t start = in.offset();
    const uint64_t gap = in.varint64();
    if (next >= bound || gap >= bound - next)
      in.fail_at(start,
                 "id " + std::to_string(i) + " out of range (" + std::to_string(bound) + ")");
    ids.push_back(uint32_t(next + gap));
    next = next + gap + 1;
  }
}

// An id below `bound`, or kNoId (written as id + 1, so that kNoId is 0).
uint32_t read_id_or_none(ByteReader& in, uint64_t bound, const char* what) {
  const uint64_t start = in.offset();
  const uint32_t id = in.varint32() - 1u;
  if (id != kNoId && id >= bound) in.fail_at(start, std::string(what) + " out of range");
  return id;
}

uint32_t read_id(ByteReader& in, uint64_t bound, const char* what) {
  const uint64_t start = in.offset();
  const uint32_t id = in.varint32();
  if (id >= bound)
    in.fail_at(start, std::string(what) + " " + std::to_string(id) + " out of range");
  return id;
}

constexpr uint64_t kAnyId = uint64_t(1) << 32;  // a bound no 32-bit id reaches

// An id written as its difference from the id written before it in the same list (zigzag
// varint): a face's corners and its neighbours' are near each other in the spatially ordered
// ids, so most take one byte.
void write_near(ByteWriter& out, uint32_t id, uint32_t& previous) {
  out.zigzag64(int64_t(id) - int64_t(previous));
  previous = id;
}

uint32_t read_near(ByteReader& in, uint64_t bound, uint32_t& previous, const char* what) {
  const uint64_t start = in.offset();
  const int64_t difference = in.zigzag64();
  // (Checked before adding: a hostile difference near 2^63 must not overflow.)
  if (difference < -int64_t(previous) || difference >= int64_t(bound) - int64_t(previous))
    in.fail_at(start, std::string(what) + ": " + std::to_string(previous) + " + " +
                          std::to_string(difference) + " out of range");
  previous = uint32_t(int64_t(previous) + difference);
  return previous;
}

Vec3 read_position(ByteReader& in, bool as_f32) {
  const uint64_t start = in.offset();
  Vec3 p;
  for (double& c : p) c = as_f32 ? double(in.f32()) : in.f64();
  for (double c : p)
    if (!std::isfinite(c)) in.fail_at(start, "position is not finite");
  return p;
}

double read_not_nan(ByteReader& in, const char* what) {
  const double x = in.f64();
  if (std::isnan(x)) in.fail(std::string(what) + " is NaN");
  return x;
}

std::string read_metric(ByteReader& in) {
  const uint64_t start = in.offset();
  switch (in.u8()) {
    case 0:
      return "";
    case 1:
      return "quadric";
    case 2:
      return "energy";
    default:
      in.fail_at(start, "unknown metric");
  }
}

// ---- Writing ----------------------------------------------------------------------------

[[noreturn]] void cannot_encode(const std::string& what) {
  throw_invalid("cannot encode: " + what);
}

std::string finish(ByteWriter& out, std::ostringstream& stream) {
  out.flush();
  return std::move(stream).str();
}

void write_increasing(ByteWriter& out, const std::vector<uint32_t>& ids, const char* what) {
  uint64_t next = 0;
  for (uint32_t id : ids) {
    if (id < next || id == kNoId) cannot_encode(std::string(what) + " ids are not increasing");
    out.varint(id - next);
    next = uint64_t(id) + 1;
  }
}

bool is_float(const Vec3& p) {
  for (double c : p)
    if (std::bit_cast<uint64_t>(round_to_float(c)) != std::bit_cast<uint64_t>(c)) return false;
  return true;
}

void write_position(ByteWriter& out, const Vec3& p, bool as_f32) {
  for (double c : p) as_f32 ? out.f32(float(c)) : out.f64(c);
}

uint8_t metric_code(const std::string& metric) {
  if (metric.empty()) return 0;
  if (metric == "quadric") return 1;
  if (metric == "energy") return 2;
  cannot_encode("unknown metric '" + metric + "'");
}

// ---- Metric state ------------------------------------------------------------------------

// The items of a job's state (the quadric's entries, the energy's points) that it writes as
// their ids alone (its worker holds the rest of them): their indices in the state's order,
// increasing; `next`, the first not yet passed.
struct HeldItems {
  const std::vector<uint32_t>& indices;
  size_t next = 0;
  // Whether item `index` (the items are visited in order) is held.
  bool take(size_t index) {
    if (next < indices.size() && indices[next] == index) {
      ++next;
      return true;
    }
    return false;
  }
};
const std::vector<uint32_t> kNoHeldItems;

// What a state's ids may reach: the job's local mesh, or (a summary, global ids) anything.
struct StateBounds {
  uint64_t vertices = kNoId;
  uint64_t faces = kNoId;
  uint64_t wedges = kNoId;
};

bool is_empty(const QuadricState& s) { return s.vertices.empty() && s.quadrics.empty(); }

bool is_empty(const EnergyState& s) {
  return s.faces.empty() && s.vertices.empty() && s.points.empty() && s.point_values.empty() &&
         s.sharp_begin.empty() && s.sharp_neighbors.empty() && s.listed_begin.empty() &&
         s.listed.empty() && s.samples.empty() && s.curve_samples_total == 0 && s.wedges.empty() &&
         s.wedge_values.empty() && s.wedge_class.empty();
}

void write_quadric(ByteWriter& out, const QuadricState& s,
                   const std::vector<uint32_t>& held_items) {
  if (s.vertices.size() != s.quadrics.size()) cannot_encode("quadric state sizes disagree");
  if (!held_items.empty() && held_items.back() >= s.quadrics.size())
    cannot_encode("held quadrics beyond the state's");
  out.varint(s.vertices.size());
  write_increasing(out, s.vertices, "quadric state vertex");
  HeldItems held{held_items};
  for (size_t i = 0; i < s.quadrics.size(); ++i) {
    if (held.take(i)) continue;  // its worker holds it
    const Quadric& q = s.quadrics[i];
    for (double x : {q.a00, q.a01, q.a02, q.a11, q.a12, q.a22, q.b0, q.b1, q.b2, q.c, q.weight})
      out.f64(x);
  }
}

// A held quadric is left at zero, for the caller to put back (put_back_held_quadrics).
void read_quadric(ByteReader& in, const StateBounds& bounds,
                  const std::vector<uint32_t>& held_items, QuadricState& s) {
  in.set_context("quadric state");
  const uint64_t n = read_count(in, held_items.empty() ? 1 + kQuadricBytes : 1, "quadric vertices");
  read_increasing(in, n, bounds.vertices, s.vertices);
  if (!held_items.empty() && held_items.back() >= n) in.fail("held quadrics beyond the state's");
  in.check_fits(n - held_items.size(), kQuadricBytes, "quadrics");  // (the held are fewer)
  s.quadrics.resize(n);
  HeldItems held{held_items};
  for (size_t i = 0; i < n; ++i) {
    if (held.take(i)) continue;
    Quadric& q = s.quadrics[i];
    for (double* x :
         {&q.a00, &q.a01, &q.a02, &q.a11, &q.a12, &q.a22, &q.b0, &q.b1, &q.b2, &q.c, &q.weight})
      *x = in.f64();
  }
}

// The floats per point and per wedge of an energy state (one number: both are the module's
// floats per wedge), or refuses a state that has two.
int energy_floats(const EnergyState& s) {
  size_t k = 0;
  if (!s.positions && !s.point_values.empty()) cannot_encode("energy state point values");
  if (s.positions && !s.points.empty()) {
    k = s.point_values.size() / s.points.size();
  } else if (!s.wedges.empty()) {
    k = s.wedge_values.size() / s.wedges.size();
  }
  if (k > size_t(ScalarAttributes::kMaxFloats) ||
      s.point_values.size() != (s.positions ? s.points.size() * k : 0) ||
      s.wedge_values.size() != s.wedges.size() * k || s.wedge_class.size() != s.wedges.size())
    cannot_encode("energy state attribute sizes disagree");
  return int(k);
}

void write_point(ByteWriter& out, const EnergyState& s, size_t i, int k, bool residuals,
                 bool as_f32, HeldItems& held, uint32_t& previous_id) {
  const EnergyState::Point& p = s.points[i];
  write_near(out, p.id, previous_id);
  if (s.positions && held.take(i)) return;  // its worker holds the rest
  if (s.positions) write_position(out, p.position, as_f32);
  out.f64(p.distance_sq);
  if (residuals) out.f64(p.residual);
  if (s.positions)
    for (int j = 0; j < k; ++j) out.f32(s.point_values[i * size_t(k) + size_t(j)]);
}

// Each vertex's span of a begin array (size vertices + 1, from 0 to the list's end).
void check_spans(const std::vector<uint32_t>& begin, size_t vertices, size_t list,
                 const char* what) {
  if (begin.size() != vertices + 1 || begin.front() != 0 || begin.back() != list)
    cannot_encode(std::string("energy state ") + what + " spans disagree");
  for (size_t i = 0; i < vertices; ++i)
    if (begin[i] > begin[i + 1]) cannot_encode(std::string("energy state ") + what + " spans");
}

void write_energy(ByteWriter& out, const EnergyState& s, const std::vector<uint32_t>& held_points) {
  const int k = energy_floats(s);
  if (!held_points.empty() && (!s.positions || held_points.back() >= s.points.size()))
    cannot_encode("held points beyond the state's");
  bool residuals = false, points_f32 = s.positions, samples_f32 = s.positions;
  HeldItems scan{held_points};
  for (size_t i = 0; i < s.points.size(); ++i) {
    residuals |= std::bit_cast<uint64_t>(s.points[i].residual) != 0;
    points_f32 = points_f32 && (scan.take(i) || is_float(s.points[i].position));
  }
  HeldItems held{held_points};
  for (const EnergyState::CurveSample& c : s.samples)
    samples_f32 = samples_f32 && is_float(c.position);
  out.varint(s.faces.size());
  write_increasing(out, s.faces, "energy state face");
  out.varint(s.vertices.size());
  write_increasing(out, s.vertices, "energy state vertex");
  out.u8(uint8_t(k));
  out.u8(uint8_t((residuals ? kResiduals : 0) | (s.positions ? kPositions : 0) |
                 (points_f32 ? kPointsF32 : 0) | (samples_f32 ? kSamplesF32 : 0)));
  // Points in export order: each face's, then each vertex's parked one.
  size_t next = 0;
  uint32_t previous_id = 0;
  for (FaceId f : s.faces) {
    size_t end = next;
    while (end < s.points.size() && s.points[end].face == f && s.points[end].vertex == kNoId) ++end;
    out.varint(end - next);
    for (; next < end; ++next)
      write_point(out, s, next, k, residuals, points_f32, held, previous_id);
  }
  const size_t face_points = next;
  for (VertexId v : s.vertices)
    if (next < s.points.size() && s.points[next].face == kNoId && s.points[next].vertex == v)
      ++next;
  if (next != s.points.size()) cannot_encode("energy state points are not in export order");

  out.varint(s.samples.size());
  uint32_t previous_sample = 0;
  for (const EnergyState::CurveSample& c : s.samples) {
    if (c.u == kNoId) cannot_encode("energy state curve sample on no vertex");
    write_near(out, c.id, previous_sample);
    if (s.positions) write_position(out, c.position, samples_f32);
    out.f64(c.distance_sq);
    out.varint(c.u);
    out.varint(uint32_t(c.w + 1u));
  }
  check_spans(s.sharp_begin, s.vertices.size(), s.sharp_neighbors.size(), "sharp");
  check_spans(s.listed_begin, s.vertices.size(), s.listed.size(), "listed");
  next = face_points;
  for (size_t i = 0; i < s.vertices.size(); ++i) {
    const bool parked = next < s.points.size() && s.points[next].vertex == s.vertices[i];
    out.u8(parked ? 1 : 0);
    if (parked) write_point(out, s, next++, k, residuals, points_f32, held, previous_id);
    out.varint(s.sharp_begin[i + 1] - s.sharp_begin[i]);
    for (uint32_t j = s.sharp_begin[i]; j < s.sharp_begin[i + 1]; ++j)
      out.varint(s.sharp_neighbors[j]);
    out.varint(s.listed_begin[i + 1] - s.listed_begin[i]);
    for (uint32_t j = s.listed_begin[i]; j < s.listed_begin[i + 1]; ++j) out.varint(s.listed[j]);
  }
  out.varint(s.curve_samples_total);

  out.varint(s.wedges.size());
  write_increasing(out, s.wedges, "energy state wedge");
  for (float x : s.wedge_values) out.f32(x);
  for (size_t i = 0; i < s.wedges.size(); ++i) {
    // The class's wedge is the first of the class in the list (ScalarAttributes).
    const auto first = s.wedges.begin();
    const auto it = std::lower_bound(first, first + ptrdiff_t(i) + 1, s.wedge_class[i]);
    if (it == first + ptrdiff_t(i) + 1 || *it != s.wedge_class[i])
      cannot_encode("energy state wedge class not among the earlier wedges");
    out.varint(uint64_t(i - size_t(it - first)));
  }
}

// A held point is its id alone: its position, distance, residual and values are left at zero
// (its worker fills them in).
void read_point(ByteReader& in, int k, bool residuals, bool as_f32, FaceId face, VertexId vertex,
                HeldItems& held, uint32_t& previous_id, EnergyState& s) {
  EnergyState::Point p;
  p.id = read_near(in, kAnyId, previous_id, "point id");
  p.face = face;
  p.vertex = vertex;
  if (s.positions && held.take(s.points.size())) {
    s.point_values.resize(s.point_values.size() + size_t(k), 0.0f);
    s.points.push_back(p);
    return;
  }
  if (s.positions) p.position = read_position(in, as_f32);
  p.distance_sq = in.f64();
  p.residual = residuals ? in.f64() : 0.0;
  if (s.positions)
    for (int j = 0; j < k; ++j) s.point_values.push_back(in.f32());
  s.points.push_back(p);
}

// A job's state carries positions (its held points are ids alone), a returned one does not
// (EnergyState::positions).
void read_energy(ByteReader& in, const StateBounds& bounds, bool positions,
                 const std::vector<uint32_t>& held_points, EnergyState& s) {
  HeldItems held{held_points};
  in.set_context("energy state");
  read_increasing(in, read_count(in, 2, "energy faces"), bounds.faces, s.faces);
  read_increasing(in, read_count(in, 4, "energy vertices"), bounds.vertices, s.vertices);
  const int k = in.u8();
  if (k > ScalarAttributes::kMaxFloats) in.fail("too many floats per point: " + std::to_string(k));
  const uint8_t flags = in.u8();
  if (flags & ~(kResiduals | kPositions | kPointsF32 | kSamplesF32))
    in.fail("unknown energy state flags");
  const bool residuals = flags & kResiduals;
  s.positions = flags & kPositions;
  if (s.positions != positions)
    in.fail(positions ? "a job's state without its points' positions"
                      : "a returned state with positions (they never change)");
  const bool points_f32 = flags & kPointsF32, samples_f32 = flags & kSamplesF32;
  if ((points_f32 || samples_f32) && !positions) in.fail("float positions flagged, none present");
  const uint64_t point_bytes =
      held_points.empty()
          ? 1 + 8 + (residuals ? 8 : 0) + (positions ? (points_f32 ? 12 : 24) + 4 * uint64_t(k) : 0)
          : 1;
  uint32_t previous_id = 0, previous_sample = 0;  // (near: in the order written)

  for (size_t i = 0; i < s.faces.size(); ++i) {
    in.set_context("energy face", i);
    const uint64_t n = read_count(in, point_bytes, "points");
    for (uint64_t j = 0; j < n; ++j)
      read_point(in, k, residuals, points_f32, s.faces[i], kNoId, held, previous_id, s);
  }
  in.set_context("curve samples");
  s.samples.resize(read_count(in,
                              kMinSampleBytes - (!positions    ? 24
                                                 : samples_f32 ? 12
                                                               : 0),
                              "curve samples"));
  for (EnergyState::CurveSample& c : s.samples) {
    c.id = read_near(in, kAnyId, previous_sample, "curve sample id");
    if (positions) c.position = read_position(in, samples_f32);
    c.distance_sq = in.f64();
    c.u = read_id(in, bounds.vertices, "curve sample vertex");
    c.w = read_id_or_none(in, bounds.vertices, "curve sample vertex");
  }
  s.sharp_begin.assign(1, 0);
  s.listed_begin.assign(1, 0);
  for (size_t i = 0; i < s.vertices.size(); ++i) {
    in.set_context("energy vertex", i);
    const VertexId v = s.vertices[i];
    const uint8_t parked = in.u8();
    if (parked > 1) in.fail("bad parked flag");
    if (parked) read_point(in, k, residuals, points_f32, kNoId, v, held, previous_id, s);
    const uint64_t sharp = read_count(in, 1, "sharp neighbours");
    for (uint64_t j = 0; j < sharp; ++j) {
      const VertexId x = read_id(in, bounds.vertices, "sharp neighbour");
      if (x == v) in.fail("a vertex is its own sharp neighbour");
      s.sharp_neighbors.push_back(x);
    }
    s.sharp_begin.push_back(uint32_t(s.sharp_neighbors.size()));
    const uint64_t listed = read_count(in, 1, "listed samples");
    for (uint64_t j = 0; j < listed; ++j)
      s.listed.push_back(read_id(in, s.samples.size(), "listed sample"));
    s.listed_begin.push_back(uint32_t(s.listed.size()));
  }
  in.set_context("energy state");
  s.curve_samples_total = in.varint64();
  if (held.next != held_points.size()) in.fail("held points beyond the state's");

  // Distinct point ids: the master links each point into its face's list by id.
  std::vector<uint32_t> ids(s.points.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = s.points[i].id;
  std::sort(ids.begin(), ids.end());
  if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) in.fail("a point id is repeated");

  in.set_context("energy wedges");
  const uint64_t n = read_count(in, 2 + 4 * uint64_t(k), "energy wedges");
  read_increasing(in, n, bounds.wedges, s.wedges);
  s.wedge_values.resize(n * uint64_t(k));
  for (float& x : s.wedge_values) x = in.f32();
  s.wedge_class.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const uint64_t start = in.offset();
    const uint64_t back = in.varint64();
    if (back > i) in.fail_at(start, "wedge class before the first wedge");
    s.wedge_class[i] = s.wedges[i - back];
  }
}

void write_state(ByteWriter& out, const MetricState& s,
                 const std::vector<uint32_t>& held = kNoHeldItems) {
  const uint8_t code = metric_code(s.metric);
  out.u8(code);
  if ((code != 1 && !is_empty(s.quadric)) || (code != 2 && !is_empty(s.energy)))
    cannot_encode("a state holds another metric's part");
  if (code == 1) write_quadric(out, s.quadric, held);
  if (code == 2) write_energy(out, s.energy, held);
}

// A job's state (`job`), or a returned one: without positions, and never the quadric's
// (job_state.h, returns_state).
void read_state(ByteReader& in, const StateBounds& bounds, bool job, MetricState& s,
                const std::vector<uint32_t>& held = kNoHeldItems) {
  in.set_context("state");
  s = MetricState{};
  s.metric = read_metric(in);
  if (s.metric == "quadric" && !job) in.fail("a returned quadric state (quadric jobs return none)");
  if (s.metric.empty() && !held.empty()) in.fail("held items for a job without a state");
  if (s.metric == "quadric") read_quadric(in, bounds, held, s.quadric);
  if (s.metric == "energy") read_energy(in, bounds, job, held, s.energy);
}

// ---- Job --------------------------------------------------------------------------------

void write_options(ByteWriter& out, const SubsetOptions& o) {
  out.u8(metric_code(o.metric));
  out.f64(o.samples_per_face);
  out.f64(o.crease_angle_degrees);
  out.f64(o.attribute_weight);
  out.f64(o.energy.star_planes_weight);
  out.f64(o.energy.volume_weight);
  out.f64(o.energy.spring_scale);
  out.varint(o.energy.min_crease_edges);
  out.f64(o.energy.crease_min_length);
  out.u64(o.seed);
  out.f64(o.reference_diagonal);
  out.varint(o.target_faces);
  out.f64(o.max_cost);
  out.u8(o.defer_recosting ? 1 : 0);
  out.u8(o.free_placement ? 1 : 0);
}

void read_options(ByteReader& in, SubsetOptions& o) {
  in.set_context("options");
  o.metric = read_metric(in);
  if (o.metric.empty()) in.fail("a job needs a metric");
  o.samples_per_face = read_not_nan(in, "samples per face");
  o.crease_angle_degrees = read_not_nan(in, "crease angle");
  o.attribute_weight = read_not_nan(in, "attribute weight");
  o.energy.star_planes_weight = read_not_nan(in, "star planes' weight");
  o.energy.volume_weight = read_not_nan(in, "volume weight");
  o.energy.spring_scale = read_not_nan(in, "spring scale");
  const uint64_t crease_edges = in.varint64();
  if (crease_edges > UINT32_MAX) in.fail("the minimum crease edges overflow");
  o.energy.min_crease_edges = uint32_t(crease_edges);
  o.energy.crease_min_length = read_not_nan(in, "minimum crease length");
  o.seed = in.u64();
  o.reference_diagonal = in.f64();
  if (!(std::isfinite(o.reference_diagonal) && o.reference_diagonal >= 0))
    in.fail("the reference diagonal must be finite and >= 0");
  o.target_faces = in.varint64();
  o.max_cost = read_not_nan(in, "max cost");
  const uint8_t defer = in.u8();
  if (defer > 1) in.fail("the deferred re-costing flag must be 0 or 1");
  o.defer_recosting = defer == 1;
  const uint8_t free_placement = in.u8();
  if (free_placement > 1) in.fail("the free placement flag must be 0 or 1");
  o.free_placement = free_placement == 1;
}

// Whether the job's energy module will run E_scalar, so that its state must carry the
// wedges (as EnergyPriority::import_local decides: corner wedges, attributes, and a positive
// weight times the reference diagonal, or the job's own when there is none).
bool runs_scalar_attributes(const SubsetJob& job) {
  const Mesh& m = job.mesh;
  if (job.options.metric != "energy" || !m.layout.any() || m.face_wedges.empty()) return false;
  const double diagonal = job.options.reference_diagonal > 0 ? job.options.reference_diagonal
                                                             : bounding_box(m).diagonal();
  return job.options.attribute_weight * diagonal > 0;
}

// The state against the job: its metric, and the wedges E_scalar will index.
void check_job_state(ByteReader& in, const SubsetJob& job) {
  const MetricState& s = job.state;
  if (s.empty()) return;
  if (s.metric != job.options.metric) in.fail("the state's metric is not the job's");
  if (s.metric != "energy") return;
  const EnergyState& e = s.energy;
  if (e.wedges.empty() && e.point_values.empty()) {
    if (runs_scalar_attributes(job)) in.fail("the state lacks the wedges' attributes");
    return;
  }
  const size_t k = !e.points.empty() ? e.point_values.size() / e.points.size()
                                     : e.wedge_values.size() / e.wedges.size();
  // Strictly increasing ids below W, W of them: exactly 0..W-1.
  if (e.wedges.size() != job.mesh.wedge_count() || k != size_t(job.mesh.layout.floats_per_wedge()))
    in.fail("the state's wedges are not the job's");
}

// ---- Queue keys ---------------------------------------------------------------------------

// Sorted by (a, b), a < b: a as its gap from the previous edge's a, b as b - a - 1, then the
// edge's value (write_value). Queue keys (EdgeKey, cost f64) and deferred edges
// (DeferredEdge, key f32) alike.
template <typename Edge, typename WriteValue>
void write_edges(ByteWriter& out, const std::vector<Edge>& edges, const char* what,
                 WriteValue write_value) {
  out.varint(edges.size());
  VertexId previous_a = 0;
  for (size_t i = 0; i < edges.size(); ++i) {
    const Edge& k = edges[i];
    if (k.a >= k.b || k.b == kNoId || k.a < previous_a ||
        (i > 0 && k.a == previous_a && k.b <= edges[i - 1].b))
      cannot_encode(std::string(what) + " not sorted by (a, b) with a < b");
    out.varint(k.a - previous_a);
    out.varint(k.b - k.a - 1);
    write_value(k);
    previous_a = k.a;
  }
}

// Ids below `bound`; read_value(edge) reads the edge's value.
template <typename Edge, typename ReadValue>
void read_edges(ByteReader& in, uint64_t bound, uint64_t min_bytes, const char* what,
                std::vector<Edge>& edges, ReadValue read_value) {
  in.set_context(what);
  const uint64_t n = read_count(in, min_bytes, what);
  edges.resize(n);
  uint64_t previous_a = 0, previous_b = 0;
  for (uint64_t i = 0; i < n; ++i) {
    const uint64_t start = in.offset();
    // Each step checked before it is added, so that no sum wraps.
    const uint64_t gap = in.varint64();
    const uint64_t a = gap < bound - previous_a ? previous_a + gap : bound;
    const uint64_t span = in.varint64();
    if (a + 1 >= bound || span >= bound - a - 1)
      in.fail_at(start, std::string(what) + " " + std::to_string(i) + " out of range");
    const uint64_t b = a + 1 + span;
    if (i > 0 && a == previous_a && b <= previous_b)
      in.fail_at(start, std::string(what) + " not sorted");
    edges[i].a = VertexId(a);
    edges[i].b = VertexId(b);
    read_value(edges[i]);
    previous_a = a;
    previous_b = b;
  }
}

void write_keys(ByteWriter& out, const std::vector<EdgeKey>& keys) {
  write_edges(out, keys, "queue keys", [&](const EdgeKey& k) { out.f64(k.cost); });
}

// A cost may be NaN (the edge cannot be placed) or anything else: a key only orders the
// queue, the edge is costed again before it is collapsed.
void read_keys(ByteReader& in, uint64_t bound, std::vector<EdgeKey>& keys) {
  read_edges(in, bound, kMinKeyBytes, "queue keys", keys, [&](EdgeKey& k) { k.cost = in.f64(); });
}

void write_deferred(ByteWriter& out, const std::vector<DeferredEdge>& deferred) {
  write_edges(out, deferred, "deferred edges", [&](const DeferredEdge& d) { out.f32(d.key); });
}

// Any key: it only places the edge in the queue, and a NaN one is no key (the edge is costed
// at once).
void read_deferred(ByteReader& in, uint64_t bound, std::vector<DeferredEdge>& deferred) {
  read_edges(in, bound, kMinDeferredBytes, "deferred edges", deferred,
             [&](DeferredEdge& d) { d.key = in.f32(); });
}

void write_job(ByteWriter& out, const SubsetJob& job, const MetricState& state,
               const std::vector<uint32_t>& held) {
  const Mesh& m = job.mesh;
  const size_t floats = size_t(m.layout.floats_per_wedge());
  if (job.global_vertex.size() != m.vertex_count() || job.owned.size() != m.vertex_count() ||
      job.locked.size() != m.vertex_count() || job.global_face.size() != m.face_count() ||
      (!job.copy_group.empty() && job.copy_group.size() != m.vertex_count()) ||
      job.global_wedge.size() != m.wedge_count() ||
      m.wedge_values.size() != m.wedge_count() * floats ||
      (!m.face_wedges.empty() && m.face_wedges.size() != m.face_count()))
    cannot_encode("job sizes disagree");
  out.bytes(kJobMagic, 4);
  out.u8(kVersion);
  out.varint(job.round);
  out.varint(job.subset);
  out.varint(m.vertex_count());
  out.varint(m.face_count());
  out.varint(m.wedge_count());
  write_options(out, job.options);

  bool as_f32 = true;
  for (const Vec3& p : m.positions) as_f32 = as_f32 && is_float(p);
  out.u8(uint8_t((m.positions_are_float ? kPositionsAreFloat : 0) |
                 (m.layout.normals ? kNormals : 0) | (m.layout.texcoords ? kTexcoords : 0) |
                 (m.layout.colors ? kColors : 0) | (m.face_wedges.empty() ? 0 : kCornerWedges) |
                 (as_f32 ? kPositionsAsF32 : 0)));
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    if (job.owned[v] > 1 || job.locked[v] > 1) cannot_encode("owned or locked flags not 0/1");
    write_position(out, m.positions[v], as_f32);
    const uint32_t group = job.copy_group.empty() ? kNoId : job.copy_group[v];
    out.u8(uint8_t((job.owned[v] ? kOwned : 0) | (job.locked[v] ? kLocked : 0) |
                   (group != kNoId ? kGrouped : 0)));
    if (group != kNoId) out.varint(group);
  }
  write_increasing(out, job.global_vertex, "global vertex");
  uint32_t previous = 0;
  for (const Triangle& t : m.faces)
    for (VertexId v : t) write_near(out, v, previous);
  write_increasing(out, job.global_face, "global face");
  previous = 0;
  for (VertexId v : m.wedge_vertex) write_near(out, v, previous);
  for (float x : m.wedge_values) out.f32(x);
  previous = 0;
  for (const auto& w : m.face_wedges)
    for (WedgeId id : w) write_near(out, id, previous);
  write_increasing(out, job.global_wedge, "global wedge");
  out.varint(job.owned_faces);
  write_state(out, state, held);
  write_keys(out, job.keys);
  write_deferred(out, job.deferred);
}

void read_job(ByteReader& in, SubsetJob& job, const std::vector<uint32_t>& held) {
  read_magic(in, kJobMagic, "subset job");
  job.round = in.varint32();
  job.subset = in.varint32();
  in.set_context("sizes");
  // Counts first, each checked (and then together) against the bytes that follow.
  const uint64_t vertices = read_count(in, kMinVertexBytes, "vertices");
  const uint64_t faces = read_count(in, kMinFaceBytes, "faces");
  const uint64_t wedges = read_count(in, kMinWedgeBytes, "wedges");
  in.check_fits(1, vertices * kMinVertexBytes + faces * kMinFaceBytes + wedges * kMinWedgeBytes,
                "meshes of these sizes");
  read_options(in, job.options);

  in.set_context("mesh flags");
  Mesh& m = job.mesh;
  const uint8_t flags = in.u8();
  if (flags &
      ~(kPositionsAreFloat | kNormals | kTexcoords | kColors | kCornerWedges | kPositionsAsF32))
    in.fail("unknown mesh flags");
  m.positions_are_float = flags & kPositionsAreFloat;
  m.layout.normals = flags & kNormals;
  m.layout.texcoords = flags & kTexcoords;
  m.layout.colors = flags & kColors;
  const bool as_f32 = flags & kPositionsAsF32;
  const size_t floats = size_t(m.layout.floats_per_wedge());
  in.check_fits(wedges, kMinWedgeBytes + 4 * floats, "wedges with their values");

  m.positions.resize(vertices);
  job.owned.resize(vertices);
  job.locked.resize(vertices);
  for (size_t v = 0; v < vertices; ++v) {
    in.set_context("vertex", v);
    m.positions[v] = read_position(in, as_f32);
    const uint8_t f = in.u8();
    if (f & ~(kOwned | kLocked | kGrouped)) in.fail("unknown vertex flags");
    job.owned[v] = f & kOwned ? 1 : 0;
    job.locked[v] = f & kLocked ? 1 : 0;
    if (f & kGrouped) {
      if (job.copy_group.empty()) job.copy_group.assign(vertices, kNoId);
      job.copy_group[v] = in.varint32();
      if (job.copy_group[v] >= vertices) in.fail("copy group out of range");
    }
  }
  in.set_context("global vertex ids");
  read_increasing(in, vertices, kNoId, job.global_vertex);
  m.faces.resize(faces);
  uint32_t previous = 0;
  for (size_t f = 0; f < faces; ++f) {
    in.set_context("face", f);
    Triangle& t = m.faces[f];
    for (VertexId& v : t) v = read_near(in, vertices, previous, "corner");
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) in.fail("a corner is repeated");
  }
  in.set_context("global face ids");
  read_increasing(in, faces, kNoId, job.global_face);
  m.wedge_vertex.resize(wedges);
  previous = 0;
  for (size_t w = 0; w < wedges; ++w) {
    in.set_context("wedge", w);
    m.wedge_vertex[w] = read_near(in, vertices, previous, "wedge vertex");
  }
  in.set_context("wedge values");
  m.wedge_values.resize(wedges * floats);
  for (float& x : m.wedge_values) x = in.f32();
  if (flags & kCornerWedges) {
    m.face_wedges.resize(faces);
    previous = 0;
    for (size_t f = 0; f < faces; ++f) {
      in.set_context("corner wedges", f);
      for (int k = 0; k < 3; ++k) {
        const WedgeId w = m.face_wedges[f][k] = read_near(in, wedges, previous, "corner wedge");
        // The simplifier takes a corner's wedge to be its vertex's (repair.h rule 1).
        if (m.wedge_vertex[w] != m.faces[f][k]) in.fail("a corner's wedge is another vertex's");
      }
    }
  }
  in.set_context("global wedge ids");
  read_increasing(in, wedges, kNoId, job.global_wedge);
  in.set_context("owned faces");
  job.owned_faces = in.varint64();
  if (job.owned_faces > faces) in.fail("more owned faces than faces");

  read_state(in, StateBounds{vertices, faces, wedges}, /*job=*/true, job.state, held);
  in.set_context("state");
  check_job_state(in, job);
  read_keys(in, vertices, job.keys);
  read_deferred(in, vertices, job.deferred);
  expect_end(in);
}

// ---- Records ------------------------------------------------------------------------------

void write_record(ByteWriter& out, const CollapseRecord& r, size_t k) {
  if (r.changed_values.size() != r.changed_wedges.size() * k)
    cannot_encode("records with different floats per changed wedge");
  const bool as_f32 = is_float(r.position);
  out.u8(as_f32 ? kRecordPositionsAsF32 : 0);
  out.varint(r.vs);
  out.varint(r.vt);
  for (uint32_t id : {r.fl, r.fr}) out.varint(uint32_t(id + 1u));
  write_position(out, r.position, as_f32);
  out.f64(r.cost);
  out.f32(r.error);
  out.varint(r.changed_wedges.size());
  for (WedgeId w : r.changed_wedges) out.varint(w);
  for (float x : r.changed_values) out.f32(x);
}

void read_record(ByteReader& in, size_t k, CollapseRecord& r) {
  const uint8_t flags = in.u8();
  if (flags & ~kRecordPositionsAsF32) in.fail("unknown record flags");
  r.vs = read_id(in, kNoId, "vs");
  r.vt = read_id(in, kNoId, "vt");
  if (r.vs == r.vt) in.fail("vs and vt are one vertex");
  r.fl = read_id_or_none(in, kNoId, "fl");
  r.fr = read_id_or_none(in, kNoId, "fr");
  r.position = read_position(in, flags & kRecordPositionsAsF32);
  r.to_complete = true;  // the rest is the coordinator's mesh's (collapse_merge.h)
  r.cost = read_not_nan(in, "cost");
  r.error = in.f32();
  if (std::isnan(r.error)) in.fail("error is NaN");
  const uint64_t n = read_count(in, 1 + 4 * uint64_t(k), "changed wedges");
  r.changed_wedges.resize(n);
  for (WedgeId& w : r.changed_wedges) w = read_id(in, kNoId, "changed wedge");
  r.changed_values.resize(n * k);
  for (float& x : r.changed_values) x = in.f32();
}

// ---- Summary ------------------------------------------------------------------------------

void write_summary(ByteWriter& out, const SubsetResult& r) {
  out.bytes(kSummaryMagic, 4);
  out.u8(kVersion);
  out.varint(r.round);
  out.varint(r.subset);
  write_state(out, r.state);
  write_keys(out, r.keys);
  write_deferred(out, r.deferred);
  out.varint(r.keys_reused);
  out.varint(r.costings);
  out.varint(r.faces);
  out.varint(r.owned_faces);
  out.varint(r.free_vertices);
  const SimplifierStats& s = r.stats;
  for (uint64_t x : {s.collapses, s.rejected, s.stale, s.reevaluated, s.evaluations}) out.varint(x);
  if (s.stop_reason.size() > kMaxStopReason) cannot_encode("stop reason too long");
  out.varint(s.stop_reason.size());
  out.bytes(s.stop_reason.data(), s.stop_reason.size());
  out.f64(r.wall_seconds);
  out.f64(r.cpu_seconds);
  out.f64(r.team_saved_seconds);
  out.f64(r.team_cpu_seconds);
}

void read_summary(ByteReader& in, SubsetResult& r) {
  read_magic(in, kSummaryMagic, "subset summary");
  r.round = in.varint32();
  r.subset = in.varint32();
  read_state(in, StateBounds{}, /*job=*/false, r.state);
  read_keys(in, kNoId, r.keys);
  read_deferred(in, kNoId, r.deferred);
  in.set_context("counts");
  r.keys_reused = in.varint64();
  r.costings = in.varint64();
  r.faces = in.varint64();
  r.owned_faces = in.varint64();
  r.free_vertices = in.varint64();
  SimplifierStats& s = r.stats;
  for (uint64_t* x : {&s.collapses, &s.rejected, &s.stale, &s.reevaluated, &s.evaluations})
    *x = in.varint64();
  in.set_context("stop reason");
  s.stop_reason.resize(read_count(in, 1, "stop reason bytes", kMaxStopReason));
  in.bytes(s.stop_reason.data(), s.stop_reason.size());
  in.set_context("timings");
  r.wall_seconds = read_not_nan(in, "wall seconds");
  r.cpu_seconds = read_not_nan(in, "cpu seconds");
  r.team_saved_seconds = read_not_nan(in, "team saved seconds");
  r.team_cpu_seconds = read_not_nan(in, "team cpu seconds");
  expect_end(in);
}

}  // namespace

std::string encode_subset_job(const SubsetJob& job) {
  std::ostringstream stream;
  ByteWriter out(&stream);
  write_job(out, job, job.state, kNoHeldItems);
  return finish(out, stream);
}

std::string encode_subset_job(const SubsetJob& job, const MetricState& state,
                              const std::vector<uint32_t>& held_items) {
  if (std::adjacent_find(held_items.begin(), held_items.end(), std::greater_equal<>()) !=
      held_items.end())
    cannot_encode("held item indices not increasing");
  std::ostringstream stream;
  ByteWriter out(&stream);
  write_job(out, job, state, held_items);
  return finish(out, stream);
}

std::string encode_increasing_ids(const std::vector<uint32_t>& ids) {
  std::ostringstream stream;
  ByteWriter out(&stream);
  out.varint(ids.size());
  write_increasing(out, ids, "listed");
  return finish(out, stream);
}

std::vector<uint32_t> decode_increasing_ids(std::string_view bytes, uint64_t bound,
                                            const char* what) {
  ViewReader reader(bytes, what);
  ByteReader& in = reader.in;
  in.set_context("ids");
  const uint64_t n = read_count(in, 1, "ids");
  std::vector<uint32_t> ids;
  read_increasing(in, n, bound, ids);
  expect_end(in);
  return ids;
}

SubsetJob decode_subset_job(std::string_view bytes, const std::vector<uint32_t>& held_items) {
  if (std::adjacent_find(held_items.begin(), held_items.end(), std::greater_equal<>()) !=
      held_items.end())
    throw_invalid("subset job: held item indices not increasing");
  ViewReader reader(bytes, "subset job");
  SubsetJob job;
  read_job(reader.in, job, held_items);
  validate_subset_job(job);
  return job;
}

std::string encode_collapse_records(const CollapseRecord* records, size_t count) {
  // One floats-per-wedge for the batch: the first record with changes tells it.
  size_t k = 0;
  for (size_t i = 0; i < count; ++i)
    if (!records[i].changed_wedges.empty()) {
      k = records[i].changed_values.size() / records[i].changed_wedges.size();
      break;
    }
  if (k > size_t(ScalarAttributes::kMaxFloats)) cannot_encode("too many floats per wedge");
  std::ostringstream stream;
  ByteWriter out(&stream);
  out.bytes(kRecordsMagic, 4);
  out.u8(kVersion);
  out.varint(count);
  out.u8(uint8_t(k));
  for (size_t i = 0; i < count; ++i) write_record(out, records[i], k);
  return finish(out, stream);
}

void decode_collapse_records(std::string_view bytes, std::vector<CollapseRecord>& append_to) {
  const size_t before = append_to.size();
  try {
    ViewReader reader(bytes, "collapse records");
    ByteReader& in = reader.in;
    read_magic(in, kRecordsMagic, "collapse records");
    in.set_context("count");
    const uint64_t n = read_count(in, kMinRecordBytes, "records");
    const int k = in.u8();
    if (k > ScalarAttributes::kMaxFloats)
      in.fail("too many floats per wedge: " + std::to_string(k));
    append_to.reserve(before + n);
    for (uint64_t i = 0; i < n; ++i) {
      in.set_context("record", i);
      read_record(in, size_t(k), append_to.emplace_back());
    }
    expect_end(in);
  } catch (...) {
    append_to.resize(before);  // all of the batch or nothing
    throw;
  }
}

std::string encode_subset_summary(const SubsetResult& result) {
  std::ostringstream stream;
  ByteWriter out(&stream);
  write_summary(out, result);
  return finish(out, stream);
}

void decode_subset_summary(std::string_view bytes, SubsetResult& result) {
  ViewReader reader(bytes, "subset summary");
  SubsetResult decoded;
  read_summary(reader.in, decoded);
  decoded.records = std::move(result.records);
  result = std::move(decoded);
}

}  // namespace parapm
