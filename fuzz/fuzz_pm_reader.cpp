// Any bytes as a .pm: read whole (with validation), and as a partial stream split by split as
// a viewer reads it. Every outcome must be a PM or a parapm::Error.
#include <cstddef>
#include <cstdint>
#include <istream>
#include <string_view>

#include "pm/pm_file.h"
#include "util/error.h"
#include "util/view_buffer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    parapm::ViewBuffer buffer(bytes);
    std::istream in(&buffer);
    parapm::read_pm(in, "fuzz.pm");
  } catch (const parapm::Error&) {
  }
  try {
    parapm::ViewBuffer buffer(bytes);
    std::istream in(&buffer);
    parapm::PmReader reader(in, "fuzz stream", parapm::PmReader::Input::kPartialStream);
    reader.read_base();
    parapm::PmSplitRecord record;
    while (reader.next_split(record)) {
    }
    reader.read_tail();
  } catch (const parapm::Error&) {
  }
  return 0;
}
