/* This process's resident memory (resident.h). */
#include "base/resident.h"

#include <stdio.h>
#include <string.h>

int sp_resident_mb(double *now, double *peak) {
  double kb_now = 0.0, kb_peak = 0.0;
  int found = 0;
  FILE *f = fopen("/proc/self/status", "r");
  if (f) {
    char line[256];
    while (fgets(line, sizeof line, f)) {
      long kb;
      if (sscanf(line, "VmRSS: %ld kB", &kb) == 1) kb_now = (double)kb, found |= 1;
      else if (sscanf(line, "VmHWM: %ld kB", &kb) == 1) kb_peak = (double)kb, found |= 2;
    }
    fclose(f);
  }
  if (now) *now = kb_now / 1024.0;
  if (peak) *peak = kb_peak / 1024.0;
  return found == 3 ? 0 : -1;
}
