/**
 * @file contacts.h
 * @brief Contacts measured from the fields (capability 2;
 *        docs/model.md, "Contacts"): each cell's diffuse surface
 *        S_k = int |grad c_k| dV, each pair's contact
 *        A_kl = int min(|grad c_k|, |grad c_l|) dV (the interface density
 *        the two share), and from them contacts.csv and
 *        the contact graph picture. One code for 2D (lengths) and 3D
 *        (areas): the dimension is the mesh's, the quadrature q1.h's.
 *
 * Under MPI each rank integrates the elements it assembles (those whose
 * first node it owns, the solver's rule) and one reduction sums them
 * (sp_contacts_reduce), so every rank ends with the one-process values to
 * round-off.
 */
#ifndef SP_CONTACTS_H
#define SP_CONTACTS_H

#include <mpi.h>
#include <stdio.h>

#include "public/cell_obs.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The contacts of a state. Pair (k, l), k < l, is entry
 *  sp_contacts_pair(n_cells, k, l) of @c overlap. */
typedef struct {
  int n_cells;
  double *surface; /**< n_cells: S_k = int |grad c_k| dV */
  double *overlap; /**< n_cells (n_cells - 1) / 2: A_kl = int min(|grad c_k|, |grad c_l|) dV */
  int cap;         /**< cells the arrays hold */
} sp_contacts;

/** Index of the pair k < l among the n cells' pairs (row-major upper
 *  triangle). */
static inline size_t sp_contacts_pair(int n, int k, int l) {
  return (size_t)k * (size_t)(2 * n - k - 1) / 2 + (size_t)(l - k - 1);
}

/**
 * @brief Integrate S_k and A_kl over the elements whose first node is in
 *        [@p first_node, @p end_node) (0, n_nodes: the whole mesh), on the
 *        elements where both cells live (the layout's slot table: a pair
 *        contributes only where both have support).
 * @param[in,out] out resized to the layout's cells and overwritten
 */
int sp_contacts_integrate(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                          int first_node, int end_node, sp_contacts *out);

/** @brief Sum every rank's partial sums (one MPI_Allreduce on @p comm).
 *         Collective; agree on errors first (agree.h). */
int sp_contacts_reduce(MPI_Comm comm, sp_contacts *c);

/** @brief 1 if cells k and l are in contact: A_kl >= @p threshold x
 *         min(S_k, S_l) and A_kl > 0 (docs/model.md, "Contacts"). */
int sp_contacts_touch(const sp_contacts *c, int k, int l, double threshold);

/** @brief Cell k's contact (the sum of A_kl over the cells l it is in
 *         contact with) and its free surface S_k - that sum. */
void sp_contacts_of_cell(const sp_contacts *c, int k, double threshold, double *contact,
                         double *free_surface);

/** @brief Free the arrays (the struct is left empty, reusable). */
void sp_contacts_clear(sp_contacts *c);

#ifdef __cplusplus
}
#endif
#endif
