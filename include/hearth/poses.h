/* hearth/poses.h - area poses (src/poses/): metric scale recovery from depth
 * maps, pose transfer through the rig, automatic thermal-pose refinement
 * and alignment overlays (the paper's "scale recovery" and its manual
 * per-view refinement, made automatic).
 *
 * Frames: recon/ is the reconstruction frame at unknown scale; a point
 * x_recon is at s * x_recon metres (docs/conventions.md). Depth PNGs hold z
 * along the depth camera's +z axis in millimetres, 0 = no measurement. */
#ifndef HEARTH_POSES_H
#define HEARTH_POSES_H

#include <stddef.h>
#include "hearth/camera.h"
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/image.h"
#include "hearth/map.h"
#include "hearth/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- scale ----------------------------------------------------------------- */
/* One depth frame: the recorded depth (U16, 1 channel, mm), its per-frame
 * intrinsics and factory extrinsic (metres), and the colour camera's pose in
 * the reconstruction frame (recon units). */
typedef struct hearth_scale_view {
  const hearth_image *depth;
  hearth_camera depth_cam;
  hearth_rigid T_depth_from_rgb;
  hearth_rigid T_world_from_rgb;
} hearth_scale_view;

typedef struct hearth_scale_opts {
  int pixel_stride;        /* cast every k-th depth pixel in x and y; default 2 */
  double edge_rel;         /* neighbour depth jump (relative) marking an edge; default 0.02 */
  double inlier_sigmas;    /* inlier band in robust sigmas; default 3 */
  double min_band_mm;      /* the band is at least this wide; default 1 */
  int min_pixels_per_view; /* a view counts as used with this many inliers; default 50 */
  int threads;             /* 0 = hearth_default_threads() */
} hearth_scale_opts;
void hearth_scale_opts_default(hearth_scale_opts *o);

typedef struct hearth_scale_result {
  double scale; /* metres per recon unit */
  int views_used;
  size_t n_candidates; /* pixels with a measurement and a rendered surface, off edges */
  size_t n_inliers;
  double residual_median_mm; /* median |z_measured - s z_rendered| over inliers */
  double residual_rms_mm;    /* over inliers */
  double residual_p90_mm;    /* over inliers */
  double inlier_fraction;
  int iterations; /* outer (baseline) rounds used, coarse and full grid */
} hearth_scale_result;

/* Robust scale: per pixel, z_measured / z_rendered of the recon mesh, edges,
 * holes and background excluded, trimmed least squares around the median.
 * The depth camera's centre depends on s through the metric baseline, so
 * the cast is repeated until s settles. Deterministic for any thread count. */
hearth_status hearth_scale_estimate(const hearth_mesh *recon_mesh, const hearth_raycaster *rc,
                                    const hearth_scale_view *views, size_t n_views,
                                    const hearth_scale_opts *opts, hearth_scale_result *out,
                                    hearth_err *err);

/* hearth scale: reads recon/{mesh.glb, poses_rgb.json, rgb_texture.png} and
 * raw/<state>/{manifest.json, depth/}; writes derived/scale.json,
 * derived/mesh.glb (metric, RGB texture embedded) and derived/poses_rgb.json. */
typedef struct hearth_scale_job {
  const char *root;
  const char *instance;
  const char *state; /* NULL: depth frames of every state */
  hearth_scale_opts opts;
} hearth_scale_job;
/* Defaults: every state, hearth_scale_opts_default. */
void hearth_scale_job_default(hearth_scale_job *job);
hearth_status hearth_scale_run(const hearth_scale_job *job, hearth_scale_result *res,
                               hearth_err *err);

/* ---- refinement ------------------------------------------------------------ */
typedef struct hearth_refine_opts {
  double search_px;      /* first edge-search half window; default 14 */
  int iterations;        /* Gauss-Newton iterations; default 12 */
  size_t max_samples;    /* silhouette samples per iteration; default 400 */
  double min_contrast_c; /* |object - background| below this: pose kept; default 1.5 */
  double max_rot_deg;    /* refinement may move the pose at most this far; default 3 */
  double max_t_mm;       /* default 15 */
  int threads;           /* over views; 0 = hearth_default_threads() */
} hearth_refine_opts;
void hearth_refine_opts_default(hearth_refine_opts *o);

typedef struct hearth_refine_view_result {
  hearth_rigid T_world_from_cam;    /* the returned pose (start unless accepted) */
  int accepted;                     /* 1: refined pose replaced the start */
  double cost_start, cost_final;    /* the criterion (mean truncated squared edge distance, px^2) */
  double d_rot_deg, d_t_mm;         /* change from the start */
  double contrast_c;                /* median object - background across the contour */
  double confidence;                /* 0..1: inlier fraction x conditioning */
  double sigma_rot_deg, sigma_t_mm; /* weakest-direction standard deviations */
  size_t n_samples, n_inliers;
  double seconds;
  char reason[96]; /* why a pose was kept, or "refined" */
} hearth_refine_view_result;

/* Refine each view's T_world_from_cam (views[i].image: F32 temperatures)
 * against the metric mesh; out is the caller's array of n_views results.
 * Views are independent and run in parallel; output i depends only on view
 * i. opts may be NULL (the defaults). */
hearth_status hearth_refine_views(const hearth_mesh *mesh, const hearth_raycaster *rc,
                                  const hearth_camera *cam, const hearth_map_view *views,
                                  size_t n_views, const hearth_refine_opts *opts,
                                  hearth_refine_view_result *out, hearth_err *err);

/* The criterion of hearth_refine_views at a given pose (for tests/tools). */
hearth_status hearth_refine_cost(const hearth_mesh *mesh, const hearth_raycaster *rc,
                                 const hearth_camera *cam, const hearth_image *image,
                                 const hearth_rigid *T_world_from_cam, double *cost,
                                 hearth_err *err);

/* A manual nudge in the camera's frame: T' = T * (R(d_rot), d_t). */
typedef struct hearth_pose_nudge {
  char state[64], view[64];
  double d_rot_deg[3];
  double d_t_mm[3];
} hearth_pose_nudge;
void hearth_pose_nudge_apply(const hearth_pose_nudge *n, hearth_rigid *T_world_from_cam);
/* "STATE/VIEW:rx,ry,rz,tx,ty,tz" (degrees, millimetres). */
hearth_status hearth_pose_nudge_parse(const char *text, hearth_pose_nudge *out, hearth_err *err);
/* {"views": [{"state", "view", "d_rot_deg": [3], "d_t_mm": [3]}]}; *out
 * malloc'ed (n entries, the caller frees it with free()). */
hearth_status hearth_pose_nudges_read(const char *path, hearth_pose_nudge **out, size_t *n,
                                      hearth_err *err);

/* hearth refine: one instance (one state or all). Starts from
 * derived/poses_thermal_transferred.json, writes derived/poses_thermal.json
 * (views of other states are kept from the existing file, else the start)
 * and derived/refine_report.json. */
typedef struct hearth_refine_job {
  const char *root;
  const char *instance;
  const char *state;       /* NULL: all states */
  const char *mesh_path;   /* NULL: derived/mesh.glb */
  const char *rig_path;    /* NULL: calibration/rig.json */
  const char *start_path;  /* NULL: derived/poses_thermal_transferred.json */
  const char *out_path;    /* NULL: derived/poses_thermal.json */
  const char *report_path; /* NULL: derived/refine_report.json */
  int no_auto;             /* 1: only apply nudges */
  const hearth_pose_nudge *nudges;
  size_t n_nudges;
  /* evaluation only: perturb the start poses (random, seeded) and/or
     report reprojection errors against true poses */
  double perturb_deg, perturb_mm;
  uint64_t perturb_seed;
  const char *truth_path;
  hearth_refine_opts opts;
} hearth_refine_job;
void hearth_refine_job_default(hearth_refine_job *job);

typedef struct hearth_refine_summary {
  size_t n_views, n_accepted;
  double mean_seconds_per_view;
  /* with truth_path: mean over views of the mean reprojection error of
     visible surface points, start and final */
  double reproj_start_px, reproj_final_px, reproj_final_max_px;
} hearth_refine_summary;
hearth_status hearth_refine_run(const hearth_refine_job *job, hearth_refine_summary *sum,
                                hearth_err *err);

/* Mean reprojection error (px) between two poses of the camera over the
 * surface points visible from T_a (cast every `stride`-th pixel). */
hearth_status hearth_reprojection_error(const hearth_raycaster *rc, const hearth_camera *cam,
                                        const hearth_rigid *T_a, const hearth_rigid *T_b,
                                        int stride, double *mean_px, hearth_err *err);

/* ---- overlays -------------------------------------------------------------- */
/* Render the mesh outline (silhouette and depth edges) of a pose onto a
 * Turbo-coloured thermal image, upscaled by `zoom`; colour rgb. Temperature
 * range [lo, hi] degC; lo >= hi picks the 2..98 % range of the image. out
 * is a new RGB U8 image (the caller frees it with hearth_image_free). */
hearth_status hearth_overlay_render(const hearth_raycaster *rc, const hearth_camera *cam,
                                    const hearth_image *temps, const hearth_rigid *T_world_from_cam,
                                    int zoom, double lo, double hi, const uint8_t rgb[3],
                                    hearth_image *out, hearth_err *err);

/* hearth overlay: derived/overlay/<state>/vNN.png (after, with before in a
 * second colour) and derived/overlay/<state>/contact_sheet.png (cells at
 * the camera's pixels: a pixel is on the outline when one of its zoom x
 * zoom sub-pixels is). Both are stored by hearth_png_write_picture. */
typedef struct hearth_overlay_job {
  const char *root, *instance, *state;
  const char *mesh_path, *rig_path;
  const char *before_path; /* NULL: derived/poses_thermal_transferred.json */
  const char *after_path;  /* NULL: derived/poses_thermal.json */
  int zoom;                /* default 3 */
  double lo, hi;           /* default auto */
  int threads;
} hearth_overlay_job;
/* Defaults: every state, zoom 3, automatic temperature range, all cores. */
void hearth_overlay_job_default(hearth_overlay_job *job);
hearth_status hearth_overlay_run(const hearth_overlay_job *job, size_t *n_written, hearth_err *err);

/* ---- transfer: stage over a release tree (layout: docs/dataset.md) --------- */
/* hearth transfer: T_world_from_th = T_world_from_rgb * inverse(T_th_from_rgb)
 * for every view of every state. Reads derived/poses_rgb.json and
 * calibration/rig.json (rig_path overrides); writes
 * derived/poses_thermal_transferred.json and, unless a refined
 * derived/poses_thermal.json newer than it exists or keep_refined is 0,
 * derived/poses_thermal.json. */
typedef struct hearth_transfer_job {
  const char *root;
  const char *instance;   /* required */
  const char *rig_path;   /* NULL: <root>/calibration/rig.json */
  const char *poses_path; /* NULL: <root>/instances/<id>/derived/poses_rgb.json */
  int keep_refined;       /* 1: do not overwrite a refined poses_thermal.json */
} hearth_transfer_job;
/* Defaults: the standard paths, keep_refined 0. */
void hearth_transfer_job_default(hearth_transfer_job *job);
hearth_status hearth_transfer_run(const hearth_transfer_job *job, hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
