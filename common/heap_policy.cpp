#include "common/heap_policy.hpp"

#include <malloc.h>

#include <cstdlib>
#include <cstring>
#include <initializer_list>

namespace stentsim::heap {

bool keep_large_blocks() {
  for (const char* v : {"MALLOC_MMAP_MAX_", "MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_"})
    if (std::getenv(v)) return false;
  if (const char* t = std::getenv("GLIBC_TUNABLES"); t && std::strstr(t, "glibc.malloc.")) return false;
  // mallopt returns 1 on success; -1 as the trim threshold disables trimming (mallopt(3)).
  return ::mallopt(M_MMAP_MAX, 0) == 1 && ::mallopt(M_TRIM_THRESHOLD, -1) == 1;
}

}  // namespace stentsim::heap
