// ParaPM's engine for other programs (CMake: find_package(ParaPM) and link ParaPM::engine):
// read and repair a mesh, build its Progressive Mesh (Hoppe 96) in one thread or in parallel
// subsets, store and read .pm files (docs/PM-FORMAT.md), cut levels of detail, write them as
// OBJ, PLY or glTF. Everything throws parapm::Error (util/error.h, with an ErrorCode) on bad
// input; nothing here talks to the network.
//
// A PM from a mesh file, and two levels of it:
//
//   #include <parapm/engine.h>
//
//   const parapm::RepairedMesh input = parapm::repair_mesh(parapm::read_mesh("bunny.ply"));
//   parapm::SimplifyOptions options;
//   options.target_ratio = 0.02;   // base mesh: 2% of the input's faces
//   options.metric = "energy";     // or "quadric" (faster)
//   const parapm::ProgressiveMesh pm = parapm::build_progressive_mesh(input, options);
//   parapm::write_pm_file(pm, "bunny.pm");
//   const parapm::Mesh level = parapm::level_of_detail(pm, parapm::level_for_faces(pm, 5000));
//   parapm::write_mesh(level, "bunny-5k.ply");
//
// In parallel (p subsets on threads; the PM depends on p, not on the threads):
//
//   parapm::ParallelOptions parallel;
//   parallel.subsets = 8;
//   const parapm::ProgressiveMesh pm8 =
//       parapm::build_progressive_mesh_parallel(input, options, parallel);
//
// A chain of levels for engines that read glTF (MSFT_lod), finest first:
//
//   const parapm::Mesh fine = parapm::level_of_detail(pm, parapm::level_for_faces(pm, 20000));
//   const parapm::Mesh coarse = parapm::level_of_detail(pm, parapm::level_for_faces(pm, 2000));
//   parapm::write_gltf({{&fine, parapm::level_for_faces(pm, 20000), 0},
//                       {&coarse, parapm::level_for_faces(pm, 2000), 0}}, "lods.glb");
//
// Correctness is checkable: level_of_detail(pm, pm.splits.size()) is the repaired input, face
// for face (parapm check does it).
#pragma once

#include "io/gltf_writer.h"           // write_gltf, gltf_bytes: glTF 2.0 levels and chains
#include "io/mesh_io.h"               // read_mesh, write_mesh: OBJ, PLY, OFF, STL (.gz)
#include "mesh/mesh.h"                // Mesh: positions, faces, wedges of attributes
#include "mesh/repair.h"              // repair_mesh: what the builds need (manifold, no duplicates)
#include "parallel/parallel_build.h"  // build_progressive_mesh_parallel, ParallelOptions
#include "pm/levels.h"                // level_for_faces, level_for_error, level_of_detail
#include "pm/pm_file.h"               // read_pm_file, write_pm_file, PmReader (streams)
#include "pm/progressive_mesh.h"      // ProgressiveMesh: base mesh + vertex splits
#include "simplify/simplify.h"        // build_progressive_mesh, SimplifyOptions
#include "util/error.h"               // Error, ErrorCode
