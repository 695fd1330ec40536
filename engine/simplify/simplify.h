// The engine's entry point for building a Progressive Mesh in-process: repaired mesh in,
// PM out. The CLI, the tests and (later) the worker daemon all call this.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mesh/repair.h"
#include "pm/progressive_mesh.h"
#include "util/progress.h"

namespace parapm {

// The energy metric's weights and its rule for noise creases, as the build's options (the
// reasons for each default: EnergyOptions in energy_priority.h, SharpEdgeOptions in
// sharp_curves.h). They travel in the parallel build's jobs.
struct EnergyTuning {
  // The star's planes and volume preservation (Lindstrom-Turk's terms), against E_dist.
  double star_planes_weight = 30;
  double volume_weight = 64;
  // E_spring's kappa: Hoppe's schedule times this.
  double spring_scale = 0.03;
  // A crease of fewer edges than this and shorter than crease_min_length x the bounding-box
  // diagonal is a scan's noise, not a curve to keep (boundaries and seams always are).
  uint32_t min_crease_edges = 8;
  double crease_min_length = 0.05;
};

// The quadric's line between free and constrained placement (QuadricOptions::
// free_placement_above_faces): a fifth of the input's faces, and never under 2000 faces, where
// a level is coarse whatever the input (a small mesh is built constrained throughout).
constexpr double kFreePlacementAboveRatio = 0.2;
constexpr uint64_t kFreePlacementFloorFaces = 2000;
inline uint64_t free_placement_line(uint64_t input_faces) {
  return std::max<uint64_t>(uint64_t(kFreePlacementAboveRatio * double(input_faces)),
                            kFreePlacementFloorFaces);
}

// The quadric's placements a user chooses from (`parapm simplify --quadric-placement`, the
// service's JobOptions.quadric_placement), as SimplifyOptions::free_placement_above_faces takes
// them: "auto", unset (free above free_placement_line, constrained below); "constrained", never
// free (every level keeps its star's volume and border: the finest levels nearest the input,
// the build slower); "free", free at every level (the fastest build; coarse levels shrink and
// their borders drift). Throws InvalidInput for any other name.
std::optional<uint64_t> free_placement_above_faces_of(const std::string& placement);
// The names free_placement_above_faces_of takes, "auto" first (the default).
const std::vector<std::string>& quadric_placements();

struct SimplifyOptions {
  // Target size of the base mesh: target_faces when non-zero, else target_ratio of the input
  // faces when non-zero, else as far as collapses stay legal.
  uint64_t target_faces = 0;
  double target_ratio = 0;
  // "quadric": Garland-Heckbert quadrics, fast. "energy": Hoppe's mesh-optimisation energy,
  // points sampled on the input measured against the mesh (energy_priority.h).
  std::string metric = "quadric";
  // energy: extra points drawn by area, per face, beyond one per vertex: they see the surface
  // between the vertices, which the coarse collapses of a flat or sparsely sampled region cut
  // (docs/DECISIONS.md, "One extra point per face").
  double samples_per_face = 1;
  // energy: an edge whose faces' normals differ by more is a crease, kept as a curve (E_disc);
  // 180: none, the default (the star's planes keep creases: docs/DECISIONS.md, "No crease
  // curves by default")
  double crease_angle_degrees = 180;
  // energy: E_scalar's weight of attributes (colours, normals, texture coordinates) against
  // geometry: an attribute difference of 1 costs as much as this fraction of the bounding-box
  // diagonal in distance. 0: attributes are not optimised (each wedge keeps its input value).
  double attribute_weight = 0.01;
  EnergyTuning energy;      // energy: the terms' weights, the noise creases
  uint64_t seed = 1;        // of the randomised steps (the energy's extra points)
  bool keep_order = false;  // store the input's vertex and face order in the PM
  // The repair splits a non-manifold input vertex into copies, one per sheet meeting there.
  // false: the copies move and leave only together (locked_vertices, seam collapses:
  // copy_groups.h), so the sheets meet at every level but inside one seam collapse's records;
  // a copy in a part too small to shrink stays behind, and where the copies' collapses cannot
  // all be made (a mesh with many copies) they and their edges are what remains at coarse
  // levels (the simplification stops above the target). true: they simplify like any vertex,
  // and the sheets part at coarse levels (cracks, often far wider than the level's distance
  // error: pm/copy_separation.h measures them). Full resolution is exact either way.
  bool free_copies = false;
  // true: every connected component keeps at least a triangle (a closed one a tetrahedron) at
  // every level. false: an open component's last triangle collapses away when its turn comes
  // by cost, as small parts vanish at coarse levels (a vertex split brings the triangle back
  // from faceless vertices); the largest component, closed ones and those touching another
  // (a vertex at the same place) keep theirs.
  bool keep_components = false;
  // Re-costing deferred above a tenth of the input's faces (SimplifierLimits::
  // defer_above_faces; the energy only). Off: every edge around a collapse is costed at once
  // (for measuring what deferral saves; the PM differs a little).
  bool defer_recosting = true;
  // The quadric places at its free optimum while more faces than this are live
  // (QuadricOptions::free_placement_above_faces); unset: free_placement_line of the input's
  // faces. A parallel build's jobs get 0 or UINT64_MAX by their round.
  std::optional<uint64_t> free_placement_above_faces;
};

// The quadric's line for a build of `input_faces` faces: the options', else free_placement_line.
inline uint64_t free_placement_line_of(const SimplifyOptions& options, uint64_t input_faces) {
  return options.free_placement_above_faces.value_or(free_placement_line(input_faces));
}

struct SimplifyStats {
  uint64_t collapses = 0;
  uint64_t rejected = 0;
  std::string stop_reason;
  double seconds = 0;     // simplification and PM assembly, not reading or repair
  uint64_t costings = 0;  // edges the metric costed (PriorityModule::costings)
  // The calling thread's CPU over `seconds` (what the parallel build's cpu_seconds is compared
  // with: the wall time also counts waits for a busy machine).
  double cpu_seconds = 0;
};

// Throws Error(kInvalidInput) for unknown options, Error(kCancelled / kDeadlineExceeded) when
// `cancel` fires.
ProgressiveMesh build_progressive_mesh(const RepairedMesh& repaired, const SimplifyOptions& options,
                                       SimplifyStats* stats = nullptr,
                                       const ProgressCallback& progress = {},
                                       const CancelToken* cancel = nullptr);

uint64_t target_face_count(uint64_t input_faces, const SimplifyOptions& options);

// The steps of build_progressive_mesh that the parallel build (engine/parallel) shares.
// Throws Error(kInvalidInput) for an unknown metric or an option out of range.
void check_simplify_options(const SimplifyOptions& options);
void check_energy_tuning(const EnergyTuning& energy);
struct CopyGroups;
// Per vertex of repaired.mesh: 1 when the repair step made copies of its input vertex (such
// vertices move and leave only in seam collapses, copy_groups.h, so that the copies of one
// input vertex do not crack apart); all 0 with `free_copies` (SimplifyOptions::free_copies).
std::vector<uint8_t> locked_vertices(const RepairedMesh& repaired, bool free_copies = false);
// The same from the groups already found: per vertex of a mesh of `vertices` vertices, 1 for
// the members of `groups`.
std::vector<uint8_t> locked_vertices(const CopyGroups& groups, size_t vertices);
class PriorityModule;
// The priority module of options.metric for `mesh` (per vertex `locked`). reference_diagonal:
// the scale energy costs are measured against; 0 means mesh's own bounding-box diagonal (a
// subset job passes the whole mesh's, so that costs compare across subsets).
std::unique_ptr<PriorityModule> make_priority_module(const SimplifyOptions& options,
                                                     const Mesh& mesh,
                                                     const std::vector<uint8_t>& locked,
                                                     double reference_diagonal = 0);

}  // namespace parapm
