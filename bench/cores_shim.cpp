// A preloaded library that tells the process it has FAKE_CORES cores (default 16), so that
// `--threads P` above this machine's cores is honoured: every job of a round is then alive at
// once, as on a machine with P cores, and the process's peak memory is the one such a machine
// sees (bench/scaling.sh with ALL_ALIVE=1). Time figures from such a run mean nothing.
//
//   LD_PRELOAD=build/bin/libparapm-cores.so FAKE_CORES=16 build/bin/parapm simplify ...
#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>

namespace {

int fake_cores() {
  const char* text = std::getenv("FAKE_CORES");
  const int n = text ? std::atoi(text) : 16;
  return n > 0 ? n : 16;
}

}  // namespace

extern "C" {

// glibc's, which libstdc++'s std::thread::hardware_concurrency calls.
int get_nprocs() { return fake_cores(); }
int get_nprocs_conf() { return fake_cores(); }

long sysconf(int name) {
  if (name == _SC_NPROCESSORS_ONLN || name == _SC_NPROCESSORS_CONF) return fake_cores();
  using Sysconf = long (*)(int);
  static const Sysconf real = reinterpret_cast<Sysconf>(dlsym(RTLD_NEXT, "sysconf"));
  return real(name);
}

}  // extern "C"
