/**
 * @file cell_obs.h
 * @brief What is observed of each cell after a step (public: a step
 *        callback sees them, run_types.h); computed by cells.h.
 */
#ifndef SP_CELL_OBS_H
#define SP_CELL_OBS_H

#ifdef __cplusplus
extern "C" {
#endif

/** Room for a cell's name with its NUL: at most 31 characters, letters,
 *  digits, '_', '.' and '-' (the scene's cells[i].name and lineage
 *  table; "" for an unnamed cell). */
#define SP_CELL_NAME_MAX 32

/** A cell's name ("": none). */
typedef char sp_cell_name[SP_CELL_NAME_MAX];

/** Observables of one cell (MODEL.md, shape penalty, for the tensor). */
typedef struct {
  double mass;      /**< m_k = int c_k dV (the conserved quantity) */
  double mass_core; /**< int c_k dV over c_k >= weight_threshold only: the
                         cell without its background (division, source) */
  double xc, yc;    /**< centre of mass int c X / int c */
  double zc;        /**< its z on a 3D mesh (0 in 2D) */
  double Ixx, Iyy, Ixy; /**< inertia tensor about the centre, Xb = X - Xc:
                             2D [[Ixx, Ixy],[Ixy, Iyy]] with Ixx = int c Xb2^2,
                             Iyy = int c Xb1^2, Ixy = -int c Xb1 Xb2
                             (MODEL.md); 3D the rigid body's tensor
                             I = int c (|Xb|^2 Id - Xb Xb^T), whose xy
                             block adds int c Xb3^2 to both diagonal
                             entries (the same eigenvectors) */
  double Izz, Ixz, Iyz; /**< 3D: Izz = int c (Xb1^2 + Xb2^2), Ixz =
                             -int c Xb1 Xb3, Iyz = -int c Xb2 Xb3 (0 in 2D) */
  double I1, I2;    /**< principal moments, I1 >= I2 (>= I3 in 3D) */
  double I3;        /**< 3D: the smallest principal moment (0 in 2D) */
  double v1[3], v2[3]; /**< unit eigenvectors of I1 and I2 (z = 0 in 2D) */
  double v3[3];     /**< 3D: unit eigenvector of I3, the long axis (0 in 2D,
                         where the long axis is v2) */
  double angle;     /**< 2D: angle of v1 from the x axis, in (-pi/2, pi/2]
                         (0 in 3D) */
  double area;      /**< area (3D: volume) where c_k >= 1/2 (inside the
                         membrane; at the quadrature points, whatever the
                         weight threshold) */
} sp_cell_obs;

#ifdef __cplusplus
}
#endif
#endif
