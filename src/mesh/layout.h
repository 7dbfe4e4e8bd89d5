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
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** The most (cell, node) pairs a layout may have: pairs, their 2 x pairs
 *  unknowns (state[2p + 1]) and the solver's global ids (the glue's are
 *  32-bit ints) are all ints. */
#define SP_LAYOUT_MAX_PAIRS (INT_MAX / 2)

/** The most nonzeros the solver's matrix may have: its row offsets are
 *  ints in the glue's CSR rows (per rank), serial SuperLU and SuperLU_DIST (global
 *  counts), and the serial backends gather every row on one process. */
#define SP_LAYOUT_MAX_NONZEROS ((long long)INT_MAX)

/** An upper bound of the Jacobian's nonzeros on a layout of a mesh of
 *  dimension @p dim whose node i carries n_i cells: a cell lives on an
 *  element only if all its nodes carry it, so every cell coupled to (k, i)
 *  is at node i too; with g = 3^dim (9 in 2D, 27 in 3D: node i and its
 *  neighbours on a structured mesh), the c row of (k, i) has at most g x 2
 *  entries (c_k and mu_k), the mu row at most g x (n_i + 1) (c_k, mu_k and
 *  the other cells' c): sum over nodes of g n_i (n_i + 3). Exact inside a
 *  full layout of a structured mesh; an overestimate at boundaries. */
static inline long long sp_nonzeros_bound(int dim, long long n_nodes, long long n_i) {
  return (dim == 3 ? 27 : 9) * n_nodes * n_i * (n_i + 3);
}

struct sp_mesh;

/** Tables derived from a layout (layout.c), built on first use, freed with it. */
typedef struct sp_layout_cache sp_layout_cache;

typedef struct sp_layout {
  int n_nodes;
  int n_cells;
  int n_pairs;
  int *node_start; /**< n_nodes + 1 offsets into pair_cell */
  int *pair_cell;  /**< cell of each pair */
  sp_layout_cache *cache; /**< derived tables (sp_layout_slots, sp_layout_cells) */
} sp_layout;

/**
 * The element-slot table of a layout on a mesh: the one place where the
 * rule "cell k lives on element e only if all the element's nodes carry k"
 * is applied (a field's domain is then a union of whole elements, with a
 * natural no-flux boundary). CSR by element: element e's slots are
 * elem_start[e] .. elem_start[e+1]-1, by increasing cell; slot s is cell
 * slot_cell[s] on the element, with the pair of its local node a at
 * slot_pair[nodes_per_elem s + a] (never -1); nodes_per_elem is the
 * mesh's (4 or 8). Offsets are 64-bit: slots x 8 can pass 2^31 where
 * pairs cannot.
 */
typedef struct sp_slots {
  int n_elems;
  int nodes_per_elem;  /**< the mesh's: 4 (quadrilaterals) or 8 (hexahedra) */
  int64_t n_slots;
  int64_t *elem_start; /**< n_elems + 1 */
  int *slot_cell;      /**< n_slots */
  int *slot_pair;      /**< nodes_per_elem n_slots */
} sp_slots;

/**
 * Each cell's pairs, cell-major (the transpose of the node-major numbering):
 * cell k's are cell_start[k] .. cell_start[k+1]-1, by increasing node, pair
 * cell_pair[j] at node cell_node[j]. Walks over one cell's support cost its
 * pairs, not the mesh's nodes.
 */
typedef struct sp_cell_pairs {
  int64_t *cell_start; /**< n_cells + 1 */
  int *cell_node;      /**< n_pairs */
  int *cell_pair;      /**< n_pairs */
} sp_cell_pairs;

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

/** @brief Bytes the layout holds: its pair numbering and the derived
 *  tables built so far (slot table, cell-major pairs). */
double sp_layout_bytes(const sp_layout *layout);

/** @brief sp_nonzeros_bound summed over the layout's nodes (a mesh of
 *         dimension @p dim). */
long long sp_layout_nonzeros_bound(const sp_layout *layout, int dim);

/**
 * @brief A layout from per-cell node lists: cell k's support is the nodes
 *        cell_node[cell_start[k] .. cell_start[k+1]-1] (no repeats, any
 *        order). O(pairs + nodes); the same layout as from the masks.
 * @return SP_OK, or SP_ERR_MEMORY as sp_layout_create_from_masks
 */
int sp_layout_create_from_lists(int n_nodes, int n_cells, const int64_t *cell_start,
                                const int *cell_node, sp_layout **out);

/** @brief @p layout with one more cell, n_cells, on @p parent's support
 *         (a division: the child starts where its parent is). O(pairs). */
int sp_layout_with_child(const sp_layout *layout, int parent, sp_layout **out);

/**
 * @brief The element-slot table of @p layout on @p mesh (sp_slots), built
 *        on the first call and kept with the layout (a new mesh rebuilds it).
 * @param[out] out borrowed: valid while the layout lives
 */
int sp_layout_slots(const sp_layout *layout, const struct sp_mesh *mesh,
                    const sp_slots **out);

/** @brief The cell-major pairs of @p layout (sp_cell_pairs), built on the
 *         first call and kept with it. @param[out] out borrowed */
int sp_layout_cells(const sp_layout *layout, const sp_cell_pairs **out);

/** @brief The pair of (cell, node), or -1 if node is outside the support. */
int sp_layout_pair(const sp_layout *layout, int cell, int node);

/** @brief The cell at @p node of @p state: the one (from 0) with the largest
 *         c > 1/2 there (ties keep the lower), or -1 where none has c > 1/2
 *         (the .vtu's cell_id minus 1; the pictures' name labels). */
int sp_layout_node_cell(const sp_layout *layout, const double *state, int node);

/** @brief Copy values from one layout's state to another's by (cell, node);
 *         pairs absent from @p from get c = fill_c, mu = 0. */
void sp_layout_transfer(const sp_layout *from, const double *state_from,
                        const sp_layout *to, double *state_to, double fill_c);

void sp_layout_destroy(sp_layout **layout);

#ifdef __cplusplus
}
#endif
#endif
