/**
 * @file resident.h
 * @brief This process's resident memory now and at its peak (Linux:
 *        VmRSS and VmHWM of /proc/self/status), for the run's memory line.
 */
#ifndef SP_RESIDENT_H
#define SP_RESIDENT_H

/** @brief The resident size and its peak so far, in MB (2^20 bytes);
 *         either pointer may be NULL.
 *  @return 0, or -1 where /proc/self/status says neither (both set to 0) */
int sp_resident_mb(double *now, double *peak);

#endif
