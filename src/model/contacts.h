/**
 * @file contacts.h
 * @brief Contacts measured from the fields (capability 2;
 *        docs/model.md, "Contacts"), by one of two measures:
 *        - isosurface (the default): each cell's membrane
 *          S_k = |{c_k = 1/2}| and each pair's contact
 *          A_kl = (|S_k and {c_l >= theta}| + |S_l and {c_k >= theta}|) / 2,
 *          the part of each membrane where the other cell's field reaches
 *          the level theta, on the piecewise linear interpolant of the
 *          fields on the elements' simplices (zero between cells whose
 *          membranes are further apart than d ln((1 - theta) / theta));
 *        - overlap: each cell's diffuse surface S_k = int |grad c_k| dV and
 *          each pair's A_kl = int min(|grad c_k|, |grad c_l|) dV (the
 *          interface density the two share), at the Gauss points of q1.h;
 *        and from them contacts.csv and the contact graph picture. One code
 *        for 2D (lengths) and 3D (areas): the dimension is the mesh's.
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

/** Which measure sp_contacts_integrate computes (output.contact_measure). */
typedef enum {
  SP_CONTACTS_ISOSURFACE = 0, /**< membranes |{c_k = 1/2}| and their parts
                                   where the other field is >= a level */
  SP_CONTACTS_OVERLAP = 1     /**< diffuse surfaces and their overlaps */
} sp_contacts_measure;

/** The contacts of a state. Pair (k, l), k < l, is entry
 *  sp_contacts_pair(n_cells, k, l) of @c overlap. */
typedef struct {
  int n_cells;
  double *surface; /**< n_cells: S_k, the membrane's or diffuse surface */
  double *overlap; /**< n_cells (n_cells - 1) / 2: A_kl */
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
 * @param[in] measure isosurface or overlap
 * @param[in] level the isosurface measure's theta, in (0, 1/2] (the
 *            overlap measure does not read it)
 * @param[in,out] out resized to the layout's cells and overwritten
 */
int sp_contacts_integrate(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                          int first_node, int end_node, sp_contacts_measure measure,
                          double level, sp_contacts *out);

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
