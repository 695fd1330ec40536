// The viewer's page files (viewer/), embedded in the coordinator at build time
// (cmake/embed_files.cmake), so that the binary serves them wherever it runs.
#pragma once

#include <span>
#include <string_view>

namespace parapm::service {

struct ViewerAsset {
  std::string_view path;  // its name under /, e.g. "index.html"
  std::string_view content_type;
  std::string_view bytes;
};

std::span<const ViewerAsset> viewer_assets();

}  // namespace parapm::service
