/* hearth/map.h - area map (src/map/): temperature (and colour) mapping from
 * camera views onto a mesh's UV layout: the paper's "Temperature Mapping and
 * Thermal Textures".
 *
 * For each view, every pixel's undistorted centre is cast into the scene
 * (by rasterising the mesh through the camera's ray fan when the whole mesh
 * lies in front of the view, by tracing rays otherwise; see
 * include/hearth/mesh.h); the nearest front-facing surface takes that
 * pixel's raw value unchanged, splatted with bilinear weights into an
 * R x R UV map. Within a view,
 * contributions are averaged by weight; across views they are fused (the
 * paper's maximum by default). Unobserved surface texels are then filled
 * from the nearest observed texel of the same UV island. Conventions:
 * docs/conventions.md (UV row 0 at v = 0, texel centre (col+0.5)/R). */
#ifndef HEARTH_MAP_H
#define HEARTH_MAP_H

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

typedef enum hearth_fusion {
  HEARTH_FUSE_MAX = 0,    /* paper: upper envelope of the per-view means */
  HEARTH_FUSE_ROBUST = 1, /* silhouette pixels rejected, weighted median over views */
  HEARTH_FUSE_MEAN = 2,   /* weighted mean over views (colour textures) */
  /* ROBUST's silhouette rejection and weighted median, made aware of the
     capture's physics: views far from a texel's best viewing angle are
     dropped and the rest weighted by cos^4, each reading's excess over
     ambient (the median of the images' borders) is referred to the normal
     with a typical dielectric's Fresnel fall-off, and brought back to the
     start of the scan with a Newton cooling rate estimated from the views'
     times, passes and readings (docs/virtual-rig.md, "Which fusion") */
  HEARTH_FUSE_CORRECTED = 3
} hearth_fusion;

/* Mask values of a map (also the values of mask.npy). */
enum {
  HEARTH_TEXEL_NONE = 0, /* no surface at this texel */
  HEARTH_TEXEL_OBSERVED = 1,
  HEARTH_TEXEL_FILLED = 2,
  HEARTH_TEXEL_UNOBSERVED = 3 /* surface, but its island was never observed */
};

typedef struct hearth_map_opts {
  size_t resolution;    /* R; default 1024 */
  hearth_fusion fusion; /* default HEARTH_FUSE_MAX */
  double min_cos;       /* reject hits seen more obliquely than this cosine; default 0 */
  int pixel_stride;     /* cast every k-th pixel in x and y (colour baking); default 1 */
  int keep_edges;       /* 1: also use pixels at depth discontinuities (the paper's literal
                             rule); default 0: such pixels mix two surfaces through the
                             lens blur and are skipped (always skipped by ROBUST) */
  int threads;          /* 0 = hearth_default_threads() */
  int trace_rays;       /* 1: trace every view's rays (Embree) even where the fan could
                             rasterise it; default 0 (the same hits up to float rounding) */
  int skip_best_cos;    /* 1: leave the result's best_cos NULL, saving an R*R map per
                             worker; default 0 */
  int skip_observed;    /* 1: leave the result's observed NULL: the filled map is made in
                             its place, saving an R*R*channels map; default 0 */
  /* Views whose image is NULL have it made by load(load_ctx, v, &img, err)
     when their cast reaches them (a U8 RGB or F32 gray image of the
     camera's size, freed by the mapping after the view's splat), so that a
     worker holds one view's image at a time. load_channels is their kind
     (3: U8 RGB, 1: F32 gray). A failed load fails the mapping with the
     error of the lowest view that failed; NULL load: every view needs its
     image. */
  hearth_status (*load)(void *load_ctx, size_t view, hearth_image *img, hearth_err *err);
  void *load_ctx;
  int load_channels;
  /* 1: load makes only the pixels the mapping reads, the grid of every
     pixel_stride-th pixel: an image of ceil(width / stride) x
     ceil(height / stride) whose pixel (x, y) is the camera's pixel
     (x * stride, y * stride); 0 (default): the camera's whole image */
  int load_grid;
  /* viewing cosines (the corrected fusion's emissivity fall-off, its choice
     of views and weights) from each triangle's normal averaged this many
     times over the triangles that share a vertex with it (by position, across
     UV seams; area-weighted; neighbours more than 60 degrees off left out),
     instead of its own normal: a mesh fused from depth has noise in its face
     normals at the voxel scale, which biases the fall-off correction; the
     surface itself and which hits count are unchanged. 0 (default): the face
     normals; hearth_map_job_default sets HEARTH_MAP_NORMALS_AUTO */
  int normal_passes;
  /* drop, with the silhouette pixels (the fusions that drop those: robust,
     corrected, or keep_edges 0), a pixel whose 3 x 3 neighbourhood hits
     faces whose normals lie more than this many degrees apart: at a crease
     the thermal pixel mixes two surfaces as at a silhouette, and where a
     mesh fused from depth rounds the crease over a voxel or two, a pixel
     that sees one side lands on the other (the hot kettle's body read onto
     its cooler base). 0 (default): none; hearth_map_job_default sets
     HEARTH_MAP_CREASE_AUTO */
  double crease_deg;
} hearth_map_opts;
/* hearth_map_run: 60 degrees where HEARTH_MAP_NORMALS_AUTO gives 2 passes
   (a mesh hearth fused from depth), else 0 */
#define HEARTH_MAP_CREASE_AUTO (-1.0)
/* hearth_map_run: 2 passes when the instance's recon/report.json records a
   mesh hearth fused from depth (its "mesh" member) and the job names no mesh
   of its own, else 0 */
#define HEARTH_MAP_NORMALS_AUTO (-1)
void hearth_map_opts_default(hearth_map_opts *o);

/* One view: an image (F32 1-channel temperatures, or U8 RGB colour) and the
 * camera's pose. Images are read, never modified. */
typedef struct hearth_map_view {
  const hearth_image *image;
  hearth_rigid T_world_from_cam;
  double time_s; /* when it was taken (s from the state's preparation); only
                    HEARTH_FUSE_CORRECTED reads it; all 0: no cooling correction */
  int pass;      /* the pass it belongs to (the manifest's elevation index): the
                    cooling rate is estimated within passes; 0 for all: one */
} hearth_map_view;

typedef struct hearth_map_result {
  size_t R;
  int channels;        /* 1 for temperature, 3 for colour */
  float *observed;     /* R*R*channels; NaN where mask != OBSERVED; NULL with
                                 opts.skip_observed */
  float *filled;       /* R*R*channels; NaN where mask not in {OBSERVED, FILLED} */
  uint8_t *mask;       /* R*R, HEARTH_TEXEL_* */
  float *best_cos;     /* R*R: largest viewing cosine among observing views (0 if none);
                                 NULL with opts.skip_best_cos */
  uint32_t *view_hits; /* n_views: pixels of each view that landed on the surface */
  size_t n_views;
  size_t n_surface, n_observed, n_filled, n_unobserved;
} hearth_map_result;
/* A result owns its arrays (filled by the mapping functions); this frees
 * them and zeroes r, and accepts a zeroed result. */
void hearth_map_result_free(hearth_map_result *r);

/* Map n views seen by one camera model onto mesh (which must have UVs).
 * rc is a ray caster built over the same mesh, or NULL to build one here
 * if a view needs rays. opts may be NULL (the defaults). out is filled (the
 * caller frees it with hearth_map_result_free); values are in the views'
 * units (degC, or colour 0..255).
 * Deterministic: the same bytes for any thread count. */
hearth_status hearth_map_views(const hearth_mesh *mesh, const hearth_raycaster *rc,
                               const hearth_camera *cam, const hearth_map_view *views,
                               size_t n_views, const hearth_map_opts *opts, hearth_map_result *out,
                               hearth_err *err);

/* Time spent in each phase (seconds), for benchmarks. hearth_map_views_timed
 * fills raster (UV raster and islands, with the pixel grid and its fan made
 * beside them), cast (casting and splatting), fuse, fill and total, and
 * build: the ray caster's construction where a view needs rays and none is
 * given (0 otherwise). hearth_map_run also fills read (inputs) and write
 * (outputs) and sets total to the whole run. */
typedef struct hearth_map_timing {
  double raster, cast, fuse, fill, total;
  double build, read, write;
} hearth_map_timing;
hearth_status hearth_map_views_timed(const hearth_mesh *mesh, const hearth_raycaster *rc,
                                     const hearth_camera *cam, const hearth_map_view *views,
                                     size_t n_views, const hearth_map_opts *opts,
                                     hearth_map_result *out, hearth_map_timing *timing,
                                     hearth_err *err);

/* The part of a mapping that depends only on the mesh, the camera and the
 * options' resolution and pixel stride (released with
 * hearth_map_layout_free, which accepts NULL): the UV raster and islands, the
 * triangles' normals, the mesh's bounding sphere, and the camera's pixel
 * grid with its ray fan. Made once, it serves any number of view sets of
 * that mesh and camera (the states of an instance), and it can be made
 * while the images are being read. The mesh must outlive it. */
typedef struct hearth_map_layout hearth_map_layout;
hearth_status hearth_map_layout_new(const hearth_mesh *mesh, const hearth_camera *cam,
                                    const hearth_map_opts *opts, hearth_map_layout **out,
                                    hearth_err *err);
void hearth_map_layout_free(hearth_map_layout *l);
/* hearth_map_views_timed on a layout (opts' resolution and pixel stride
 * must be the layout's: HEARTH_E_INCONSISTENT otherwise). timing->raster is
 * left as it is (the layout's time is the caller's to measure). */
hearth_status hearth_map_views_with_layout(const hearth_map_layout *l, const hearth_raycaster *rc,
                                           const hearth_map_view *views, size_t n_views,
                                           const hearth_map_opts *opts, hearth_map_result *out,
                                           hearth_map_timing *timing, hearth_err *err);

/* Copy the filled map into a new R x R RGB U8 image for a texture (the
 * caller frees it with hearth_image_free): Turbo over [lo, hi] degC for
 * temperatures (channels == 1) or the colour (channels == 3); texels without
 * a value are padded from neighbours for `pad` texels (so bilinear texture
 * lookups at island borders stay clean) and set to nan_rgb beyond. */
hearth_status hearth_map_texture(const hearth_map_result *r, double lo, double hi, int pad,
                                 const uint8_t nan_rgb[3], hearth_image *out, hearth_err *err);

/* ---- stages over a release tree (layout: docs/dataset.md); each writes its
 * outputs atomically: a stage that fails leaves the previous outputs (or none). */
/* hearth map: one state of one instance. */
typedef struct hearth_map_job {
  const char *root;
  const char *instance;
  const char *state;
  hearth_map_opts map;
  const char *mesh_path;     /* NULL: derived/mesh.glb */
  const char *poses_path;    /* NULL: derived/poses_thermal.json */
  const char *rig_path;      /* NULL: calibration/rig.json */
  const char *views;         /* NULL: all; else comma-separated view names */
  const char *out_dir;       /* NULL: derived/<state> */
  double turbo_lo, turbo_hi; /* 10, 60 */
  hearth_map_timing *timing; /* optional: phase times of the run */
} hearth_map_job;
void hearth_map_job_default(hearth_map_job *job);
/* stats (optional) receives the result's counters (arrays not kept). */
hearth_status hearth_map_run(const hearth_map_job *job, hearth_map_result *stats, hearth_err *err);

/* hearth map --rgb: bake the colour texture from the colour views into
 * derived/rgb_texture.png and embed it in derived/mesh.glb. Every input is
 * read before anything is written. */
typedef struct hearth_bake_job {
  const char *root;
  const char *instance;
  const char *state; /* which state's colour views (NULL: the first state) */
  size_t resolution; /* default 1024 */
  int pixel_stride;  /* default 2 */
  const char *mesh_path, *poses_path, *rig_path;
  int threads;
  const char *out_texture; /* NULL: derived/rgb_texture.png */
  const char *out_mesh;    /* NULL: derived/mesh.glb */
} hearth_bake_job;
/* Defaults: resolution 1024, pixel stride 2, all cores, the standard paths. */
void hearth_bake_job_default(hearth_bake_job *job);
hearth_status hearth_bake_rgb_run(const hearth_bake_job *job, hearth_err *err);

/* hearth map --rgb on one instance, all or nothing: the colour texture is
 * baked (bake) and the n_states states mapped (map, its state and out_dir
 * unused) into temporaries beside their places in derived/, which replace
 * the old outputs only when every step has succeeded; on failure every
 * output is as it was and no temporary is left. Temporaries of killed
 * earlier runs are removed first. stats (optional, n_states) receives each
 * state's counters; seconds (optional, n_states + 1) the bake's time, then
 * each state's; bake_peak_kib (optional) the process's peak resident memory
 * when the bake ended (KiB, getrusage): the bake runs first, so in a
 * process that has done nothing bigger before, the bake's own peak. */
hearth_status hearth_map_bake_run(const hearth_map_job *map, const hearth_bake_job *bake,
                                  const char *const *states, size_t n_states,
                                  hearth_map_result *stats, double *seconds, size_t *bake_peak_kib,
                                  hearth_err *err);

#ifdef __cplusplus
}
#endif
#endif
