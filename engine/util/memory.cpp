#include "util/memory.h"

#include <cstdio>
#include <cstring>

namespace parapm {
namespace {

uint64_t status_field_kb(const char* field) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0;
  char line[256];
  uint64_t kb = 0;
  const size_t n = std::strlen(field);
  while (std::fgets(line, sizeof line, f)) {
    if (std::strncmp(line, field, n) == 0) {
      std::sscanf(line + n, " %lu", &kb);
      break;
    }
  }
  std::fclose(f);
  return kb;
}

}  // namespace

uint64_t peak_memory_bytes() { return status_field_kb("VmHWM:") * 1024; }
uint64_t current_memory_bytes() { return status_field_kb("VmRSS:") * 1024; }

}  // namespace parapm
