/**
 * @file wall_clock.h
 * @brief Seconds on a monotonic clock (the costs in energy.csv, checkpoint
 *        intervals, the progress line).
 */
#ifndef SP_WALL_CLOCK_H
#define SP_WALL_CLOCK_H

#include <time.h>

static inline double sp_wall_clock(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

#endif
