/* This process's resident memory (resident.h). */
#include "base/resident.h"

#include <stdio.h>
#include <string.h>

int sp_resident_mb(double *now, double *peak) {
  *now = *peak = 0.0;
  FILE *f = fopen("/proc/self/status", "r");
  if (!f) return -1;
  char line[256];
  int found = 0;
  while (fgets(line, sizeof line, f)) {
    long kb;
    if (sscanf(line, "VmRSS: %ld kB", &kb) == 1) *now = kb / 1024.0, found |= 1;
    else if (sscanf(line, "VmHWM: %ld kB", &kb) == 1) *peak = kb / 1024.0, found |= 2;
  }
  fclose(f);
  return found == 3 ? 0 : -1;
}
