/**
 * @file mesh.c
 * @brief Rectangle meshes, the paper's five-patch disk mapped to an
 *        ellipse (docs/model.md, "Discretisation" and "Buffer zone"),
 *        and in 3D hexahedral boxes and its twin, the cubed ball
 *        mapped to an ellipsoid (docs/3d.md).
 *
 * The five-patch disk of refinement r has n = 2^r elements along every patch
 * side: an n x n centre square and four n x n patches between the square's
 * edges and the unit circle. Seen from outside the square the outer patches
 * form n rings of 4n quadrilaterals each, so the disk is built as
 *
 *   - the centre square's (n+1)^2 grid nodes, and
 *   - rings k = 1..n (+ buffer rings n+1..n+L) of 4n nodes each, indexed by
 *     the angular position t = 0..4n-1 counterclockwise from the corner
 *     (s, -s) at -45 degrees; "ring 0" is the square's own boundary.
 *
 * Every node therefore exists once (no merging of patch copies is needed):
 * V = (n+1)^2 + 4n^2 (+ 4nL), E = 5n^2 (+ 4nL); r = 5 gives 5185 and 5120.
 */
#include "mesh/mesh.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>

#include "public/error.h"
#include "mesh/q1.h"

/**
 * Half-width s of the centre square of the unit disk: s = 1/(2 + sqrt 2)
 * ~ 0.293, the value of deal.II's GridGenerator::hyper_ball (the paper's
 * library), chosen there to "equilibrate cell sizes at the transition": the
 * square's side 2s equals the diagonal distance 1 - s sqrt 2 from its corner
 * to the circle. Against the alternatives (at r = 5) it gives the least
 * flattened elements at the circle, where the worst element sits on the
 * diagonal with sides (pi/2)/n (along the arc) and (1 - s sqrt 2)/n (radial):
 *   s = 0.293: max edge ratio 2.68, element areas max/min 4.2;
 *   s = 0.396 (equal patch areas): 3.57 and 3.5;  s = 0.5: 5.36 and 4.4.
 * tests/test_mesh.c prints the det J quality numbers.
 */
#define SP_MESH_SQUARE_HALF_WIDTH 0.29289321881345248 /* 1/(2 + sqrt 2) */

/** pi; M_PI is not part of C11. */
#define SP_MESH_PI 3.14159265358979323846

/** Largest refinement accepted: r = 10 already has 5.2e6 nodes. */
#define SP_MESH_MAX_REFINEMENTS 10

/**
 * Relative tolerance of sp_mesh_contains: points on the boundary computed in
 * floating point (e.g. mesh nodes, which lie on the ellipse) count as inside.
 */
#define SP_MESH_CONTAINS_TOL 1e-12

/* ------------------------------------------------------------------------ */
/* Shared helpers                                                           */
/* ------------------------------------------------------------------------ */

/** Allocate the arrays of a mesh of dimension @p dim with the given counts. */
static int mesh_allocate(int dim, int n_nodes, int n_elems, sp_mesh **out) {
  sp_mesh *mesh;
  SP_ALLOC(mesh, 1);
  const size_t nq = (size_t)sp_q1_qpoints(dim);
  mesh->n_nodes = n_nodes;
  mesh->n_elems = n_elems;
  mesh->dim = dim;
  mesh->nodes_per_elem = sp_q1_nodes(dim);
  mesh->xy = calloc((size_t)dim * n_nodes, sizeof *mesh->xy);
  mesh->elem = calloc((size_t)mesh->nodes_per_elem * n_elems, sizeof *mesh->elem);
  mesh->region = calloc((size_t)n_elems, sizeof *mesh->region);
  mesh->q1_w = calloc(nq * n_elems, sizeof *mesh->q1_w);
  mesh->q1_x = calloc((size_t)dim * nq * n_elems, sizeof *mesh->q1_x);
  if (!mesh->xy || !mesh->elem || !mesh->region || !mesh->q1_w || !mesh->q1_x) {
    sp_mesh_destroy(&mesh);
    return sp_error_set(SP_ERR_MEMORY, "out of memory allocating a mesh of "
                        "%d nodes and %d elements", n_nodes, n_elems);
  }
  *out = mesh;
  return SP_OK;
}

/** The largest element edge length (sets mesh->h) and the Q1 geometry at
 *  the Gauss points (mesh->q1_w, q1_x), once the nodes are final. */
static void mesh_finish(sp_mesh *mesh) {
  /* The edges of an element (q1.h's node order): each face ring 0-1-2-3
   * (and 4-5-6-7 in 3D), and in 3D the edges a -> a + 4 between them. */
  static const int edge[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                  {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  const int dim = mesh->dim, nq = sp_q1_qpoints(dim), n_edges = dim == 3 ? 12 : 4;
  double h2 = 0;
  for (int e = 0; e < mesh->n_elems; ++e) {
    double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(mesh, e, xe);
    for (int q = 0; q < nq; ++q) {
      const size_t eq = (size_t)nq * e + q;
      double N[SP_Q1_MAX_NODES], dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
      sp_q1_point(dim, xe, q, N, dNdx, mesh->q1_x + (size_t)dim * eq, mesh->q1_w + eq);
    }
    for (int k = 0; k < n_edges; ++k) {
      const int a = edge[k][0], b = edge[k][1];
      double length2 = 0;
      for (int d = 0; d < dim; ++d) length2 += (xe[b][d] - xe[a][d]) * (xe[b][d] - xe[a][d]);
      if (length2 > h2) h2 = length2;
    }
  }
  mesh->h = sqrt(h2);
}

/** The arguments of the curved meshes (sp_mesh_ellipse, sp_mesh_ellipsoid):
 *  refinements in [0, @p max_refinements], @p dim finite positive semi-axes
 *  (a along x, b along y, c along z), buffer_layers in [0, 2^10] and, with
 *  layers, a finite positive buffer_width. */
/** The arguments of the rectangle and the box (sp_mesh_rectangle,
 *  sp_mesh_box): n[d] >= 1 elements and lo[d] < hi[d] along each of the
 *  @p dim axes, every count before any extent, as each mesh checked them. */
static int check_straight_arguments(int dim, const int *n, const double *lo, const double *hi) {
  static const char name[3] = {'x', 'y', 'z'};
  for (int d = 0; d < dim; ++d)
    SP_CHECK(n[d] >= 1, SP_ERR_INPUT, "mesh: n%c must be >= 1, got %d", name[d], n[d]);
  for (int d = 0; d < dim; ++d)
    SP_CHECK(isfinite(lo[d]) && isfinite(hi[d]) && hi[d] > lo[d], SP_ERR_INPUT,
             "mesh: need %c0 < %c1 (finite), got %c0 = %g, %c1 = %g", name[d], name[d],
             name[d], lo[d], name[d], hi[d]);
  return SP_OK;
}

static int check_curved_arguments(int refinements, int max_refinements, int dim,
                                  const double *semi, int buffer_layers,
                                  double buffer_width) {
  static const char *const axis[3] = {"a (x)", "b (y)", "c (z)"};
  SP_CHECK(refinements >= 0 && refinements <= max_refinements, SP_ERR_INPUT,
           "mesh: refinements must be in [0, %d], got %d", max_refinements, refinements);
  for (int d = 0; d < dim; ++d)
    SP_CHECK(isfinite(semi[d]) && semi[d] > 0, SP_ERR_INPUT,
             "mesh: semi-axis %s must be positive, got %g", axis[d], semi[d]);
  SP_CHECK(buffer_layers >= 0 && buffer_layers <= 1 << SP_MESH_MAX_REFINEMENTS,
           SP_ERR_INPUT, "mesh: buffer_layers must be in [0, %d], got %d",
           1 << SP_MESH_MAX_REFINEMENTS, buffer_layers);
  SP_CHECK(buffer_layers == 0 || (isfinite(buffer_width) && buffer_width > 0),
           SP_ERR_INPUT, "mesh: buffer_width must be positive when "
           "buffer_layers = %d > 0, got %g", buffer_layers, buffer_width);
  return SP_OK;
}

/** x0 + (x1 - x0) i / n, returning x1 exactly for i = n. */
static double lerp_exact_ends(double x0, double x1, int i, int n) {
  if (i == n) return x1;
  return x0 + (x1 - x0) * ((double)i / n);
}

/* ------------------------------------------------------------------------ */
/* Rectangle                                                                */
/* ------------------------------------------------------------------------ */

long long sp_mesh_rectangle_nodes(int nx, int ny) {
  return ((long long)nx + 1) * ((long long)ny + 1);
}

int sp_mesh_rectangle(double x0, double y0, double x1, double y1, int nx,
                      int ny, sp_mesh **out) {
  SP_CHECK(out, SP_ERR_INPUT, "sp_mesh_rectangle: out is NULL");
  *out = NULL;
  SP_CALL(check_straight_arguments(2, (int[]){nx, ny}, (double[]){x0, y0}, (double[]){x1, y1}));
  /* (nx+1)(ny+1) must fit an int, and so must 4 nx ny. */
  SP_CHECK(sp_mesh_rectangle_nodes(nx, ny) < INT_MAX / 4, SP_ERR_INPUT,
           "mesh: nx x ny = %d x %d is too large", nx, ny);

  sp_mesh *mesh;
  SP_CALL(mesh_allocate(2, (int)sp_mesh_rectangle_nodes(nx, ny), nx * ny, &mesh));
  /* Nodes row by row, i fastest: node (i, j) = j (nx+1) + i. */
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      int node = j * (nx + 1) + i;
      mesh->xy[2 * node] = lerp_exact_ends(x0, x1, i, nx);
      mesh->xy[2 * node + 1] = lerp_exact_ends(y0, y1, j, ny);
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      int *nodes = mesh->elem + 4 * (j * nx + i);
      nodes[0] = j * (nx + 1) + i; /* counterclockwise from lower left */
      nodes[1] = nodes[0] + 1;
      nodes[2] = nodes[1] + nx + 1;
      nodes[3] = nodes[0] + nx + 1;
    }
  /* region[] is already SP_REGION_OMEGA (= 0) from calloc. */
  mesh->is_ellipse = 0;
  mesh->bounds[0] = x0;
  mesh->bounds[1] = y0;
  mesh->bounds[2] = x1;
  mesh->bounds[3] = y1;
  mesh_finish(mesh);
  *out = mesh;
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* Box (3D)                                                                 */
/* ------------------------------------------------------------------------ */

long long sp_mesh_box_nodes(int nx, int ny, int nz) {
  return ((long long)nx + 1) * ((long long)ny + 1) * ((long long)nz + 1);
}

int sp_mesh_box(double x0, double y0, double z0, double x1, double y1, double z1, int nx,
                int ny, int nz, sp_mesh **out) {
  SP_CHECK(out, SP_ERR_INPUT, "sp_mesh_box: out is NULL");
  *out = NULL;
  SP_CALL(check_straight_arguments(3, (int[]){nx, ny, nz}, (double[]){x0, y0, z0},
                                   (double[]){x1, y1, z1}));
  /* the nodes, and 8 nx ny nz element entries, must fit an int */
  SP_CHECK(sp_mesh_box_nodes(nx, ny, nz) < INT_MAX / 8, SP_ERR_INPUT,
           "mesh: nx x ny x nz = %d x %d x %d is too large", nx, ny, nz);

  sp_mesh *mesh;
  SP_CALL(mesh_allocate(3, (int)sp_mesh_box_nodes(nx, ny, nz), nx * ny * nz, &mesh));
  /* node (i, j, k) = (k (ny+1) + j) (nx+1) + i */
  const int sx = 1, sy = nx + 1, sz = (nx + 1) * (ny + 1);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const int node = k * sz + j * sy + i;
        mesh->xy[3 * node] = lerp_exact_ends(x0, x1, i, nx);
        mesh->xy[3 * node + 1] = lerp_exact_ends(y0, y1, j, ny);
        mesh->xy[3 * node + 2] = lerp_exact_ends(z0, z1, k, nz);
      }
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        int *nodes = mesh->elem + 8 * ((k * ny + j) * nx + i);
        nodes[0] = k * sz + j * sy + i; /* the bottom face counterclockwise */
        nodes[1] = nodes[0] + sx;
        nodes[2] = nodes[1] + sy;
        nodes[3] = nodes[0] + sy;
        for (int a = 0; a < 4; ++a) nodes[a + 4] = nodes[a] + sz; /* the top face */
      }
  mesh->is_ellipse = 0;
  const double bounds[6] = {x0, y0, x1, y1, z0, z1};
  for (int d = 0; d < 6; ++d) mesh->bounds[d] = bounds[d];
  mesh_finish(mesh);
  *out = mesh;
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* Five-patch disk                                                          */
/* ------------------------------------------------------------------------ */

/**
 * Construction ("logical") numbering of the disk's nodes; renumbered at the
 * end (see disk_ring_order). Square node (i, j), i, j = 0..n: j (n+1) + i.
 * Ring node (k >= 1, t): (n+1)^2 + (k-1) 4n + t.
 */
typedef struct {
  int n;       /**< elements per patch side, 2^r */
  int n_rings; /**< n outer-patch rings + buffer rings */
} disk_grid;

static int disk_square_node(const disk_grid *g, int i, int j) {
  return j * (g->n + 1) + i;
}

/**
 * Node at ring k, angular position t (taken modulo 4n). Ring 0 is the
 * square's boundary walked counterclockwise from the corner (n, 0): east
 * edge up, north edge leftwards, west edge down, south edge rightwards.
 */
static int disk_ring_node(const disk_grid *g, int k, int t) {
  int n = g->n;
  t = ((t % (4 * n)) + 4 * n) % (4 * n);
  if (k > 0) return (n + 1) * (n + 1) + (k - 1) * 4 * n + t;
  int side = t / n, step = t % n;
  switch (side) {
  case 0: return disk_square_node(g, n, step);
  case 1: return disk_square_node(g, n - step, n);
  case 2: return disk_square_node(g, 0, n - step);
  default: return disk_square_node(g, step, 0);
  }
}

/** Rotate (x, y) by quarter_turns * 90 degrees counterclockwise, exactly. */
static void rotate_quarter_turns(int quarter_turns, double *x, double *y) {
  for (int q = 0; q < quarter_turns; ++q) {
    double x_old = *x;
    *x = -*y;
    *y = x_old;
  }
}

/**
 * Unit-disk coordinates of ring node (k >= 1, t). Each outer patch is built
 * in the frame of the east patch and rotated by whole quarter turns, so the
 * mesh is exactly symmetric under 90-degree rotations (and under the axis
 * mirrors up to the last bit of cos/sin at +-45 degrees).
 * In the east frame, local step l = 0..n along the patch maps to the square
 * point S = (s, s (2l - n)/n) and the circle point C = (cos phi, sin phi),
 * phi = (pi/4) (2l - n)/n (uniform angles on a 90-degree arc centred on the
 * axis); ring k <= n is the linear blend (1 - k/n) S + (k/n) C, so ring n
 * lies exactly on the circle. Buffer ring n + m is C scaled to radius
 * 1 + m width / layers (uniform radial steps).
 */
static void disk_ring_point(const disk_grid *g, int k, int t,
                            int buffer_layers, double buffer_width,
                            double *x, double *y) {
  const double s = SP_MESH_SQUARE_HALF_WIDTH;
  int n = g->n, patch = t / n, l = t % n;
  double offset = (double)(2 * l - n) / n; /* in [-1, 1) */
  double phi = 0.25 * SP_MESH_PI * offset;
  double cx = cos(phi), cy = sin(phi);
  if (k <= n) {
    double eta = (double)k / n;
    *x = (1 - eta) * s + eta * cx;
    *y = (1 - eta) * s * offset + eta * cy;
  } else {
    double radius = 1 + (k - n) * (buffer_width / buffer_layers);
    if (k - n == buffer_layers) radius = 1 + buffer_width;
    *x = radius * cx;
    *y = radius * cy;
  }
  rotate_quarter_turns(patch, x, y);
}

/** Sort key of a node for the final numbering (see disk_ring_order). */
typedef struct {
  long ring;     /**< concentric ring, inside out */
  long position; /**< counterclockwise position within the ring */
  int old;       /**< construction index */
} disk_node_key;

static int disk_key_compare(const void *pa, const void *pb) {
  const disk_node_key *a = pa, *b = pb;
  if (a->ring != b->ring) return a->ring < b->ring ? -1 : 1;
  if (a->position != b->position) return a->position < b->position ? -1 : 1;
  return (a->old > b->old) - (a->old < b->old);
}

/**
 * Position of square node (i, j) on its concentric square ring
 * m = max(|2i - n|, |2j - n|) (in half-steps; m = n is the square's
 * boundary), counted counterclockwise from the ring's lower-right corner like
 * the outer rings' t, in half-steps (even values in [0, 8m)).
 */
static long square_ring_position(int n, int i, int j, long m) {
  long u = 2L * i - n, v = 2L * j - n; /* in [-m, m] */
  if (m == 0) return 0;
  if (u == m && v < m) return v + m;               /* east, upwards */
  if (v == m && u > -m) return 2 * m + (m - u);     /* north, leftwards */
  if (u == -m && v > -m) return 4 * m + (m - v);    /* west, downwards */
  return 6 * m + (u + m);                           /* south, rightwards */
}

/**
 * Fold a position p in [0, length) of a closed ring so that ring neighbours
 * stay close: 0, length-1, 1, length-2, ... become 0, 1, 2, 3, ... (the two
 * halves of the ring interleave, so the wrap-around pair p = 0, length-1 is
 * no longer length-1 apart).
 */
static long ring_fold(long p, long length) {
  if (length <= 1) return 0; /* the centre node of an even n */
  return p < length / 2 + length % 2 ? 2 * p : 2 * (length - p) - 1;
}

/**
 * Final numbering: concentric rings from the centre outwards (the square's
 * rings of nodes at Chebyshev distance m from the centre, then the outer
 * rings k = 1..), each ring folded (ring_fold) from -45 degrees. Every
 * element couples one ring or two consecutive ones, at matching folded
 * positions, so the matrix bandwidth is 4n + 2 (one outer ring plus two):
 * 130 for r = 5, against 255 without folding, 237 for a (y, x) sort, 133 for
 * reverse Cuthill-McKee and ~(n+1)^2 for the construction numbering. (A
 * (y, x) sort has the smallest profile, ~23 % below this one; fill-reducing
 * orderings inside SuperLU/KLU make either fine.) Deterministic: integer keys
 * only. Fills new_of_old[old] = new.
 */
static int disk_ring_order(const disk_grid *g, int n_nodes, int *new_of_old) {
  int n = g->n;
  disk_node_key *keys;
  SP_ALLOC(keys, n_nodes);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      int old = disk_square_node(g, i, j);
      long m = labs(2L * i - n) > labs(2L * j - n) ? labs(2L * i - n)
                                                    : labs(2L * j - n);
      keys[old].ring = m;
      keys[old].position =
          ring_fold(square_ring_position(n, i, j, m), 8 * m);
      keys[old].old = old;
    }
  for (int k = 1; k <= g->n_rings; ++k)
    for (int t = 0; t < 4 * n; ++t) {
      int old = disk_ring_node(g, k, t);
      keys[old].ring = n + k;
      keys[old].position = ring_fold(t, 4L * n);
      keys[old].old = old;
    }
  qsort(keys, (size_t)n_nodes, sizeof *keys, disk_key_compare);
  for (int p = 0; p < n_nodes; ++p) new_of_old[keys[p].old] = p;
  free(keys);
  return SP_OK;
}

/** Apply new_of_old to the mesh's node coordinates and connectivity. */
static int mesh_renumber(sp_mesh *mesh, const int *new_of_old) {
  double *xy;
  SP_ALLOC(xy, (size_t)2 * mesh->n_nodes);
  for (int old = 0; old < mesh->n_nodes; ++old) {
    xy[2 * new_of_old[old]] = mesh->xy[2 * old];
    xy[2 * new_of_old[old] + 1] = mesh->xy[2 * old + 1];
  }
  free(mesh->xy);
  mesh->xy = xy;
  for (long c = 0; c < 4L * mesh->n_elems; ++c)
    mesh->elem[c] = new_of_old[mesh->elem[c]];
  return SP_OK;
}

/** The disk mesh in construction numbering, unit radius, before scaling. */
static void disk_fill(const disk_grid *g, int buffer_layers,
                      double buffer_width, sp_mesh *mesh) {
  const double s = SP_MESH_SQUARE_HALF_WIDTH;
  int n = g->n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      int node = disk_square_node(g, i, j);
      /* s (2i - n)/n: exactly antisymmetric about the centre. */
      mesh->xy[2 * node] = s * ((double)(2 * i - n) / n);
      mesh->xy[2 * node + 1] = s * ((double)(2 * j - n) / n);
    }
  for (int k = 1; k <= g->n_rings; ++k)
    for (int t = 0; t < 4 * n; ++t) {
      int node = disk_ring_node(g, k, t);
      disk_ring_point(g, k, t, buffer_layers, buffer_width,
                      &mesh->xy[2 * node], &mesh->xy[2 * node + 1]);
    }

  int e = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i, ++e) {
      int *nodes = mesh->elem + 4 * e;
      nodes[0] = disk_square_node(g, i, j);
      nodes[1] = disk_square_node(g, i + 1, j);
      nodes[2] = disk_square_node(g, i + 1, j + 1);
      nodes[3] = disk_square_node(g, i, j + 1);
      mesh->region[e] = SP_REGION_OMEGA;
    }
  /* Ring elements between rings k and k+1: outward, then along increasing
   * t, is counterclockwise (e_r x e_theta = +z). */
  for (int k = 0; k < g->n_rings; ++k)
    for (int t = 0; t < 4 * n; ++t, ++e) {
      int *nodes = mesh->elem + 4 * e;
      nodes[0] = disk_ring_node(g, k, t);
      nodes[1] = disk_ring_node(g, k + 1, t);
      nodes[2] = disk_ring_node(g, k + 1, t + 1);
      nodes[3] = disk_ring_node(g, k, t + 1);
      mesh->region[e] = k < n ? SP_REGION_OMEGA : SP_REGION_BUFFER;
    }
}

long long sp_mesh_ellipse_nodes(int refinements, int buffer_layers) {
  const long long n = 1LL << refinements;
  return (n + 1) * (n + 1) + 4 * n * (n + buffer_layers);
}

int sp_mesh_ellipse(int refinements, double a, double b, int buffer_layers,
                    double buffer_width, sp_mesh **out) {
  SP_CHECK(out, SP_ERR_INPUT, "sp_mesh_ellipse: out is NULL");
  *out = NULL;
  SP_CALL(check_curved_arguments(refinements, SP_MESH_MAX_REFINEMENTS, 2, (double[]){a, b},
                                 buffer_layers, buffer_width));

  disk_grid grid = {1 << refinements, (1 << refinements) + buffer_layers};
  int n = grid.n;
  int n_nodes = (int)sp_mesh_ellipse_nodes(refinements, buffer_layers);
  int n_elems = n * n + 4 * n * grid.n_rings;

  sp_mesh *mesh;
  SP_CALL(mesh_allocate(2, n_nodes, n_elems, &mesh));
  disk_fill(&grid, buffer_layers, buffer_width, mesh);

  int *new_of_old = malloc((size_t)n_nodes * sizeof *new_of_old);
  int rc = new_of_old ? disk_ring_order(&grid, n_nodes, new_of_old)
                      : sp_error_set(SP_ERR_MEMORY, "out of memory "
                                     "renumbering %d mesh nodes", n_nodes);
  if (rc == SP_OK) rc = mesh_renumber(mesh, new_of_old);
  free(new_of_old);
  if (rc != SP_OK) {
    sp_mesh_destroy(&mesh);
    return rc;
  }

  for (int node = 0; node < n_nodes; ++node) {
    mesh->xy[2 * node] *= a;
    mesh->xy[2 * node + 1] *= b;
  }
  mesh->is_ellipse = 1;
  mesh->bounds[0] = 0;
  mesh->bounds[1] = 0;
  mesh->bounds[2] = a;
  mesh->bounds[3] = b;
  mesh_finish(mesh);
  *out = mesh;
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* Cubed ball (3D)                                                          */
/* ------------------------------------------------------------------------ */

/**
 * Half-width of the centre cube of the unit ball: the 2D rule above in 3D,
 * the cube's side 2s equal to the diagonal distance 1 - s sqrt 3 from its
 * corner to the sphere, s = 1/(2 + sqrt 3) ~ 0.268 (deal.II's 3D hyper_ball
 * uses 1/(3 + sqrt 3) ~ 0.211; tests/test_mesh_3d.c prints the quality of
 * this one).
 */
#define SP_MESH_CUBE_HALF_WIDTH 0.26794919243112270 /* 1/(2 + sqrt 3) */

/**
 * The cubed ball of refinement r: the centre cube's (n+1)^3 grid nodes,
 * n = 2^r, and shells k = 1..n (+ buffer shells n+1..n+L) of 6n^2 + 2 nodes
 * each, one per node of the cube's surface grid ("shell 0"). Node numbers:
 * grid node (i, j, l) of the cube is (l (n+1) + j)(n+1) + i; the node of
 * shell k >= 1 over surface node g is (n+1)^3 + (k-1)(6n^2+2) + surface[g].
 */
typedef struct {
  int n;        /**< elements per cube edge and per patch, 2^r */
  int n_shells; /**< n patch shells + buffer shells */
  int *surface; /**< per cube grid node: its index on the surface, or -1 */
} ball_grid;

static int ball_cube_node(int n, const int g[3]) {
  return (g[2] * (n + 1) + g[1]) * (n + 1) + g[0];
}

/** Nodes on one shell: the surface of the (n+1)^3 grid, 6n^2 + 2. */
static long long ball_shell_nodes(long long n) { return 6 * n * n + 2; }

/** Node of shell k over the cube's surface grid node g. */
static int ball_node(const ball_grid *b, int k, const int g[3]) {
  const int cube = ball_cube_node(b->n, g);
  if (k == 0) return cube;
  const int n = b->n;
  return (n + 1) * (n + 1) * (n + 1) + (k - 1) * (int)ball_shell_nodes(n) + b->surface[cube];
}

/**
 * Unit-ball coordinates of shell k >= 1's node over surface grid node g,
 * the 2D ring point (disk_ring_point) in 3D: with offsets u_d = (2 g_d - n)/n
 * in [-1, 1] (|u_d| = 1 on the node's face), the cube point S = s u and the
 * sphere point C = t / |t| with t_d = tan(pi u_d / 4) (exactly +-1 on the
 * face): the equiangular ("gnomonic") cubed sphere, whose restriction to a
 * coordinate plane is the 2D patches' uniform angles. Shell k <= n is the
 * blend (1 - k/n) S + (k/n) C, so shell n lies on the sphere; buffer shell
 * n + m is C at radius 1 + m width / layers. Every coordinate comes from its
 * own index by the same formula, and |t| is summed in sorted order, so the
 * mesh is exactly symmetric under axis permutations and mirrors.
 */
static void ball_shell_point(const ball_grid *b, int k, const int g[3], int buffer_layers,
                             double buffer_width, double x[3]) {
  const double s = SP_MESH_CUBE_HALF_WIDTH;
  const int n = b->n;
  double u[3], t[3], t2[3];
  for (int d = 0; d < 3; ++d) {
    u[d] = (double)(2 * g[d] - n) / n;
    t[d] = g[d] == 0 ? -1.0 : g[d] == n ? 1.0 : tan(0.25 * SP_MESH_PI * u[d]);
    t2[d] = t[d] * t[d];
  }
  for (int i = 1; i < 3; ++i) /* sort the squares: a sum independent of the axes' order */
    for (int j = i; j > 0 && t2[j] < t2[j - 1]; --j) {
      const double tmp = t2[j];
      t2[j] = t2[j - 1];
      t2[j - 1] = tmp;
    }
  const double norm = sqrt(t2[0] + t2[1] + t2[2]);
  double radius = 1;
  if (k > n) radius = k - n == buffer_layers ? 1 + buffer_width
                                             : 1 + (k - n) * (buffer_width / buffer_layers);
  for (int d = 0; d < 3; ++d) {
    const double c = t[d] / norm;
    if (k <= n) {
      const double eta = (double)k / n;
      x[d] = (1 - eta) * s * u[d] + eta * c;
    } else {
      x[d] = radius * c;
    }
  }
}

/** The cubed ball's nodes in its numbering, unit radius, before scaling:
 *  the cube's grid, and over each of its surface nodes one per shell. */
static void ball_fill_nodes(const ball_grid *b, int buffer_layers, double buffer_width,
                            sp_mesh *mesh) {
  const double s = SP_MESH_CUBE_HALF_WIDTH;
  const int n = b->n;
  int g[3];
  for (g[2] = 0; g[2] <= n; ++g[2])
    for (g[1] = 0; g[1] <= n; ++g[1])
      for (g[0] = 0; g[0] <= n; ++g[0]) {
        double *x = mesh->xy + 3 * (size_t)ball_cube_node(n, g);
        for (int d = 0; d < 3; ++d) x[d] = s * ((double)(2 * g[d] - n) / n);
        if (b->surface[ball_cube_node(n, g)] < 0) continue;
        for (int k = 1; k <= b->n_shells; ++k)
          ball_shell_point(b, k, g, buffer_layers, buffer_width,
                           mesh->xy + 3 * (size_t)ball_node(b, k, g));
      }
}

/** The centre cube's n^3 hexahedra (as sp_mesh_box's), elements 0.. */
static void ball_fill_cube(const ball_grid *b, sp_mesh *mesh) {
  const int n = b->n;
  int e = 0;
  for (int l = 0; l < n; ++l)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i, ++e) {
        int *nodes = mesh->elem + 8 * (size_t)e;
        for (int a = 0; a < 8; ++a) {
          const int corner[3] = {i + (sp_q1_corner(a, 0) > 0), j + (sp_q1_corner(a, 1) > 0),
                                 l + (sp_q1_corner(a, 2) > 0)};
          nodes[a] = ball_cube_node(n, corner);
        }
        mesh->region[e] = SP_REGION_OMEGA;
      }
}

/**
 * The patches' hexahedra between shells k and k + 1, from element @p e on:
 * over each face quad of the cube's surface (counterclockwise seen from
 * outside), shell k's quad is its q1.h bottom face and shell k + 1's its
 * top face, so det J > 0. On the face normal to axis d at side g_d = 0 or
 * n, the tangent axes d1, d2 (e_d1 x e_d2 = e_d) are walked in that order
 * on the + side, reversed on the - side. Returns the next element.
 */
static int ball_fill_shell(const ball_grid *b, int k, int e, sp_mesh *mesh) {
  static const int walk[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const int n = b->n;
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side <= 1; ++side)
      for (int q = 0; q < n; ++q)
        for (int p = 0; p < n; ++p, ++e) {
          const int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
          int *nodes = mesh->elem + 8 * (size_t)e;
          for (int a = 0; a < 4; ++a) {
            const int w = side ? a : (4 - a) % 4; /* reversed: 0, 3, 2, 1 */
            int corner[3];
            corner[d] = side ? n : 0;
            corner[d1] = p + walk[w][0];
            corner[d2] = q + walk[w][1];
            nodes[a] = ball_node(b, k, corner);
            nodes[a + 4] = ball_node(b, k + 1, corner);
          }
          mesh->region[e] = k < n ? SP_REGION_OMEGA : SP_REGION_BUFFER;
        }
  return e;
}

/** The cubed ball in its numbering, unit radius, before scaling. */
static void ball_fill(const ball_grid *b, int buffer_layers, double buffer_width,
                      sp_mesh *mesh) {
  ball_fill_nodes(b, buffer_layers, buffer_width, mesh);
  ball_fill_cube(b, mesh);
  int e = b->n * b->n * b->n;
  for (int k = 0; k < b->n_shells; ++k) e = ball_fill_shell(b, k, e, mesh);
}

long long sp_mesh_ellipsoid_nodes(int refinements, int buffer_layers) {
  const long long n = 1LL << refinements;
  return (n + 1) * (n + 1) * (n + 1) + (n + buffer_layers) * ball_shell_nodes(n);
}

long long sp_mesh_ellipsoid_elements(int refinements, int buffer_layers) {
  const long long n = 1LL << refinements;
  return n * n * n + 6 * n * n * (n + buffer_layers);
}

int sp_mesh_ellipsoid(int refinements, double a, double b, double c, int buffer_layers,
                      double buffer_width, sp_mesh **out) {
  SP_CHECK(out, SP_ERR_INPUT, "sp_mesh_ellipsoid: out is NULL");
  *out = NULL;
  SP_CALL(check_curved_arguments(refinements, SP_MESH_ELLIPSOID_MAX_REFINEMENTS, 3,
                                 (double[]){a, b, c}, buffer_layers, buffer_width));
  /* the nodes, and 8 entries per element, must fit an int */
  const long long n_nodes = sp_mesh_ellipsoid_nodes(refinements, buffer_layers);
  const long long n_elems = sp_mesh_ellipsoid_elements(refinements, buffer_layers);
  SP_CHECK(n_nodes < INT_MAX / 8 && n_elems < INT_MAX / 8, SP_ERR_INPUT,
           "mesh: refinements = %d with buffer_layers = %d is too large (%lld nodes, %lld "
           "elements)", refinements, buffer_layers, n_nodes, n_elems);

  const int n = 1 << refinements;
  ball_grid grid = {n, n + buffer_layers, NULL};
  const size_t cube_nodes = (size_t)(n + 1) * (n + 1) * (n + 1);
  SP_ALLOC(grid.surface, cube_nodes);
  int next = 0, g[3];
  for (g[2] = 0; g[2] <= n; ++g[2])
    for (g[1] = 0; g[1] <= n; ++g[1])
      for (g[0] = 0; g[0] <= n; ++g[0]) {
        int on_surface = 0;
        for (int d = 0; d < 3; ++d) on_surface |= g[d] == 0 || g[d] == n;
        grid.surface[ball_cube_node(n, g)] = on_surface ? next++ : -1;
      }

  sp_mesh *mesh;
  const int rc = mesh_allocate(3, (int)n_nodes, (int)n_elems, &mesh);
  if (rc != SP_OK) {
    free(grid.surface);
    return rc;
  }
  ball_fill(&grid, buffer_layers, buffer_width, mesh);
  free(grid.surface);
  const double scale[3] = {a, b, c};
  for (size_t i = 0; i < (size_t)n_nodes; ++i)
    for (int d = 0; d < 3; ++d) mesh->xy[3 * i + d] *= scale[d];
  mesh->is_ellipse = 1;
  const double bounds[6] = {0, 0, a, b, 0, c};
  for (int d = 0; d < 6; ++d) mesh->bounds[d] = bounds[d];
  mesh_finish(mesh);
  *out = mesh;
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* The coverslip: the ellipse (ellipsoid) cut by two planes                 */
/* ------------------------------------------------------------------------ */

/** The semi-axes of an ellipse (ellipsoid) mesh, from its bounds. */
static void mesh_semi_axes(const sp_mesh *mesh, double semi[3]) {
  static const int hi[3] = {2, 3, 5};
  for (int d = 0; d < 3; ++d) semi[d] = d < mesh->dim ? mesh->bounds[hi[d]] : 0.0;
}

int sp_mesh_flatten(sp_mesh *mesh, double h) {
  SP_CHECK(mesh && mesh->is_ellipse, SP_ERR_INPUT,
           "sp_mesh_flatten: expected an ellipse or ellipsoid mesh");
  const int dim = mesh->dim, last = dim - 1;
  double semi[3];
  mesh_semi_axes(mesh, semi);
  SP_CHECK(h > 0 && h < semi[last], SP_ERR_INPUT,
           "sp_mesh_flatten: expected 0 < h < %.15g (the last semi-axis), got %.15g", semi[last],
           h);
  for (int i = 0; i < mesh->n_nodes; ++i) {
    double *x = mesh->xy + (size_t)dim * i;
    double across = 0; /* sum over the other axes of (x_d / s_d)^2 */
    for (int d = 0; d < last; ++d) across += (x[d] / semi[d]) * (x[d] / semi[d]);
    const double t = x[last] / semi[last];
    const double rho = sqrt(across + t * t);
    if (rho <= 1) { /* Omega: the column's extent T to min(T, h) */
      const double column = semi[last] * sqrt(fmax(0.0, 1 - across));
      if (column > h) x[last] *= h / column;
    } else { /* the buffer: the surface map, scaled by rho */
      x[last] = copysign(fmin(fabs(x[last]), rho * h), x[last]);
    }
  }
  mesh->flatten = h;
  mesh_finish(mesh);
  return SP_OK;
}

double sp_mesh_flattened_measure(int dim, const double semi[3], double h) {
  const double pi = 3.14159265358979323846;
  const double c = semi[dim - 1];
  if (h > c) h = c;
  if (dim == 2) {
    const double u = h / c;
    return 2 * semi[0] * c * (u * sqrt(1 - u * u) + asin(u));
  }
  return pi * semi[0] * semi[1] * (2 * h - 2 * h * h * h / (3 * c * c));
}

/* ------------------------------------------------------------------------ */
/* Queries                                                                  */
/* ------------------------------------------------------------------------ */

double sp_mesh_region_area(const sp_mesh *mesh, int region) {
  if (!mesh) return 0;
  double area = 0;
  for (int e = 0; e < mesh->n_elems; ++e) {
    if (mesh->region[e] != region) continue;
    double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], N[SP_Q1_MAX_NODES];
    double dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
    sp_mesh_elem_xy(mesh, e, xe);
    for (int q = 0; q < sp_q1_qpoints(mesh->dim); ++q) {
      sp_q1_point(mesh->dim, xe, q, N, dNdx, x, &w);
      area += w;
    }
  }
  return area;
}

int sp_mesh_contains(const sp_mesh *mesh, const double *x) {
  if (!mesh) return 0;
  /* axis d's interval [lo, hi] in bounds (x0, y0, x1, y1, z0, z1) */
  static const int lo[3] = {0, 1, 4}, hi[3] = {2, 3, 5};
  const double *bd = mesh->bounds;
  if (mesh->is_ellipse) {
    double level = 0;
    for (int d = 0; d < mesh->dim; ++d) level += (x[d] / bd[hi[d]]) * (x[d] / bd[hi[d]]);
    const double cut = mesh->flatten; /* (0: none) */
    return level <= 1 + SP_MESH_CONTAINS_TOL &&
           (!(cut > 0) || fabs(x[mesh->dim - 1]) <= cut * (1 + SP_MESH_CONTAINS_TOL));
  }
  int inside = 1;
  for (int d = 0; d < mesh->dim; ++d) {
    const double tol = SP_MESH_CONTAINS_TOL * (bd[hi[d]] - bd[lo[d]]);
    inside &= x[d] >= bd[lo[d]] - tol && x[d] <= bd[hi[d]] + tol;
  }
  return inside;
}

void sp_mesh_destroy(sp_mesh **mesh) {
  if (!mesh || !*mesh) return;
  free((*mesh)->xy);
  free((*mesh)->elem);
  free((*mesh)->region);
  free((*mesh)->q1_w);
  free((*mesh)->q1_x);
  free(*mesh);
  *mesh = NULL;
}

double sp_mesh_bytes(const sp_mesh *mesh) {
  const double nn = mesh->n_nodes, ne = mesh->n_elems;
  const double nq = mesh->q1_w ? sp_q1_qpoints(mesh->dim) : 0;
  return sizeof(double) * mesh->dim * nn + sizeof(int) * (mesh->nodes_per_elem + 1.0) * ne +
         sizeof(double) * (1.0 + mesh->dim) * nq * ne;
}
