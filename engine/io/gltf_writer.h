// glTF 2.0 files of levels of detail (Khronos glTF 2.0; MSFT_lod for a chain of levels).
//
// A level is one mesh with one triangle primitive: POSITION (float32), and its wedges'
// attributes where the mesh has them (NORMAL, TEXCOORD_0, COLOR_0 as float32), indexed by
// UNSIGNED_INT. glTF attributes are per vertex, so a mesh with attributes gets one glTF vertex
// per wedge (as the PLY writer does); one without, its own vertices. Values change only where
// glTF demands it: normals are scaled to unit length (a zero or non-finite normal becomes
// +Z), texture coordinates have v flipped (glTF's origin is the top-left corner, OBJ's and
// PLY's the bottom-left), colours are clamped to [0, 1], positions round to float32.
//
// Levels come finest first. One node per level; with more than one, the first node (the only
// one in the scene) carries MSFT_lod naming the others, coarser and coarser, as the extension
// orders them. Each level's node has extras {"parapm": {"level": vsplits applied, "faces",
// "error_bound": model units}}.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

struct GltfLevel {
  const Mesh* mesh = nullptr;
  size_t level = 0;        // vsplits applied to the base mesh
  double error_bound = 0;  // the PM's error bound of the level, model units
};

// The file's bytes: binary glTF (.glb) when `binary`, else JSON with the buffer embedded as a
// base64 data URI (one self-contained .gltf). Throws Error(kInvalidInput) for no level, a level
// without faces, or a mesh whose indices or wedges are inconsistent.
std::string gltf_bytes(const std::vector<GltfLevel>& levels, bool binary);

// Writes gltf_bytes to `path`: binary for ".glb", JSON for ".gltf" (kInvalidInput otherwise).
void write_gltf(const std::vector<GltfLevel>& levels, const std::string& path);

// True when `path` names a glTF file (".glb" or ".gltf", any case).
bool is_gltf_path(const std::string& path);

}  // namespace parapm
