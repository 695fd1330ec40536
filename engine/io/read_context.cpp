#include "io/read_context.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include "util/error.h"

namespace parapm::io {

uint64_t ReadContext::max_vertices() const {
  return std::min<uint64_t>(limits.max_vertices, uint64_t(kNoId) - 1);
}
uint64_t ReadContext::max_faces() const {
  return std::min<uint64_t>(limits.max_faces, uint64_t(kNoId) - 1);
}

void fail(const ReadContext& ctx, const std::string& what) {
  throw_invalid(ctx.name + ": " + what);
}

void fail_at_line(const ReadContext& ctx, uint64_t line, const std::string& what) {
  throw_invalid(ctx.name + ": line " + std::to_string(line) + ": " + what);
}

void fail_at_byte(const ReadContext& ctx, uint64_t offset, const std::string& what) {
  throw_invalid(ctx.name + ": byte " + std::to_string(offset) +
                (ctx.gzip ? " (decompressed)" : "") + ": " + what);
}

void fail_limit(const ReadContext& ctx, const std::string& what) {
  throw Error(ErrorCode::kResourceExhausted, ctx.name + ": " + what);
}

void check_vertex_limit(const ReadContext& ctx, uint64_t count, const std::string& what) {
  if (count > ctx.max_vertices())
    fail_limit(
        ctx, what + ", more than the limit of " + std::to_string(ctx.max_vertices()) + " vertices");
}

void check_face_limit(const ReadContext& ctx, uint64_t count, const std::string& what) {
  if (count > ctx.max_faces())
    fail_limit(ctx,
               what + ", more than the limit of " + std::to_string(ctx.max_faces()) + " faces");
}

void note_ignored(const ReadContext& ctx, const std::string& what) {
  auto& ignored = ctx.report->ignored;
  if (std::find(ignored.begin(), ignored.end(), what) == ignored.end()) ignored.push_back(what);
}

std::string quote(std::string_view token) {
  constexpr size_t kMax = 40;
  std::string out = "'";
  for (size_t i = 0; i < token.size() && i < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += char(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  out += token.size() > kMax ? "...'" : "'";
  return out;
}

void finish_mesh(Mesh& mesh) { mesh.positions_are_float = all_positions_are_float(mesh.positions); }

void check_finite_position(const ReadContext& ctx, const Vec3& p, const std::string& what,
                           uint64_t line) {
  if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) return;
  auto text = [](double c) {
    std::ostringstream out;
    out << std::setprecision(17) << c;
    return out.str();
  };
  const std::string message = what + " has a non-finite coordinate (" + text(p[0]) + ", " +
                              text(p[1]) + ", " + text(p[2]) + ")";
  if (line > 0) fail_at_line(ctx, line, message);
  fail(ctx, message);
}

}  // namespace parapm::io
