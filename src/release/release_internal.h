/* private to the release area */
#ifndef HEARTH_RELEASE_INTERNAL_H
#define HEARTH_RELEASE_INTERNAL_H

#include "hearth/dataset.h"
#include "hearth/mesh.h"
#include "hearth/release.h"

/* The parameters of a build that shape its outputs, as build.json at the
 * release root records them (docs/dataset.md). */
typedef struct hb_params {
  size_t resolution; /* temperature maps, 2..16384 */
  hearth_fusion fusion;
  double min_cos;        /* [0, 1) */
  size_t rgb_resolution; /* baked colour texture, 16..16384 */
  int bake_rgb, calibrate, calib_overlays;
} hb_params;
/* 1024, max, 0, 1024, bake, calibrate, overlays */
void hb_params_default(hb_params *p);
int hb_params_same(const hb_params *a, const hb_params *b);
hearth_status hb_params_parse(const char *text, size_t len, const char *name, hb_params *p,
                              hearth_err *err);
hearth_status hb_params_read(const char *path, hb_params *p, hearth_err *err);
/* Atomic; the same parameters give the same bytes. */
hearth_status hb_params_write(const char *path, const hb_params *p, hearth_err *err);

/* Fill stages[] (at most max) with the calibration stages that apply to
 * root: detect + calibrate when calibration/captures/ exists; returns how
 * many. overlays: detection writes its overlay pictures. */
size_t hb_calib_stages(const char *root, int overlays, hearth_build_stage *stages, size_t max);

/* The contact picture of instance/state of a built release (release_picture.c):
 * derived/mesh.glb from four viewpoints, colour texture above, the state's
 * Turbo texture below, as a 1024 x 512 PNG at out_path. */
hearth_status hb_contact_picture(const char *root, const char *inst, const char *state,
                                 const char *out_path, hearth_err *err);

/* The errors of one state's observed map o[] (R x R, the map's UV layout,
 * texels with mask m[] == 1) against the apparent truth a[] and the true
 * temperature t[], and the classes of the worst 5 % (release_report.c):
 * grazing (away[i] == 0, or without away c[3i] < 0.5), reflections
 * (c[3i+1] > 0), cooling (c[3i+2] > 1), registration (a[] changes by at
 * least the worst-5 % threshold within 2 texels) and none. Fills e's
 * has_apparent, n_away, app_*, away_true_* and worst_* fields. */
hearth_status hb_report_effects(const uint8_t *m, const float *o, const float *t, const float *a,
                                const float *c, const uint8_t *away, size_t R,
                                hearth_report_entry *e, hearth_err *err);

/* recon/report.json checked against what lies beside it (release_recon_check.c,
 * hearth validate): what is known of the instance; a member left NULL or -1
 * is not compared. */
typedef struct hb_recon_expect {
  const char *instance; /* instance.json's id */
  size_t n_states;
  const char *const *states;               /* instance.json's states */
  const hearth_manifest *manifests;        /* one per state (n_views 0: unreadable), or NULL */
  long long manifest_views;                /* all the manifests' views, -1: unknown */
  const hearth_poses *poses;               /* recon/poses_rgb.json, or NULL */
  long long mesh_vertices, mesh_triangles; /* recon/mesh_geometry.glb's, -1: not read */
  long long mesh_open_loops;               /* its boundary loops, -1: not read */
  long long atlas_charts;                  /* recon/mesh.glb's UV islands, -1: not read */
} hb_recon_expect;
/* Every problem of the report text[0..len) (as "MEMBER: what" under path)
 * into p; a text that does not parse is one problem naming its line and
 * column. */
void hb_recon_report_check(const char *text, size_t len, const char *path, const hb_recon_expect *x,
                           hearth_problems *p);
/* The UV islands of a mesh: components of its triangles over shared
 * vertices (hearth's atlas: one per chart); -1 out of memory. */
long long hb_mesh_islands(const hearth_mesh *m);

/* The truth at point q of a true mesh (release_truth.c): the map (Rg x Rg,
 * `stride` floats a texel, channel `ch`) read bilinearly at uv between the
 * four texel centres around it. A texel counts only where it holds a finite
 * value and its own surface point (pos[3 * texel], NaN where the UV layout
 * has no surface there) lies within `reach` metres of q, so a texel of
 * another island beside it in the atlas does not bleed in; the weights of
 * those that count are renormalised. NaN when none counts. */
double hb_truth_sample(const float *map, size_t Rg, size_t stride, size_t ch, const float *pos,
                       const double q[3], const double uv[2], double reach);

#endif
