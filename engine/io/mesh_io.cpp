// The public entry points: load the bytes, inflate gzip, pick the format, dispatch; check a
// mesh, serialise it, compress it, write it.
#include "io/mesh_io.h"

#include <string>

#include "io/byte_input.h"
#include "io/byte_output.h"
#include "io/formats.h"
#include "io/read_context.h"
#include "util/error.h"

namespace parapm {

Mesh read_mesh(const std::string& path, ReadReport* report, const ReadLimits& limits,
               ChunkedLoops* loops) {
  const std::string bytes = io::read_file_bytes(path, limits.max_bytes, loops);
  return read_mesh_from_memory(bytes, path, report, limits, loops);
}

Mesh read_mesh_from_memory(const std::string& bytes, const std::string& name, ReadReport* report,
                           const ReadLimits& limits, ChunkedLoops* loops) {
  ReadReport local;
  ReadReport& r = report ? *report : local;
  r = ReadReport{};

  io::ReadContext ctx;
  ctx.name = name;
  ctx.limits = limits;
  ctx.report = &r;
  ctx.loops = loops;
  std::string inflated;
  MeshFormat format = format_from_name(name);
  if (io::is_gzip(bytes)) {
    ctx.gzip = r.gzip = true;
    inflated = io::gunzip(
        bytes, name, limits.max_bytes,
        [&](std::string_view start) {
          if (!start.empty()) io::check_mesh_start(ctx, format, start);
        },
        loops);
    ctx.bytes = inflated;
  } else {
    if (bytes.size() > limits.max_bytes)
      io::fail_limit(ctx, "the input has " + std::to_string(bytes.size()) +
                              " bytes, more than the limit of " + std::to_string(limits.max_bytes));
    ctx.bytes = bytes;
  }
  r.input_bytes = ctx.bytes.size();
  if (ctx.bytes.empty()) io::fail(ctx, r.gzip ? "decompresses to nothing" : "the file is empty");

  if (format == MeshFormat::kUnknown) format = io::detect_format(ctx.bytes);
  r.format = format;
  auto welded = [&r, loops](Mesh mesh) {
    r.welded_vertices = io::weld_coincident_vertices(mesh, loops);
    return mesh;
  };
  switch (format) {
    case MeshFormat::kObj:
      return welded(io::read_obj(ctx));
    case MeshFormat::kPly:
      return welded(io::read_ply(ctx));
    case MeshFormat::kOff:
      return welded(io::read_off(ctx));
    case MeshFormat::kStl:
      return io::read_stl(ctx);
    case MeshFormat::kUnknown:
      break;
  }
  io::fail(ctx,
           "neither the name nor the content tells the format (expected OBJ, PLY, OFF or STL)");
}

namespace io {

void check_writable(const Mesh& mesh) {
  const size_t nv = mesh.positions.size();
  auto bad = [](const std::string& what) { throw_invalid("cannot write the mesh: " + what); };
  if (nv >= kNoId) bad("too many vertices for 32-bit indices");
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (VertexId v : mesh.faces[f])
      if (v >= nv)
        bad("face " + std::to_string(f) + " has vertex " + std::to_string(v) + " but there are " +
            std::to_string(nv) + " vertices");
  if (!mesh.layout.any()) return;
  const size_t nw = mesh.wedge_vertex.size();
  if (mesh.wedge_values.size() != nw * size_t(mesh.layout.floats_per_wedge()))
    bad("wedge_values has " + std::to_string(mesh.wedge_values.size()) + " floats for " +
        std::to_string(nw) + " wedges of " + std::to_string(mesh.layout.floats_per_wedge()));
  if (mesh.face_wedges.size() != mesh.faces.size())
    bad("face_wedges has " + std::to_string(mesh.face_wedges.size()) + " entries for " +
        std::to_string(mesh.faces.size()) + " faces");
  for (size_t w = 0; w < nw; ++w)
    if (mesh.wedge_vertex[w] >= nv)
      bad("wedge " + std::to_string(w) + " belongs to vertex " +
          std::to_string(mesh.wedge_vertex[w]) + " but there are " + std::to_string(nv));
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const WedgeId w = mesh.face_wedges[f][k];
      if (w >= nw)
        bad("face " + std::to_string(f) + " has wedge " + std::to_string(w) + " but there are " +
            std::to_string(nw));
      if (mesh.wedge_vertex[w] != mesh.faces[f][k])
        bad("face " + std::to_string(f) + " corner " + std::to_string(k) + " is vertex " +
            std::to_string(mesh.faces[f][k]) + " but its wedge " + std::to_string(w) +
            " belongs to vertex " + std::to_string(mesh.wedge_vertex[w]));
    }
}

}  // namespace io

void write_mesh(const Mesh& mesh, const std::string& path, const WriteOptions& options) {
  const MeshFormat format = format_from_name(path);
  if (format != MeshFormat::kObj && format != MeshFormat::kPly)
    throw_invalid(path + ": can only write .obj or .ply (optionally .gz), not " +
                  format_name(format));
  io::check_writable(mesh);
  std::string bytes =
      format == MeshFormat::kObj ? io::write_obj(mesh) : io::write_ply(mesh, options.ascii);
  const bool gz = path.size() > 3 && (path.compare(path.size() - 3, 3, ".gz") == 0 ||
                                      path.compare(path.size() - 3, 3, ".GZ") == 0);
  if (gz) bytes = io::gzip_compress(bytes);
  io::write_file_bytes(path, bytes);
}

uint64_t binary_ply_size(const Mesh& mesh) {
  io::check_writable(mesh);
  return io::binary_ply_size(mesh);
}

}  // namespace parapm
