// parapm-example-openmesh IN OUT.om: reads IN with OpenMesh into an OpenMesh TriMesh, builds
// its Progressive Mesh through ParaPM's adapter (quadric, base mesh at 5%), and writes the
// level of a quarter of IN's faces back through OpenMesh as OUT.om.
#include <cstdio>

#include <parapm/engine.h>
#include <parapm/openmesh.h>
#include <OpenMesh/Core/IO/MeshIO.hh>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s IN OUT.om\n", argv[0]);
    return 2;
  }
  parapm::openmesh::TriMesh in;
  if (!OpenMesh::IO::read_mesh(in, argv[1])) {
    std::fprintf(stderr, "OpenMesh cannot read %s\n", argv[1]);
    return 2;
  }
  try {
    parapm::SimplifyOptions options;
    options.target_ratio = 0.05;
    const parapm::ProgressiveMesh pm = parapm::build_progressive_mesh(
        parapm::repair_mesh(parapm::openmesh::from_openmesh(in)), options);
    const auto out = parapm::openmesh::to_openmesh<parapm::openmesh::TriMesh>(
        parapm::level_of_detail(pm, parapm::level_for_faces(pm, in.n_faces() / 4)));
    if (!OpenMesh::IO::write_mesh(out, argv[2])) {
      std::fprintf(stderr, "OpenMesh cannot write %s\n", argv[2]);
      return 2;
    }
    std::printf("%zu faces -> a level of %zu faces in %s\n", size_t(in.n_faces()),
                size_t(out.n_faces()), argv[2]);
    return 0;
  } catch (const parapm::Error& e) {
    std::fprintf(stderr, "parapm-example-openmesh: %s\n", e.what());
    return 2;
  }
}
