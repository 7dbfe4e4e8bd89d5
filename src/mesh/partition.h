/**
 * @file partition.h
 * @brief The node partition of MPI runs: nodes renumbered in recursive
 *        coordinate bisection (RCB) order, and each rank given a contiguous
 *        range of that order holding an equal share of the unknowns.
 *
 * Why RCB and why this way (docs/parallel.md, "What is distributed"):
 * - the solvers want each rank's rows to be one contiguous block of the
 *   global numbering in rank order (SuperLU_DIST's NRformat_loc, Amesos);
 *   the layout numbers unknowns node-major, so contiguous node ranges give
 *   contiguous rows;
 * - the ellipse mesh numbers its nodes ring by ring, so contiguous ranges of
 *   that numbering are an inner disk and outer annuli: long interfaces (a
 *   whole ring per cut). In RCB order every range of the order is a compact
 *   piece of a k-d tree, and the first half of the nodes is one side of a
 *   straight cut across the long axis: the interface is one short line;
 * - the weights change every time the local supports do (unknowns per node
 *   = 2 x cells there), so the ranges are re-balanced along the fixed order
 *   at every layout, at O(nodes) cost, without moving the mesh;
 * - Zoltan's RCB (Debian's trilinos) would give the same cuts but owns its
 *   own numbering and needs a migration of node data after every support
 *   change; a hundred lines of C keep the numbering ours and the result
 *   identical on every rank and for every number of ranks.
 * The order is applied to the mesh of every run (one rank too), so a run's
 * numbering does not depend on the number of ranks.
 */
#ifndef SP_PARTITION_H
#define SP_PARTITION_H

#include "mesh/layout.h"
#include "mesh/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief The RCB order of the mesh nodes: the node set is split at the
 *        median of its longer coordinate extent (ties by the other
 *        coordinate, then by index), recursively, down to single nodes.
 * @param[out] order n_nodes entries: order[j] = the old index of the j-th node
 * @return SP_OK or SP_ERR_MEMORY
 */
int sp_partition_rcb_order(const sp_mesh *mesh, int *order);

/**
 * @brief Renumber the nodes of @p mesh so that new node j is old node
 *        order[j] (coordinates and element connectivity; element order and
 *        regions are unchanged).
 * @return SP_OK; SP_ERR_INTERNAL if @p order is not a permutation
 */
int sp_partition_renumber(sp_mesh *mesh, const int *order);

/**
 * @brief Contiguous node ranges, one per rank, with equal shares of the
 *        layout's unknowns: rank r owns nodes first_node[r] ..
 *        first_node[r+1]-1, where first_node[r] is the first node whose
 *        pairs start at or after r/n_ranks of all pairs (so shares differ by
 *        at most one node's unknowns). Deterministic: every rank computes
 *        the same ranges.
 * @param[out] first_node n_ranks + 1 entries; first_node[0] = 0,
 *             first_node[n_ranks] = n_nodes
 */
void sp_partition_ranges(const sp_layout *layout, int n_ranks, int *first_node);

#ifdef __cplusplus
}
#endif
#endif
