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
#include "hearth/dataset.h"
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

/* Which boundary loops hearth_mesh_fill_holes_near closes: every loop of
 * at most small_edges edges, and a longer one (up to max_edges) only when
 * its centroid lies within tol_m of the plane plane[0..2] . x + plane[3] = 0
 * (plane[0..2] a unit normal). */
typedef struct hearth_hole_rule {
  size_t max_edges;
  size_t small_edges;
  double plane[4];
  double tol_m;
} hearth_hole_rule;

/* hearth_mesh_fill_holes with the rule above: the opening where an object
 * stands on its support is closed, an opening elsewhere (surface no depth
 * view reached, such as the inside of a cup below what the views saw) is
 * left open rather than closed by a made-up patch. n_filled and n_open (either
 * may be NULL) receive the loops closed and the loops of 3 or more edges
 * left open. */
hearth_status hearth_mesh_fill_holes_near(hearth_mesh *m, const hearth_hole_rule *rule,
                                          size_t *n_filled, size_t *n_open, hearth_err *err);

/* The boundary loops of m (3 or more edges; a boundary through a vertex
 * twice counts as separate loops, as hearth_mesh_fill_holes splits it):
 * n_loops and n_edges (either may be NULL) receive how many and their
 * edges. A closed mesh has 0. */
hearth_status hearth_mesh_open_loops(const hearth_mesh *m, size_t *n_loops, size_t *n_edges,
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
/* hole_support_m of `hearth recon`'s turntable route: 2.5 voxels of 2 mm;
 * on the virtual rig the base's loop lies within 3 mm of the turntable top,
 * the openings left 20 mm or more above it */
#define HEARTH_RECON_HOLE_SUPPORT_M 0.005

typedef struct hearth_recon_tsdf_opts {
  double voxel_m;          /* default 0.002 */
  double trunc_m;          /* default (0) 2 voxels; thin walls need it small */
  size_t hole_max_edges;   /* default 4000: enough for the unseen base of an
                              object standing on the turntable */
  double hole_support_m;   /* default 0: every loop up to hole_max_edges is
                              closed. > 0: a loop of more than 16 edges is
                              closed only when its centroid lies within this
                              distance of the support plane z = 0 (the
                              turntable top in the frame of `hearth recon`'s
                              poses, which sets 0.005); others stay open
                              (hearth_mesh_fill_holes_near) */
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

/* ---- colour poses from a turntable capture (recon_turntable.c) ----------- */
/* The embedded pose route: no outside tool. Each view's depth map gives,
 * in the colour camera's frame (through the factory T_depth_from_rgb),
 *  - the turntable/table plane (RANSAC and least squares on the depth
 *    pixels off the cut-out whose plane faces up in the image): the
 *    turntable axis's direction and the camera's height above the top,
 *    which start two rotation angles and one translation of its pose;
 *  - the object's points and normals (depth pixels whose point lands well
 *    inside the cut-out, away from depth edges).
 * The turntable geometry starts the rest: azimuth (index a, ring e)
 * direction * (a * azimuth_step + e * ring_shift) about the axis, the
 * object's centroid on the axis. Point-to-plane ICP then refines all six
 * degrees of every view jointly over all views of all states (pairs of
 * views whose optical axes are within max_pair_deg, projective association
 * in the target's depth image, Huber weights, a shrinking distance gate;
 * the cameras' mean horizontal step held at zero as the gauge), with each
 * view's table points (those within 0.25 m of its object points) held at
 * z = 0 and the turntable's azimuth
 * as a weak prior. Where every view of a state carries the manifest's
 * turntable_deg (and not ignore_encoder), the differences of those views'
 * angles are held stiffly to the encoder's, over all such states at once
 * (or each alone: encoder_per_state). The angle of a view is the heading
 * of the camera's tilt axis: the direction of the camera frame normal to
 * all views' table normals (a turntable camera tilts about it between
 * rings); with colour_weight > 0 the views without the encoder add a
 * photometric term (recon_photo.c: band-passed grey inside the cut-out,
 * view i's point against view j's image at its depth correspondence). With
 * aim_prior > 0, the aim term: the rig aims its cameras at the object
 * and the turntable turns the object under them, so the point C of the
 * axis they aim at lies at one place P in every camera's frame, within
 * aim_side_m across the optical axis and aim_depth_tol of its distance
 * along it (C per state and P are unknowns of the ICP). It fixes a
 * camera's place where its depth does not: a flat object's low ring, the
 * radius of a smooth cylinder. The frame of the result: metres,
 * +z up the axis, the turntable top at z = 0, view 0's azimuth at its
 * nominal value. A surface of revolution without azimuthal detail leaves
 * the angle about its own axis unobserved by its depth: those views keep
 * (about) their turntable azimuth. */
typedef struct hearth_turntable_opts {
  double azimuth_step_deg; /* between azimuth indices; default 36 */
  double ring_shift_deg;   /* added per elevation index; default 12 */
  int direction;           /* +1 (default): azimuth grows counter-clockwise seen
                              from above; -1 the other way */
  int iterations;          /* Gauss-Newton iterations; default 30 */
  size_t max_points;       /* ICP samples per view and pair; default 3000 */
  double max_pair_deg;     /* default 65 */
  double erode_px;         /* colour pixels a point must lie inside the cut-out; default 8 */
  double azimuth_prior;    /* weight (m^2/rad^2) pulling each angle towards the
                              turntable's: (depth noise / azimuth spread)^2;
                              default 3e-3 (0.8 mm, 0.9 degrees) */
  double encoder_prior;    /* weight, per match a view has, holding the
                              differences of a state's headings to those of
                              the manifest's turntable_deg; default 1 */
  int ignore_encoder;      /* 1: leave the manifest's turntable_deg unused */
  int encoder_per_state;   /* 1: only angles within a state's pass are compared
                              (the object was put back between states); 0
                              (default): one turntable frame for all states */
  double colour_weight;    /* weight (m^2 per squared grey level, 0..1) of the
                              photometric term of the views without the
                              encoder, about (depth noise / grey noise)^2 =
                              1e-2; default 0 (off: on the virtual rig it
                              does not yet improve on depth alone) */
  int colour_with_encoder; /* 1: the photometric term on the encoder's views too */
  double aim_prior;        /* weight, per match a view has, of the aim term:
                              the axis point the cameras aim at (unknown, per
                              state) held at one place (unknown) in every
                              camera's frame; 0: off; default 0.1 */
  double aim_depth_tol;    /* that place's spread along the optical axis, a
                              share of its distance (one sigma); default 0.012
                              (the virtual rig's +-2% distance jitter) */
  double aim_side_m;       /* its spread across the optical axis (m); default
                              0.0005 */
  int aim_per_ring;        /* 1: one place per ring (rings aimed at different
                              points); 0 (default): one for all views */
  double aim_height_tol;   /* the aimed-at point's height held to half the
                              object's top within this share of the top (and
                              at least 2 mm); 0: free; default 0.6 */
  /* the tilt of the views whose depth shows no table, or a weak one (a
     thin band), weights per match a view has, per squared radian: */
  double wall_prior;      /* the normal of the wall (backdrop) such a view sees
                             held horizontal (the wall taken as vertical); 0:
                             off, and a view that borrows its ring's plane is
                             held to it; default 1 */
  double roll_prior;      /* its table normal (R^T e_z) held normal to the
                             rig's tilt axis in the camera frame (from the
                             views with a table: the rig tilts its cameras
                             about one axis, level when its aim has no roll);
                             0: off; default 1 */
  double ring_tilt_prior; /* its ring's views' R^T e_z held to their mean (one
                             tilt a ring), where such a view sees no wall;
                             0 (default): off, as the virtual rig jitters
                             each view's elevation by up to 0.7 degrees */
  int threads;            /* 0: hearth_default_threads() */
  int quiet;              /* 1: no progress on stderr */
} hearth_turntable_opts;
void hearth_turntable_opts_default(hearth_turntable_opts *o);

typedef struct hearth_turntable_view {
  char state[HEARTH_NAME_MAX], view[HEARTH_NAME_MAX];
  size_t n_points;      /* object points of its depth map */
  size_t n_plane;       /* table-plane inliers (0: its ring's plane taken) */
  double plane_rms_mm;  /* their distance to the plane */
  double height_m;      /* camera centre above the turntable top */
  double elevation_deg; /* of the optical axis below the horizon */
  size_t n_pairs;       /* views it was registered with */
  size_t n_matches;     /* ICP correspondences at the end (as source) */
  double icp_rms_mm;    /* their point-to-plane distances at the end */
  double d_azimuth_deg; /* ICP's change of its azimuth from the nominal one */
} hearth_turntable_view;

typedef struct hearth_turntable_result {
  size_t n_views;
  hearth_turntable_view *views; /* owned, in the poses' order; free with
                                   hearth_turntable_result_free */
  size_t n_pairs;               /* ordered view pairs of the ICP */
  int iterations;
  double icp_rms_start_mm, icp_rms_mm; /* over all matches, first and last iteration */
  double icp_median_mm;                /* |distance| median at the end */
  size_t n_encoder_views;              /* views held to a recorded turntable angle */
  size_t n_colour_views;               /* views with the photometric term */
  size_t n_ring_plane_views;           /* views whose depth showed no table the
                                          object stands on: their elevation's
                                          mean plane taken */
  size_t n_free_ring_views;            /* views of a ring where no view showed
                                          a table: levelled by the wall they
                                          see or the other rings' elevations
                                          extrapolated, no plane term */
  size_t n_wall_views;                 /* views levelled by the wall (backdrop) they see:
                                without a table or with a weak one */
  size_t n_wall_check_views;           /* views that see both the table and a wall */
  double wall_tilt_deg;                /* the median of their walls' departure from
                                vertical (NAN when none): over 1 degree, no
                                wall is taken as vertical (n_wall_views 0) */
  double seconds;
  /* the aim term's estimate (hearth_turntable_aim_state and _place at the
   * end of this header; none when the term is off): per state, per place
   * (one, or one per ring) */
  size_t n_aim_states, n_aim_places;
  struct hearth_turntable_aim_state *aim_states; /* owned */
  struct hearth_turntable_aim_place *aim_places; /* owned */
} hearth_turntable_result;
void hearth_turntable_result_free(hearth_turntable_result *r); /* accepts a zeroed one */

/* Colour poses of every view of the states (NULL/0: every state of
 * instance.json) of `instance` under `root`, sorted by state (instance.json
 * order) and view (manifest order). A view without a depth map, an empty
 * cut-out or a depth map with too few object points is an error naming the
 * file; a view whose depth shows no plane the object stands on takes the
 * mean plane of its elevation's views, and a wall (backdrop) it sees
 * levels it; a ring where no view has one is started from the other rings
 * (an error when no view at all has one). The
 * gauge is the mean camera position of the start, no view is held. res may
 * be NULL. */
hearth_status hearth_recon_turntable(const char *root, const char *instance,
                                     const char *const *states, size_t n_states,
                                     const hearth_turntable_opts *opts, hearth_poses *out,
                                     hearth_turntable_result *res, hearth_err *err);

/* ---- UV atlas (recon_atlas.c) ---------------------------------------------- */
/* A UV atlas for a triangle mesh, one island per chart:
 *  - charts: each face goes to the nearest of six directions (k-means on
 *    the area-weighted face normals, smoothed over their neighbours,
 *    started at +-x, +-y, +-z), each label
 *    is split into edge-connected components, components under
 *    min_chart_faces faces join the neighbour they share most edges with;
 *  - a chart that is not a topological disc (connected, manifold, one
 *    boundary loop, Euler characteristic 1) is cut in two at the median of
 *    its face centroids along its longest extent, and its pieces are
 *    charted again (a band around a cylinder becomes two discs);
 *  - each disc is flattened by least squares conformal maps (LSCM: two
 *    rows per triangle, the Cauchy-Riemann residuals weighted by the root
 *    of its area; two vertices far apart pinned at their places in the
 *    chart's mean plane; conjugate gradients on the normal equations with
 *    a Jacobi preconditioner, in double, sequential); a flattening with a
 *    folded triangle, a boundary that meets itself, or more stretch than
 *    max_chart_stretch / max_face_stretch allow is cut as above and tried
 *    again (one triangle always works);
 *  - charts of at most 16 faces (mostly left by the cuts) join the
 *    neighbouring chart (of at most 1024 faces) they share most edges
 *    with, where the two still flatten as one within the limits above;
 *  - every chart is scaled to the same texel density (UV area proportional
 *    to 3-D area) and turned to its minimal-area bounding box (rotating
 *    calipers on its convex hull) lying wide; then packed into the unit
 *    square by the better (larger density) of two packers: its box in
 *    shelves (tallest first), or its own shape rasterised conservatively
 *    on a grid of min(texture_size, 512) cells (per row the hull of the
 *    cells its triangles touch), grown by the gutter and placed largest
 *    box first where it meets no chart placed before and reaches least
 *    far down, as it lies or turned a quarter. Either way any two charts,
 *    and each chart and the border, are at least gutter_texels /
 *    texture_size apart in UV, at the largest density that fits
 *    (bisection).
 * The output has the input's triangles in the input's order; a vertex is
 * repeated once per chart it belongs to (vertices in chart order, then by
 * first use). Deterministic: no threads, no randomness. */
typedef struct hearth_atlas_opts {
  size_t min_chart_faces;   /* default 8 */
  int kmeans_iterations;    /* default 4; 0: the six axes as they are */
  int smooth_passes;        /* face normals averaged with their neighbours'
                             this many times before clustering; default 3 */
  int texture_size;         /* texels per side the gutter is counted in; default 1024 */
  double gutter_texels;     /* default 4 */
  int cg_max_iterations;    /* per chart; default 4000 */
  double max_chart_stretch; /* a chart's L2 stretch over its own area above
                               this cuts it; default 1.1 */
  double max_face_stretch;  /* so does one triangle's; default 2 */
} hearth_atlas_opts;
void hearth_atlas_opts_default(hearth_atlas_opts *o);

/* Distortion of the map from the surface to UV, over non-degenerate
 * triangles, after removing the atlas's common scale (so an isometry up to
 * scale gives stretch 1, area 0, angle 0). Per triangle, the singular
 * values s1 >= s2 of the Jacobian from UV to the surface: L2 stretch
 * sqrt((s1^2 + s2^2) / 2) (Sander, Snyder, Gortler, Hoppe 2001). */
typedef struct hearth_atlas_stats {
  size_t n_charts;
  size_t n_splits;             /* charts cut because they were no disc or folded */
  size_t n_merges;             /* small charts merged into a neighbour */
  double stretch_l2;           /* the mesh's L2 stretch: sqrt(area-weighted mean of L2^2) */
  double stretch_l2_max;       /* largest per-triangle L2 stretch */
  double stretch_l2_chart_max; /* largest chart's L2 stretch (over its own area) */
  double area_distortion;      /* area-weighted mean of |ln(s1 s2)| */
  double angle_distortion;     /* area-weighted mean of ln(s1 / s2) */
  double packing_efficiency;   /* UV area of the triangles / area of the unit square */
  int cg_iterations_max;       /* most CG iterations one chart took */
} hearth_atlas_stats;

/* Atlas of in (positions and indices; UVs and texture ignored) into out
 * (allocated; positions, UVs, indices, no texture). chart_of_tri (NULL or
 * the caller's in->n_triangles entries) receives each triangle's chart.
 * stats may be NULL. opts NULL: the defaults. Empty mesh: HEARTH_E_ARG. */
hearth_status hearth_mesh_atlas(const hearth_mesh *in, const hearth_atlas_opts *opts,
                                hearth_mesh *out, uint32_t *chart_of_tri, hearth_atlas_stats *stats,
                                hearth_err *err);

/* ---- hearth recon ROOT (recon_run.c) -------------------------------------- */
/* The embedded route over one instance: colour poses by
 * hearth_recon_turntable, written as recon/poses_rgb.json with the factory
 * colour camera beside it (recon/poses_rgb_cameras.json, as the COLMAP
 * route writes), then the metric mesh from the depth maps with those poses
 * (hearth_recon_tsdf) as recon/mesh_geometry.glb (no UVs), its UV atlas
 * (hearth_mesh_atlas) as recon/mesh.glb (UVs, no texture: map --rgb bakes
 * the colour texture into derived/), and recon/report.json:
 *   {"instance", "route": "turntable", "views": N, "pairs", "iterations",
 *    "encoder_views", "colour_views", "ring_plane_views", "icp_rms_start_mm", "icp_rms_mm",
 *    "icp_median_mm",
 *    "aim": null (the term off) or {"weight", "axis_direction": [0, 0, 1],
 *            "states": [{"state", "views", "point_m", "axis_m",
 *                        "sigma_along_mm", "sigma_across_mm" (null: not had)}],
 *            "places": [{"ring" (null: every ring), "views", "camera_m",
 *                        "distance_m", "side_rms_mm", "depth_rms_mm",
 *                        "depth_rms_rel"}]},
 *    "mesh": {"vertices", "triangles", "voxel_m"},
 *    "atlas": {"charts", "merged", "stretch_l2", "stretch_l2_max",
 *              "stretch_l2_chart_max", "area_distortion", "angle_distortion",
 *              "packing_efficiency"},
 *    "per_view": [{"state", "view", "points", "plane_inliers",
 *                  "plane_rms_mm", "height_m", "elevation_deg", "pairs",
 *                  "matches", "icp_rms_mm", "d_azimuth_deg"}]}
 * (docs/dataset.md; hearth validate checks it against the files beside it).
 * Every file is written atomically; an existing recon/poses_rgb.json is
 * kept (HEARTH_E_ARG, as the COLMAP route does) unless force; so are a
 * recon/mesh.glb and recon/rgb_texture.png another tool handed over (in
 * its frame), which force removes. */
typedef struct hearth_recon_job {
  const char *root, *instance;
  hearth_turntable_opts poses;
  hearth_recon_tsdf_opts geometry; /* .poses is set by the job */
  hearth_atlas_opts atlas;
  int no_mesh; /* 1: poses and report only */
  int force;
  int quiet;
} hearth_recon_job;
void hearth_recon_job_default(hearth_recon_job *job);

typedef struct hearth_recon_summary {
  hearth_turntable_result poses; /* owned: hearth_recon_summary_free */
  size_t mesh_vertices, mesh_triangles;
  hearth_atlas_stats atlas; /* of recon/mesh.glb */
  char poses_path[1400], mesh_path[1400], atlas_path[1400], report_path[1400];
} hearth_recon_summary;
void hearth_recon_summary_free(hearth_recon_summary *s);
hearth_status hearth_recon_run(const hearth_recon_job *job, hearth_recon_summary *sum,
                               hearth_err *err);

/* ---- the aim point (recon_turntable.c) ------------------------------------ */
/* What the aim term of hearth_recon_turntable estimated, after its last
 * iteration (the poses' frame: metres, +z up the turntable axis, the top at
 * z = 0). The axis is +z by construction; the aimed-at point C lies on it,
 * so the axis is the vertical line through C. */
typedef struct hearth_turntable_aim_state {
  char state[HEARTH_NAME_MAX];
  size_t n_views;    /* the state's views in the term */
  double point_m[3]; /* C, the axis point the cameras aim at */
  double axis_m[3];  /* where the axis meets the turntable top: (Cx, Cy, 0) */
  /* C's standard deviation along the axis (its height) and across it (per
   * horizontal direction): the aim term linearised in C, P and a free
   * radius per ring (what the depth barely fixes about a surface of
   * revolution), each view weighted by its place's fitted spread, with the
   * height prior; NAN where it cannot be had (docs/dataset.md) */
  double sigma_along_m, sigma_across_m;
} hearth_turntable_aim_state;

/* P, C's place in the colour camera's frame, and its fitted spread: per
 * view the residual r = R^T (C - t) - P (C in that view's frame, less P),
 * across the optical axis sqrt(mean(rx^2 + ry^2)), along it sqrt(mean(rz^2))
 * (in metres and as a share of |P|). */
typedef struct hearth_turntable_aim_place {
  int elevation_index;  /* its ring; -1: one place for every ring */
  size_t n_views;       /* views in the term at that place */
  double camera_m[3];   /* P */
  double side_rms_m;    /* spread across the optical axis */
  double depth_rms_m;   /* spread along it */
  double depth_rms_rel; /* depth_rms_m / |P| */
} hearth_turntable_aim_place;

#ifdef __cplusplus
}
#endif

#endif
