/* A malloc for tests/mumps_workspace.sh, loaded with LD_PRELOAD: every
 * allocation (malloc, calloc, realloc, posix_memalign, aligned_alloc,
 * memalign) larger than SP_MALLOC_CAP bytes is refused (NULL or ENOMEM,
 * errno ENOMEM), as when a process runs out of memory; with
 * SP_MALLOC_REPORT set, the process writes the two largest sizes it asked
 * for at exit on stderr:
 *     malloc_cap: <comm> largest <N> next <M>
 * (<comm> the process's name: a one-process MPI run also starts orted).
 * glibc's __libc_* functions do the work. */
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

extern void *__libc_malloc(size_t n);
extern void *__libc_calloc(size_t n, size_t m);
extern void *__libc_realloc(void *p, size_t n);
extern void *__libc_memalign(size_t alignment, size_t n);

static size_t cap = (size_t)-1, largest, next;
static int ready;

/** 1 if an allocation of @p n bytes is refused; else records its size. */
static int refused(size_t n) {
  if (!ready) { /* (getenv does not allocate) */
    ready = 1;
    const char *c = getenv("SP_MALLOC_CAP");
    if (c && *c) cap = strtoull(c, NULL, 10);
  }
  if (n > cap) {
    errno = ENOMEM;
    return 1;
  }
  if (n > largest) {
    next = largest;
    largest = n;
  } else if (n > next && n < largest) {
    next = n;
  }
  return 0;
}

void *malloc(size_t n) { return refused(n) ? NULL : __libc_malloc(n); }
void *calloc(size_t n, size_t m) {
  return m && n > (size_t)-1 / m ? NULL : refused(n * m) ? NULL : __libc_calloc(n, m);
}
void *realloc(void *p, size_t n) { return refused(n) ? NULL : __libc_realloc(p, n); }
void *memalign(size_t a, size_t n) { return refused(n) ? NULL : __libc_memalign(a, n); }
void *aligned_alloc(size_t a, size_t n) { return memalign(a, n); }
int posix_memalign(void **p, size_t a, size_t n) {
  if (refused(n)) return ENOMEM;
  *p = __libc_memalign(a, n);
  return *p ? 0 : ENOMEM;
}

__attribute__((destructor)) static void report(void) {
  if (!getenv("SP_MALLOC_REPORT")) return;
  char comm[64] = "?";
  FILE *f = fopen("/proc/self/comm", "r");
  if (f) {
    if (fgets(comm, sizeof comm, f)) comm[strcspn(comm, "\n")] = 0;
    fclose(f);
  }
  fprintf(stderr, "malloc_cap: %s largest %zu next %zu\n", comm, largest, next);
}
