/* vtu_read.h: reading back the fields of a .vtu softpack wrote (initial.from). */
#ifndef SP_VTU_READ_H
#define SP_VTU_READ_H

#ifdef __cplusplus
extern "C" {
#endif

/** What sp_vtu_read finds in a softpack .vtu: the points (x, y, z; z = 0
 *  from a 2D mesh) and every cell's c and mu at them (cell-major:
 *  c[k n_points + i]). */
typedef struct {
  int n_points, n_cells;
  double *xyz, *c, *mu;
} sp_vtu_fields;

/** @brief Read a .vtu softpack wrote on one process (fields_<step>.vtu).
 *         SP_ERR_INPUT if it is not one. */
int sp_vtu_read(const char *path, sp_vtu_fields *out);
void sp_vtu_fields_free(sp_vtu_fields *v);

#ifdef __cplusplus
}
#endif
#endif
