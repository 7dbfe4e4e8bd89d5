/**
 * @file layout.h
 * @brief Where each cell's field lives: the (cell, node) pairs that carry
 *        unknowns. Every solver structure (DOF numbering, maps, graph) is
 *        derived from the layout, so restricting supports changes no solver
 *        code.
 *
 * Pairs are numbered node-major: the pairs of node i are
 * node_start[i] .. node_start[i+1]-1, sorted by cell. Each pair p carries
 * two unknowns, state[2p] = c and state[2p+1] = mu. A node partition into
 * contiguous node ranges therefore gives contiguous DOF ranges per rank.
 */
#ifndef SP_LAYOUT_H
#define SP_LAYOUT_H

#include <limits.h>

#ifdef __cplusplus
extern "C" {
#endif

/** The most (cell, node) pairs a layout may have: pairs, their 2 x pairs
 *  unknowns (state[2p + 1]) and the solver's global ids (Epetra's are
 *  32-bit ints) are all ints. */
#define SP_LAYOUT_MAX_PAIRS (INT_MAX / 2)

/** The most nonzeros the solver's matrix may have: its row offsets are
 *  ints in Epetra (per rank), serial SuperLU and SuperLU_DIST (global
 *  counts), and the serial backends gather every row on one process. */
#define SP_LAYOUT_MAX_NONZEROS ((long long)INT_MAX)

/** An upper bound of the Jacobian's nonzeros on a layout whose node i
 *  carries n_i cells: a cell lives on an element only if all four nodes
 *  carry it, so every cell coupled to (k, i) is at node i too; the c row of
 *  (k, i) has at most 9 x 2 entries (c_k and mu_k at i and its 8
 *  neighbours), the mu row at most 9 x (n_i + 1) (c_k, mu_k and the other
 *  cells' c): sum over nodes of 9 n_i (n_i + 3). Exact inside a full
 *  layout of a structured mesh; an overestimate at boundaries. */
static inline long long sp_nonzeros_bound(long long n_nodes, long long n_i) {
  return 9 * n_nodes * n_i * (n_i + 3);
}

typedef struct sp_layout {
  int n_nodes;
  int n_cells;
  int n_pairs;
  int *node_start; /**< n_nodes + 1 offsets into pair_cell */
  int *pair_cell;  /**< cell of each pair */
} sp_layout;

/** @brief Every cell supported on every node (the paper's method). */
int sp_layout_create_full(int n_nodes, int n_cells, sp_layout **out);

/**
 * @brief A layout from per-cell node masks: in_support[k * n_nodes + i] != 0
 *        when node i is in cell k's support.
 * @return SP_OK, or SP_ERR_MEMORY when the masks hold more than
 *         SP_LAYOUT_MAX_PAIRS pairs
 */
int sp_layout_create_from_masks(int n_nodes, int n_cells,
                                const unsigned char *in_support,
                                sp_layout **out);

/** @brief sp_nonzeros_bound summed over the layout's nodes. */
long long sp_layout_nonzeros_bound(const sp_layout *layout);

/** @brief The pair of (cell, node), or -1 if node is outside the support. */
int sp_layout_pair(const sp_layout *layout, int cell, int node);

/** @brief Copy values from one layout's state to another's by (cell, node);
 *         pairs absent from @p from get c = fill_c, mu = 0. */
void sp_layout_transfer(const sp_layout *from, const double *state_from,
                        const sp_layout *to, double *state_to, double fill_c);

void sp_layout_destroy(sp_layout **layout);

#ifdef __cplusplus
}
#endif
#endif
