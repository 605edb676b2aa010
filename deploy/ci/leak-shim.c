// A deliberate leak, to check that the soak's memory check catches one (docs/RELIABILITY.md):
// preloaded into tubepick-server, it drops every LEAK_EVERY-th free() of a block of 1 MiB or more
// (default 100), so about one cloud-sized buffer in LEAK_EVERY stays resident.
//
//   cc -O2 -shared -fPIC -o /tmp/leak-shim.so deploy/ci/leak-shim.c -ldl
//   LD_PRELOAD=/tmp/leak-shim.so LEAK_EVERY=250 BUILD_DIR=build bash deploy/ci/soak.sh   # must FAIL
//
// Not built by CMake and not part of any test run.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <malloc.h>
#include <stdatomic.h>
#include <stdlib.h>

static void (*real_free)(void*);
static atomic_ulong large_frees;
static unsigned long every;

void free(void* p) {
  if (!real_free) real_free = (void (*)(void*))dlsym(RTLD_NEXT, "free");
  if (!every) {
    const char* e = getenv("LEAK_EVERY");
    every = e && strtoul(e, NULL, 10) > 0 ? strtoul(e, NULL, 10) : 100;
  }
  if (p && malloc_usable_size(p) >= (1u << 20) && atomic_fetch_add(&large_frees, 1) % every == every - 1) return;
  real_free(p);
}
