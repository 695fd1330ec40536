#include "io/gltf_writer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <nlohmann/json.hpp>

#include "io/byte_output.h"
#include "io/formats.h"
#include "util/error.h"

namespace parapm {
namespace {

using nlohmann::json;

// glTF's numbers for the kinds of data it holds.
constexpr int kFloat = 5126, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kTriangles = 4;

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The buffer every accessor points into, and the JSON describing its views and accessors.
class BufferBuilder {
 public:
  // A view of `values` (4-byte numbers) and an accessor over it; returns the accessor's index.
  template <typename T>
  int add(const std::vector<T>& values, int component_type, const char* type, int components,
          int target, bool with_bounds) {
    static_assert(sizeof(T) == 4);
    const size_t offset = bytes_.size();
    bytes_.resize(offset + values.size() * 4);
    std::memcpy(bytes_.data() + offset, values.data(), values.size() * 4);
    views_.push_back({{"buffer", 0},
                      {"byteOffset", offset},
                      {"byteLength", values.size() * 4},
                      {"target", target}});
    json accessor = {{"bufferView", views_.size() - 1},
                     {"componentType", component_type},
                     {"count", values.size() / size_t(components)},
                     {"type", type}};
    if (with_bounds) {
      std::vector<float> lo(size_t(components), std::numeric_limits<float>::infinity());
      std::vector<float> hi(size_t(components), -std::numeric_limits<float>::infinity());
      for (size_t i = 0; i < values.size(); ++i) {
        const size_t k = i % size_t(components);
        lo[k] = std::min(lo[k], float(values[i]));
        hi[k] = std::max(hi[k], float(values[i]));
      }
      accessor["min"] = lo;
      accessor["max"] = hi;
    }
    accessors_.push_back(std::move(accessor));
    return int(accessors_.size() - 1);
  }

  const std::string& bytes() const { return bytes_; }
  json views() const { return views_; }
  json accessors() const { return accessors_; }

 private:
  std::string bytes_;
  json views_ = json::array();
  json accessors_ = json::array();
};

// One level's primitive: its vertices (a glTF vertex per wedge, or per mesh vertex), their
// attributes as glTF wants them, and its indices.
json add_primitive(const Mesh& mesh, BufferBuilder& buffer) {
  const bool per_wedge = mesh.layout.any();
  const size_t count = per_wedge ? mesh.wedge_count() : mesh.vertex_count();
  std::vector<float> positions(3 * count);
  for (size_t v = 0; v < count; ++v) {
    const Vec3& p = mesh.positions[per_wedge ? mesh.wedge_vertex[v] : v];
    for (int k = 0; k < 3; ++k) positions[3 * v + size_t(k)] = float(p[size_t(k)]);
  }
  json attributes = {{"POSITION", buffer.add(positions, kFloat, "VEC3", 3, kArrayBuffer, true)}};
  const AttributeLayout& layout = mesh.layout;
  if (layout.normals) {
    std::vector<float> normals(3 * count);
    for (size_t w = 0; w < count; ++w) {
      const float* n = mesh.wedge(WedgeId(w)) + layout.normal_offset();
      const double length =
          std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
      const bool usable = std::isfinite(length) && length > 0;
      for (int k = 0; k < 3; ++k)
        normals[3 * w + size_t(k)] = usable ? float(n[k] / length) : (k == 2 ? 1.0f : 0.0f);
    }
    attributes["NORMAL"] = buffer.add(normals, kFloat, "VEC3", 3, kArrayBuffer, false);
  }
  if (layout.texcoords) {
    std::vector<float> uv(2 * count);
    for (size_t w = 0; w < count; ++w) {
      const float* t = mesh.wedge(WedgeId(w)) + layout.texcoord_offset();
      uv[2 * w] = t[0];
      uv[2 * w + 1] = 1.0f - t[1];
    }
    attributes["TEXCOORD_0"] = buffer.add(uv, kFloat, "VEC2", 2, kArrayBuffer, false);
  }
  if (layout.colors) {
    std::vector<float> rgba(4 * count);
    for (size_t w = 0; w < count; ++w) {
      const float* c = mesh.wedge(WedgeId(w)) + layout.color_offset();
      for (int k = 0; k < 4; ++k)
        rgba[4 * w + size_t(k)] = std::isfinite(c[k]) ? std::clamp(c[k], 0.0f, 1.0f) : 0.0f;
    }
    attributes["COLOR_0"] = buffer.add(rgba, kFloat, "VEC4", 4, kArrayBuffer, false);
  }
  std::vector<uint32_t> indices(3 * mesh.face_count());
  for (size_t f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      indices[3 * f + size_t(k)] =
          per_wedge ? mesh.face_wedges[f][size_t(k)] : mesh.faces[f][size_t(k)];
  const int index_accessor =
      buffer.add(indices, kUnsignedInt, "SCALAR", 1, kElementArrayBuffer, false);
  return {{"attributes", attributes}, {"indices", index_accessor}, {"mode", kTriangles}};
}

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t chunk = 0;
    for (size_t k = 0; k < 3; ++k) chunk = (chunk << 8) | (k < n ? uint8_t(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? digits[(chunk >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

void append_u32(std::string& out, uint32_t v) {
  for (int k = 0; k < 4; ++k) out += char((v >> (8 * k)) & 0xff);
}

// The binary container: a 12-byte header, the JSON chunk (padded with spaces), the BIN chunk
// (padded with zeros), every chunk 4-byte aligned.
std::string glb(std::string text, std::string bin) {
  while (text.size() % 4) text += ' ';
  while (bin.size() % 4) bin += '\0';
  std::string out;
  append_u32(out, 0x46546C67);  // "glTF"
  append_u32(out, 2);
  append_u32(out, uint32_t(12 + 8 + text.size() + 8 + bin.size()));
  append_u32(out, uint32_t(text.size()));
  append_u32(out, 0x4E4F534A);  // "JSON"
  out += text;
  append_u32(out, uint32_t(bin.size()));
  append_u32(out, 0x004E4942);  // "BIN\0"
  out += bin;
  return out;
}

}  // namespace

bool is_gltf_path(const std::string& path) {
  const std::string name = lower(path);
  return name.ends_with(".glb") || name.ends_with(".gltf");
}

std::string gltf_bytes(const std::vector<GltfLevel>& levels, bool binary) {
  if (levels.empty()) throw_invalid("glTF: no level to write");
  BufferBuilder buffer;
  json meshes = json::array(), nodes = json::array();
  for (size_t i = 0; i < levels.size(); ++i) {
    const Mesh& mesh = *levels[i].mesh;
    if (mesh.face_count() == 0) throw_invalid("glTF: level " + std::to_string(i) + " has no face");
    io::check_writable(mesh);
    meshes.push_back({{"primitives", json::array({add_primitive(mesh, buffer)})}});
    nodes.push_back({{"mesh", i},
                     {"extras",
                      {{"parapm",
                        {{"level", levels[i].level},
                         {"faces", mesh.face_count()},
                         {"error_bound", levels[i].error_bound}}}}}});
  }
  json gltf = {{"asset", {{"version", "2.0"}, {"generator", "ParaPM"}}},
               {"scene", 0},
               {"scenes", json::array({{{"nodes", json::array({0})}}})},
               {"nodes", nodes},
               {"meshes", meshes},
               {"accessors", buffer.accessors()},
               {"bufferViews", buffer.views()}};
  json the_buffer = {{"byteLength", buffer.bytes().size()}};
  if (!binary) the_buffer["uri"] = "data:application/octet-stream;base64," + base64(buffer.bytes());
  gltf["buffers"] = json::array({the_buffer});
  if (levels.size() > 1) {
    json coarser = json::array();
    for (size_t i = 1; i < levels.size(); ++i) coarser.push_back(i);
    gltf["nodes"][0]["extensions"] = {{"MSFT_lod", {{"ids", coarser}}}};
    gltf["extensionsUsed"] = json::array({"MSFT_lod"});
  }
  const std::string text = gltf.dump(binary ? -1 : 1);
  return binary ? glb(text, buffer.bytes()) : text + "\n";
}

void write_gltf(const std::vector<GltfLevel>& levels, const std::string& path) {
  const std::string name = lower(path);
  if (!is_gltf_path(name)) throw_invalid(path + ": a glTF file is named .glb or .gltf");
  io::write_file_bytes(path, gltf_bytes(levels, name.ends_with(".glb")));
}

}  // namespace parapm
