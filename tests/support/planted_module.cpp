// A library planted where artcal must never load its URDF module from (tests/cli/
// test_urdf_module_loading.cpp): loaded, its constructor writes the file named by
// $ARTCAL_PLANTED_MARKER (it does nothing else, and has no artcal_urdf_module entry point).
#include <cstdio>
#include <cstdlib>

namespace {

__attribute__((constructor)) void markLoaded() {
  if (const char* marker = std::getenv("ARTCAL_PLANTED_MARKER"); marker && *marker) {
    if (std::FILE* file = std::fopen(marker, "a")) {
      std::fputs("loaded\n", file);
      std::fclose(file);
    }
  }
}

}  // namespace
