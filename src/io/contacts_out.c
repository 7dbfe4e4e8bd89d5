/* The contacts' outputs (contacts_out.h). */
#include "io/contacts_out.h"

#include <stdlib.h>

#include "public/error.h"
#include "io/output.h"
#include "io/render.h"

int sp_contacts_log_open(const char *dir, int resume_step, sp_contacts_log *log) {
  return sp_output_log_open(dir, "contacts.csv", SP_CONTACTS_HEADER, 0, resume_step, &log->f,
                            &log->path);
}

int sp_contacts_log_write(sp_contacts_log *log, int step, double t, const sp_contacts *c,
                          const sp_cell_obs *obs, double threshold) {
  const int n = c->n_cells;
  int printed = 0;
  for (int k = 0; k < n && printed >= 0; ++k) {
    double contact, free_surface;
    sp_contacts_of_cell(c, k, threshold, &contact, &free_surface);
    printed = fprintf(log->f, "%d,%.17g,%d,0,%.17g,%.17g,%.17g,%.17g\n", step, t, k + 1,
                      contact, obs[k].volume, c->surface[k], free_surface);
  }
  for (int k = 0; k < n && printed >= 0; ++k)
    for (int l = k + 1; l < n && printed >= 0; ++l)
      if (sp_contacts_touch(c, k, l, threshold))
        printed = fprintf(log->f, "%d,%.17g,%d,%d,%.17g,,,\n", step, t, k + 1, l + 1,
                          c->overlap[sp_contacts_pair(n, k, l)]);
  return sp_output_log_done(log->f, log->path, printed);
}

int sp_contacts_log_close(sp_contacts_log *log) {
  int rc = SP_OK;
  if (log->f && fclose(log->f) != 0)
    rc = sp_error_set(SP_ERR_IO, "cannot close '%s'", log->path);
  free(log->path);
  *log = (sp_contacts_log){0};
  return rc;
}

int sp_contacts_picture(const sp_contacts *c, const sp_mesh *mesh, const sp_cell_obs *obs,
                        double threshold, double t, int width_px, const char *path) {
  const int n = c->n_cells;
  const size_t pairs = (size_t)n * (size_t)(n > 0 ? n - 1 : 0) / 2;
  double *centre, *length;
  int *edge;
  const int dim = mesh->dim;
  SP_ALLOC(centre, (size_t)dim * n);
  int rc = SP_OK;
  length = malloc(sizeof(double) * (pairs ? pairs : 1));
  edge = malloc(sizeof(int) * 2 * (pairs ? pairs : 1));
  if (!length || !edge) rc = sp_error_set(SP_ERR_MEMORY, "out of memory for the contact graph");
  int n_edges = 0;
  for (int k = 0; k < n && rc == SP_OK; ++k) {
    for (int d = 0; d < dim; ++d) centre[dim * k + d] = obs[k].centre[d];
    for (int l = k + 1; l < n; ++l)
      if (sp_contacts_touch(c, k, l, threshold)) {
        edge[2 * n_edges] = k;
        edge[2 * n_edges + 1] = l;
        length[n_edges++] = c->overlap[sp_contacts_pair(n, k, l)];
      }
  }
  if (rc == SP_OK)
    rc = sp_render_contact_graph(mesh, n, centre, n_edges, edge, length, t, width_px, path);
  free(centre);
  free(length);
  free(edge);
  return rc;
}
