/* hearth/recon_geom.h - area recon (src/recon/recon_tsdf.c, recon_mc.c,
 * recon_clean.c): geometry from depth. Masked depth maps are fused in a
 * truncated signed distance volume, the zero level set is meshed by
 * marching tetrahedra (each voxel cube split into six tetrahedra along its
 * main diagonal, so no case table is needed), and the mesh is cleaned
 * (largest connected component, small holes closed) and simplified by
 * quadric error edge collapse. Everything is metric (metres).
 *
 * Signed distances are positive in front of the surface (outside the
 * object, towards the cameras) and negative behind it; triangles face
 * outwards (counter-clockwise seen from outside). */
#ifndef HEARTH_RECON_GEOM_H
#define HEARTH_RECON_GEOM_H

#include <stddef.h>
#include <stdint.h>
#include "hearth/camera.h"
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/image.h"
#include "hearth/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A voxel grid of nx * ny * nz samples at origin + voxel * (i, j, k),
 * x fastest. dist holds the truncated distance divided by trunc (in
 * [-1, 1]), weight the sum of the observations' weights (0: unobserved). */
typedef struct hearth_tsdf {
  int nx, ny, nz;
  double origin[3];
  double voxel;  /* metres */
  double trunc;  /* metres */
  float *dist;   /* owned, nx*ny*nz */
  float *weight; /* owned, nx*ny*nz */
} hearth_tsdf;

/* Refuse volumes above this many samples (HEARTH_E_LIMIT). */
#define HEARTH_TSDF_MAX_SAMPLES ((size_t)400 * 1000 * 1000)

/* A volume covering the box [lo, hi] (metres) with samples voxel apart;
 * all samples unobserved. t is overwritten, not freed. */
hearth_status hearth_tsdf_init(hearth_tsdf *t, const double lo[3], const double hi[3], double voxel,
                               double trunc, hearth_err *err);
void hearth_tsdf_free(hearth_tsdf *t); /* accepts a zeroed volume */

/* Fuse one depth map (U16 millimetres, 1 channel, 0 = no measurement) seen
 * by camera cam with pose T_world_from_cam. mask (width*height bytes, or
 * NULL: every pixel is the object) marks the object's pixels (non-zero);
 * other pixels with a depth only carve free space (samples more than trunc
 * in front of them move towards +1), they add no surface. Each sample
 * projects to its nearest pixel; the signed distance is measured along the
 * camera's z axis, samples more than trunc behind the surface are left
 * alone, and each observation adds weight 1 (a running mean). */
hearth_status hearth_tsdf_integrate(hearth_tsdf *t, const hearth_image *depth,
                                    const hearth_camera *cam, const hearth_rigid *T_world_from_cam,
                                    const uint8_t *mask, hearth_err *err);

/* The zero level set as a triangle mesh (no UVs), vertices shared between
 * neighbouring cells. Only tetrahedra whose four samples are all observed
 * are meshed. */
hearth_status hearth_tsdf_extract(const hearth_tsdf *t, hearth_mesh *out, hearth_err *err);

/* Keep the connected component (triangles joined by shared vertices) with
 * the most triangles; drops degenerate triangles and unused vertices. */
hearth_status hearth_mesh_keep_largest(hearth_mesh *m, hearth_err *err);

/* Close every boundary loop of at most max_edges edges with a fan around a
 * new vertex at the loop's centroid, oriented like its neighbours. A
 * boundary through a vertex twice (holes touching there) is split there
 * into separate loops.
 * n_filled (may be NULL) receives the number of loops closed. */
hearth_status hearth_mesh_fill_holes(hearth_mesh *m, size_t max_edges, size_t *n_filled,
                                     hearth_err *err);

/* Edge collapse by quadric error (Garland-Heckbert) until the mesh has at
 * most target_triangles triangles or no collapse keeps it manifold
 * without flipping a triangle. Each collapse moves the kept vertex to the
 * quadric's minimiser (the edge's best end or midpoint where the quadric
 * is singular). */
hearth_status hearth_mesh_simplify(hearth_mesh *m, size_t target_triangles, hearth_err *err);

/* Counts of undirected edges used by one triangle (boundary) and by more
 * than two (non-manifold); a closed manifold mesh has both 0. */
void hearth_mesh_edge_stats(const hearth_mesh *m, size_t *n_boundary, size_t *n_nonmanifold);

/* ---- from a release ------------------------------------------------------ */
typedef struct hearth_recon_tsdf_opts {
  double voxel_m;          /* default 0.002 */
  double trunc_m;          /* default (0) 2 voxels; thin walls need it small */
  size_t hole_max_edges;   /* default 4000: enough for the unseen base of an
                              object standing on the turntable */
  size_t target_triangles; /* default 20000; 0: no simplification */
  const char *poses;       /* poses file relative to the release root; default
                              ground_truth/instances/<id>/poses_rgb.json */
} hearth_recon_tsdf_opts;
void hearth_recon_tsdf_opts_default(hearth_recon_tsdf_opts *o);

/* The metric mesh of instance `instance` from the depth maps of its states
 * (states NULL or n_states 0: every state of instance.json): each view's
 * depth (raw/<state>/depth/vNN.png with the intrinsics of vNN.json),
 * masked by the cut-out (a depth pixel is the object when its point,
 * taken to the colour camera by the inverse of calibration/factory.json's
 * T_depth_from_rgb and projected with the factory colour intrinsics, lands
 * on a non-zero cut-out pixel), fused with the depth camera's pose
 * T_world_from_rgb * inverse(T_depth_from_rgb) from the (metric) colour
 * poses. The volume bounds are those of the masked points plus a margin.
 * The result is cleaned, hole-filled and simplified as the options say. */
hearth_status hearth_recon_tsdf(const char *root, const char *instance, const char *const *states,
                                size_t n_states, const hearth_recon_tsdf_opts *opts,
                                hearth_mesh *out, hearth_err *err);

#ifdef __cplusplus
}
#endif

#endif
