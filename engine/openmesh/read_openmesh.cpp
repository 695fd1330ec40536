// read_openmesh (parapm/openmesh.h): OpenMesh's readers, then ParaPM's checks.
#include <OpenMesh/Core/IO/MeshIO.hh>

#include <parapm/openmesh.h>

namespace parapm::openmesh {

Mesh read_openmesh(const std::string& path) {
  TriMesh om;
  om.request_vertex_normals();
  om.request_vertex_colors();
  om.request_vertex_texcoords2D();
  om.request_halfedge_texcoords2D();
  OpenMesh::IO::Options options =
      OpenMesh::IO::Options::VertexNormal | OpenMesh::IO::Options::VertexColor |
      OpenMesh::IO::Options::VertexTexCoord | OpenMesh::IO::Options::FaceTexCoord |
      OpenMesh::IO::Options::ColorAlpha;
  if (!OpenMesh::IO::read_mesh(om, path, options))
    throw_invalid(path + ": OpenMesh cannot read it (not a mesh of a format OpenMesh knows)");
  // Keep only what the file had.
  if (!options.check(OpenMesh::IO::Options::VertexNormal)) om.release_vertex_normals();
  if (!options.check(OpenMesh::IO::Options::VertexColor)) om.release_vertex_colors();
  if (!options.check(OpenMesh::IO::Options::VertexTexCoord)) om.release_vertex_texcoords2D();
  if (!options.check(OpenMesh::IO::Options::FaceTexCoord)) om.release_halfedge_texcoords2D();
  Mesh mesh = from_openmesh(om);
  if (mesh.faces.empty()) throw_invalid(path + ": OpenMesh read no face");
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    for (double c : mesh.positions[v])
      if (!std::isfinite(c))
        throw_invalid(path + ": vertex " + std::to_string(v) +
                      " has a coordinate that is not finite");
  return mesh;
}

}  // namespace parapm::openmesh
