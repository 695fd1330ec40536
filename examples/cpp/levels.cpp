// parapm-example-levels MESH OUT_DIR: builds MESH's Progressive Mesh (energy metric, base mesh
// at 2% of its faces, 4 subsets in parallel), checks that all its vertex splits give the mesh
// back, writes OUT_DIR/mesh.pm and OUT_DIR/lods.glb (levels at 50%, 10% and 2% of the faces).
#include <cstdio>
#include <filesystem>

#include <parapm/engine.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s MESH OUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path out = argv[2];
    std::filesystem::create_directories(out);
    const parapm::RepairedMesh input = parapm::repair_mesh(parapm::read_mesh(argv[1]));
    parapm::SimplifyOptions options;
    options.metric = "energy";
    options.target_ratio = 0.02;
    parapm::ParallelOptions parallel;
    parallel.subsets = 4;
    const parapm::ProgressiveMesh pm =
        parapm::build_progressive_mesh_parallel(input, options, parallel);
    const parapm::Mesh full = parapm::level_of_detail(pm, pm.splits.size());
    if (full.faces.size() != input.mesh.faces.size()) {
      std::fprintf(stderr, "the full level has %zu faces, the input %zu\n", full.faces.size(),
                   input.mesh.faces.size());
      return 1;
    }
    parapm::write_pm_file(pm, (out / "mesh.pm").string());
    const size_t faces = input.mesh.faces.size();
    std::vector<parapm::Mesh> meshes;
    std::vector<parapm::GltfLevel> chain;
    meshes.reserve(3);
    for (double ratio : {0.5, 0.1, 0.02}) {
      const size_t level = parapm::level_for_faces(pm, size_t(ratio * double(faces)));
      meshes.push_back(parapm::level_of_detail(pm, level));
      chain.push_back(
          {&meshes.back(), level, level < pm.splits.size() ? pm.splits[level].error : 0});
    }
    parapm::write_gltf(chain, (out / "lods.glb").string());
    std::printf("%zu faces -> base %zu faces + %zu vertex splits; levels of %zu, %zu, %zu faces\n",
                faces, pm.base.faces.size(), pm.splits.size(), meshes[0].faces.size(),
                meshes[1].faces.size(), meshes[2].faces.size());
    return 0;
  } catch (const parapm::Error& e) {
    std::fprintf(stderr, "parapm-example-levels: %s\n", e.what());
    return 2;
  }
}
