/**
 * @file contacts_out.h
 * @brief The contacts' outputs: contacts.csv and the contact graph picture
 *        (the measure itself: model/contacts.h; docs/model.md, "Contacts").
 */
#ifndef SP_CONTACTS_OUT_H
#define SP_CONTACTS_OUT_H

#include <stdio.h>

#include "model/contacts.h"

#ifdef __cplusplus
extern "C" {
#endif

/** contacts.csv, open on rank 0. */
typedef struct {
  FILE *f;
  char *path;
} sp_contacts_log;

/** contacts.csv's header: a cell row (other = 0) holds the cell's total
 *  contact, volume (c >= 1/2; an area in 2D), surface (its membrane, or
 *  its diffuse surface: contacts.h's measures) and free surface; a pair
 *  row (cell < other) its contact, the rest empty. */
#define SP_CONTACTS_HEADER "step,t,cell,other,contact,volume,surface,free_surface"

/** @brief Open @p dir/contacts.csv: new with its header (@p resume_step
 *         < 0), or cut back to the rows of steps <= @p resume_step and
 *         appended to (a restart). */
int sp_contacts_log_open(const char *dir, int resume_step, sp_contacts_log *log);

/** @brief Append the rows of one output: a row per cell (volume from
 *         @p obs, cells.csv's area), then a row per pair in contact. */
int sp_contacts_log_write(sp_contacts_log *log, int step, double t, const sp_contacts *c,
                          const sp_cell_obs *obs, double threshold);

/** @brief Close contacts.csv (a NULL file is fine). */
int sp_contacts_log_close(sp_contacts_log *log);

/** @brief The contact graph picture (in 3D seen as sp_render_surfaces sees the
 *         cells): the cells as nodes at
 *         their centres (@p obs), an edge per pair in contact, its width
 *         proportional to the contact (render.h's sp_render_contact_graph). */
int sp_contacts_picture(const sp_contacts *c, const sp_mesh *mesh, const sp_cell_obs *obs,
                        double threshold, double t, int width_px, const char *path);

#ifdef __cplusplus
}
#endif
#endif
