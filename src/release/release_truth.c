/* Ground truth through surface correspondence: the virtual rig's true maps
 * (ground_truth/instances/<id>/<state>/ maps, in the true mesh's UV layout)
 * resampled onto the UV layout of the built derived/mesh.glb. Each texel's
 * surface point on the built mesh is taken into the truth's frame by the
 * similarity that best maps derived/poses_rgb.json onto the true colour
 * poses, matched to the nearest point of the true mesh (a uniform grid of
 * its triangles, exact point-triangle distances), and the truth maps are
 * read at that point's UV bilinearly, over the texels of the same stretch
 * of surface (hb_truth_sample): a nearest texel would put up to half a
 * texel of the truth's own grid into every comparison, 0.7 degC on the hot
 * cup's rim at 256 texels. Each texel also learns whether some thermal
 * view of the state (derived/poses_thermal.json, the rig's thermal camera)
 * sees it unoccluded, inside the frame, within 60 degrees of its normal. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "hearth/mesh.h"
#include "hearth/npy.h"
#include "hearth/recon.h"
#include "hearth/release.h"
#include "release_internal.h"

#define PATH_SZ 4096

void hearth_truth_match_free(hearth_truth_match *m) {
  if (!m) return;
  free(m->t_true);
  free(m->t_apparent);
  free(m->conditions);
  free(m->dist_m);
  free(m->away);
  memset(m, 0, sizeof *m);
}

/* ---- nearest point of a mesh: a uniform grid of its triangles -------------- */
typedef struct tri_grid {
  const hearth_mesh *m;
  double lo[3], cell;
  int n[3];
  size_t *start; /* n0*n1*n2 + 1 */
  uint32_t *tris;
} tri_grid;

static size_t cell_index(const tri_grid *g, int i, int j, int k) {
  return ((size_t)k * (size_t)g->n[1] + (size_t)j) * (size_t)g->n[0] + (size_t)i;
}

static int clampi(int x, int lo, int hi) { return x < lo ? lo : x > hi ? hi : x; }

/* cells of cell size (grown until the grid has at most 2^22 cells) */
static hearth_status grid_build(tri_grid *g, const hearth_mesh *m, double cell, hearth_err *err) {
  memset(g, 0, sizeof *g);
  g->m = m;
  double hi[3];
  hearth_mesh_bounds(m, g->lo, hi);
  size_t nc;
  for (;;) {
    for (int a = 0; a < 3; a++) g->n[a] = (int)((hi[a] - g->lo[a]) / cell) + 1;
    nc = (size_t)g->n[0] * (size_t)g->n[1] * (size_t)g->n[2];
    if (nc <= ((size_t)1 << 22)) break;
    cell *= 2;
  }
  g->cell = cell;
  g->start = calloc(nc + 1, sizeof *g->start);
  size_t *fill = calloc(nc, sizeof *fill);
  if (!g->start || !fill) goto nomem;
  for (int pass = 0; pass < 2; pass++) {
    for (size_t t = 0; t < m->n_triangles; t++) {
      int lo[3], up[3];
      for (int a = 0; a < 3; a++) {
        double mn = DBL_MAX, mx = -DBL_MAX;
        for (int c = 0; c < 3; c++) {
          double x = m->positions[3 * (size_t)m->indices[3 * t + c] + a];
          mn = x < mn ? x : mn;
          mx = x > mx ? x : mx;
        }
        lo[a] = clampi((int)((mn - g->lo[a]) / cell), 0, g->n[a] - 1);
        up[a] = clampi((int)((mx - g->lo[a]) / cell), 0, g->n[a] - 1);
      }
      for (int k = lo[2]; k <= up[2]; k++)
        for (int j = lo[1]; j <= up[1]; j++)
          for (int i = lo[0]; i <= up[0]; i++) {
            size_t c = cell_index(g, i, j, k);
            if (pass) g->tris[g->start[c] + fill[c]++] = (uint32_t)t;
            else g->start[c + 1]++;
          }
    }
    if (!pass) {
      for (size_t c = 0; c < nc; c++) g->start[c + 1] += g->start[c];
      if (!(g->tris = malloc((g->start[nc] + 1) * sizeof *g->tris))) goto nomem;
    }
  }
  free(fill);
  return HEARTH_OK;
nomem:
  free(fill);
  free(g->start);
  free(g->tris);
  memset(g, 0, sizeof *g);
  return hearth_err_set(err, HEARTH_E_NOMEM, "truth: out of memory");
}

static void grid_free(tri_grid *g) {
  free(g->start);
  free(g->tris);
  memset(g, 0, sizeof *g);
}

static double dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* squared distance from p to triangle abc and the closest point q (by the
 * Voronoi regions of the vertices, edges and face) */
static double closest_on_triangle(const double p[3], const double a[3], const double b[3],
                                  const double c[3], double q[3]) {
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int i = 0; i < 3; i++) {
    ab[i] = b[i] - a[i];
    ac[i] = c[i] - a[i];
    ap[i] = p[i] - a[i];
    bp[i] = p[i] - b[i];
    cp[i] = p[i] - c[i];
  }
  double d1 = dot(ab, ap), d2 = dot(ac, ap), d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp),
         d6 = dot(ac, cp);
  double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  if (d1 <= 0 && d2 <= 0) {
    memcpy(q, a, 3 * sizeof *q);
  } else if (d3 >= 0 && d4 <= d3) {
    memcpy(q, b, 3 * sizeof *q);
  } else if (d6 >= 0 && d5 <= d6) {
    memcpy(q, c, 3 * sizeof *q);
  } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double v = d1 / (d1 - d3);
    for (int i = 0; i < 3; i++) q[i] = a[i] + v * ab[i];
  } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double w = d2 / (d2 - d6);
    for (int i = 0; i < 3; i++) q[i] = a[i] + w * ac[i];
  } else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    for (int i = 0; i < 3; i++) q[i] = b[i] + w * (c[i] - b[i]);
  } else {
    double den = 1.0 / (va + vb + vc), v = vb * den, w = vc * den;
    for (int i = 0; i < 3; i++) q[i] = a[i] + ab[i] * v + ac[i] * w;
  }
  double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
  return dot(d, d);
}

/* the nearest point q of the mesh to p, its triangle, and the distance:
 * rings of cells around p's cell (clamped into the grid) until no farther
 * ring can hold anything closer */
static double grid_nearest(const tri_grid *g, const double p[3], uint32_t *tri, double q[3]) {
  int c0[3];
  double off2 = 0; /* squared distance from p to its clamped cell */
  for (int a = 0; a < 3; a++) {
    int c = (int)floor((p[a] - g->lo[a]) / g->cell);
    c0[a] = clampi(c, 0, g->n[a] - 1);
    double lo = g->lo[a] + c0[a] * g->cell, hi = lo + g->cell;
    double d = p[a] < lo ? lo - p[a] : p[a] > hi ? p[a] - hi : 0;
    off2 += d * d;
  }
  const double off = sqrt(off2);
  double best = DBL_MAX;
  int maxr = g->n[0] + g->n[1] + g->n[2];
  for (int r = 0; r <= maxr; r++) {
    for (int k = c0[2] - r; k <= c0[2] + r; k++)
      for (int j = c0[1] - r; j <= c0[1] + r; j++)
        for (int i = c0[0] - r; i <= c0[0] + r; i++) {
          if (abs(i - c0[0]) != r && abs(j - c0[1]) != r && abs(k - c0[2]) != r) continue;
          if (i < 0 || j < 0 || k < 0 || i >= g->n[0] || j >= g->n[1] || k >= g->n[2]) continue;
          size_t c = cell_index(g, i, j, k);
          for (size_t e = g->start[c]; e < g->start[c + 1]; e++) {
            const uint32_t *f = g->m->indices + 3 * (size_t)g->tris[e];
            double v[3][3], qq[3];
            for (int w = 0; w < 3; w++)
              for (int a = 0; a < 3; a++) v[w][a] = g->m->positions[3 * (size_t)f[w] + a];
            double d2 = closest_on_triangle(p, v[0], v[1], v[2], qq);
            if (d2 < best || (d2 == best && g->tris[e] < *tri)) {
              best = d2;
              *tri = g->tris[e];
              memcpy(q, qq, sizeof qq);
            }
          }
        }
    /* whatever lies outside rings 0..r is at least r cells minus p's
       offset from its cell away */
    if (best < DBL_MAX && sqrt(best) <= r * g->cell - off) break;
  }
  return sqrt(best);
}

/* the UV of point q on triangle tri of m (barycentrics by projection) */
static void uv_at(const hearth_mesh *m, uint32_t tri, const double q[3], double uv[2]) {
  const uint32_t *f = m->indices + 3 * (size_t)tri;
  double v[3][3];
  for (int c = 0; c < 3; c++)
    for (int a = 0; a < 3; a++) v[c][a] = m->positions[3 * (size_t)f[c] + a];
  double e0[3], e1[3], ep[3];
  for (int a = 0; a < 3; a++) {
    e0[a] = v[1][a] - v[0][a];
    e1[a] = v[2][a] - v[0][a];
    ep[a] = q[a] - v[0][a];
  }
  double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(ep, e0),
         d21 = dot(ep, e1), den = d00 * d11 - d01 * d01;
  double w1 = den > 0 ? (d11 * d20 - d01 * d21) / den : 0;
  double w2 = den > 0 ? (d00 * d21 - d01 * d20) / den : 0;
  double w[3] = {1 - w1 - w2, w1, w2};
  uv[0] = uv[1] = 0;
  for (int c = 0; c < 3; c++) {
    uv[0] += w[c] * m->uvs[2 * (size_t)f[c]];
    uv[1] += w[c] * m->uvs[2 * (size_t)f[c] + 1];
  }
}

double hb_truth_sample(const float *map, size_t Rg, size_t stride, size_t ch, const float *pos,
                       const double q[3], const double uv[2], double reach) {
  double x = uv[0] * (double)Rg - 0.5, y = uv[1] * (double)Rg - 0.5;
  if (!(x > -1.0 && y > -1.0 && x < (double)Rg && y < (double)Rg)) return NAN;
  long c0 = (long)floor(x), r0 = (long)floor(y);
  double fx = x - (double)c0, fy = y - (double)r0, sum = 0, wsum = 0;
  for (int k = 0; k < 4; k++) {
    long c = c0 + (k & 1), r = r0 + (k >> 1);
    if (c < 0 || r < 0 || c >= (long)Rg || r >= (long)Rg) continue;
    double w = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
    size_t t = (size_t)r * Rg + (size_t)c;
    double v = map[stride * t + ch];
    const float *p = pos + 3 * t;
    if (w <= 0 || !isfinite(v) || !isfinite(p[0])) continue;
    double d0 = p[0] - q[0], d1 = p[1] - q[1], d2 = p[2] - q[2];
    if (d0 * d0 + d1 * d1 + d2 * d2 > reach * reach) continue;
    sum += w * v;
    wsum += w;
  }
  return wsum > 0 ? sum / wsum : NAN;
}

/* how far apart two neighbouring texel centres of an R-texel map of m can
   lie on triangle tri, doubled: the UV-to-surface map's largest stretch
   over R, times 2 (a corner of the 2x2 cell is at most sqrt 2 texels away);
   0 where the triangle has no UV area */
static double truth_reach(const hearth_mesh *m, uint32_t tri, size_t R) {
  const uint32_t *f = m->indices + 3 * (size_t)tri;
  double e[2][3], a[2][2];
  for (int k = 0; k < 2; k++) {
    for (int c = 0; c < 3; c++)
      e[k][c] = m->positions[3 * (size_t)f[k + 1] + c] - m->positions[3 * (size_t)f[0] + c];
    for (int c = 0; c < 2; c++)
      a[k][c] = (double)m->uvs[2 * (size_t)f[k + 1] + c] - (double)m->uvs[2 * (size_t)f[0] + c];
  }
  double det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
  if (!(fabs(det) > 1e-18)) return 0;
  /* J = E A^-1: the columns are d position / du and d position / dv */
  double j[2][3];
  for (int c = 0; c < 3; c++) {
    j[0][c] = (e[0][c] * a[1][1] - e[1][c] * a[0][1]) / det;
    j[1][c] = (e[1][c] * a[0][0] - e[0][c] * a[1][0]) / det;
  }
  double g00 = dot(j[0], j[0]), g01 = dot(j[0], j[1]), g11 = dot(j[1], j[1]);
  double tr = 0.5 * (g00 + g11), dd = 0.5 * (g00 - g11);
  double s1 = sqrt(tr + sqrt(dd * dd + g01 * g01));
  return 2.0 * s1 / (double)R;
}

/* each texel centre's point on m through an R x R raster of its UVs (NaN
   where no triangle holds the centre), in a new array *out */
static hearth_status texel_points(const hearth_mesh *m, size_t R, float **out, hearth_err *err) {
  size_t n = R * R;
  uint32_t *tri = hearth_alloc_array(n, sizeof *tri);
  float *bary = hearth_alloc_array(n, 3 * sizeof *bary);
  float *pos = hearth_alloc_array(n, 3 * sizeof *pos);
  hearth_status s = HEARTH_OK;
  if (!tri || !bary || !pos) s = hearth_err_set(err, HEARTH_E_NOMEM, "truth: out of memory");
  else s = hearth_uv_rasterize(m, R, tri, bary, err);
  for (size_t q = 0; !s && q < n; q++) {
    float *p = pos + 3 * q;
    if (tri[q] == UINT32_MAX) {
      p[0] = p[1] = p[2] = NAN;
      continue;
    }
    const uint32_t *f = m->indices + 3 * (size_t)tri[q];
    for (int a = 0; a < 3; a++) {
      double v = 0;
      for (int c = 0; c < 3; c++) v += bary[3 * q + c] * m->positions[3 * (size_t)f[c] + a];
      p[a] = (float)v;
    }
  }
  free(tri);
  free(bary);
  if (s) {
    free(pos);
    pos = NULL;
  }
  *out = pos;
  return s;
}

/* a 2-D float map (or 3-D with `depth` channels) of the truth, or absent */
static hearth_status read_truth_map(const char *path, size_t depth, hearth_npy *a, int *have,
                                    hearth_err *err) {
  *have = 0;
  if (!hearth_path_exists(path)) return HEARTH_OK;
  hearth_status s = hearth_npy_read(path, a, err);
  if (s) return s;
  int ok = a->dtype == HEARTH_NPY_F32 && a->shape[0] == a->shape[1] && a->shape[0] > 0 &&
           (depth ? a->ndim == 3 && a->shape[2] == depth : a->ndim == 2);
  if (!ok) {
    hearth_npy_free(a);
    return hearth_err_set(err, HEARTH_E_SIZE, "%s: expected a square float32 map%s", path,
                          depth ? " with 3 channels" : "");
  }
  *have = 1;
  return HEARTH_OK;
}

/* 1 when both meshes carry the same UVs on the same vertices (the stand-in:
 * the built mesh is the true one under a similarity) */
static int same_uvs(const hearth_mesh *a, const hearth_mesh *b) {
  if (a->n_vertices != b->n_vertices || a->n_triangles != b->n_triangles || !a->uvs || !b->uvs)
    return 0;
  for (size_t i = 0; i < 3 * a->n_triangles; i++)
    if (a->indices[i] != b->indices[i]) return 0;
  for (size_t i = 0; i < 2 * a->n_vertices; i++)
    if (fabsf(a->uvs[i] - b->uvs[i]) > 1e-6f) return 0;
  return 1;
}

hearth_status hearth_truth_match_state(const char *root, const char *inst, const char *state,
                                       size_t R, const hearth_similarity *ref_from_est,
                                       hearth_truth_match *out, hearth_err *err) {
  memset(out, 0, sizeof *out);
  char path[PATH_SZ];
  hearth_mesh mesh = {0}, gt = {0};
  hearth_poses prgb = {0}, pgt = {0}, pth = {0};
  hearth_npy tt = {0}, ta = {0}, tc = {0};
  hearth_manifest man = {0};
  hearth_raycaster *rc = NULL;
  tri_grid g = {0};
  uint32_t *tri = NULL;
  float *bary = NULL, *gpos = NULL;
  hearth_status s;
  int have_t = 0, have_a = 0, have_c = 0;
  const size_t n = R * R;
  hearth_glb_read_opts go = {.require_uvs = 1};
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/%s/temperature_true.npy", root, inst,
           state);
  if ((s = read_truth_map(path, 0, &tt, &have_t, err))) goto done;
  if (!have_t) {
    s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no ground truth", path);
    goto done;
  }
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/%s/temperature_apparent.npy", root,
           inst, state);
  if ((s = read_truth_map(path, 0, &ta, &have_a, err))) goto done;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/%s/conditions.npy", root, inst, state);
  if ((s = read_truth_map(path, 3, &tc, &have_c, err))) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/derived/mesh.glb", root, inst);
  if ((s = hearth_glb_read(path, &go, &mesh, err))) goto done;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/mesh.glb", root, inst);
  if ((s = hearth_glb_read(path, &go, &gt, err))) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/derived/poses_rgb.json", root, inst);
  if ((s = hearth_poses_read(path, &prgb, err))) goto done;
  snprintf(path, sizeof path, "%s/ground_truth/instances/%s/poses_rgb.json", root, inst);
  if ((s = hearth_poses_read(path, &pgt, err))) goto done;
  if ((s = hearth_poses_align(&prgb, &pgt, &out->alignment, err))) {
    hearth_err_prefix(err, "%s/%s: derived/poses_rgb.json against the truth", inst, state);
    goto done;
  }
  out->same_uvs = same_uvs(&mesh, &gt);
  const hearth_similarity S = ref_from_est ? *ref_from_est : out->alignment.ref_from_est;
  out->R = R;
  out->t_true = hearth_alloc_array(n, sizeof *out->t_true);
  out->dist_m = hearth_alloc_array(n, sizeof *out->dist_m);
  out->away = hearth_alloc_array(n, 1);
  if (have_a) out->t_apparent = hearth_alloc_array(n, sizeof *out->t_apparent);
  if (have_c) out->conditions = hearth_alloc_array(n, 3 * sizeof *out->conditions);
  tri = hearth_alloc_array(n, sizeof *tri);
  bary = hearth_alloc_array(n, 3 * sizeof *bary);
  if (!out->t_true || !out->dist_m || !out->away || (have_a && !out->t_apparent) ||
      (have_c && !out->conditions) || !tri || !bary) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "truth: out of memory");
    goto done;
  }
  if ((s = hearth_uv_rasterize(&mesh, R, tri, bary, err))) goto done;
  /* the views that can see a texel: the state's thermal views */
  hearth_rig rig;
  snprintf(path, sizeof path, "%s/calibration/rig.json", root);
  if ((s = hearth_rig_read(path, &rig, err))) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/derived/poses_thermal.json", root, inst);
  if ((s = hearth_poses_read(path, &pth, err))) goto done;
  snprintf(path, sizeof path, "%s/instances/%s/raw/%s/manifest.json", root, inst, state);
  if ((s = hearth_manifest_read(path, &man, err))) goto done;
  if ((s = hearth_raycaster_new(&mesh, &rc, err))) goto done;
  if ((s = grid_build(&g, &gt, 0.004, err))) goto done;
  const size_t Rg = tt.shape[0];
  if ((s = texel_points(&gt, Rg, &gpos, err))) goto done;
  const float *T = tt.data, *A = have_a ? ta.data : NULL, *C = have_c ? tc.data : NULL;
  const double cos_away = 0.5; /* 60 degrees */
  for (size_t q = 0; q < n; q++) {
    out->t_true[q] = out->dist_m[q] = NAN;
    if (out->t_apparent) out->t_apparent[q] = NAN;
    if (out->conditions)
      for (int c = 0; c < 3; c++) out->conditions[3 * q + c] = NAN;
    out->away[q] = 0;
    if (tri[q] == UINT32_MAX) continue;
    const uint32_t *f = mesh.indices + 3 * (size_t)tri[q];
    double v[3][3], p[3] = {0, 0, 0};
    for (int c = 0; c < 3; c++)
      for (int a = 0; a < 3; a++) {
        v[c][a] = mesh.positions[3 * (size_t)f[c] + a];
        p[a] += bary[3 * q + c] * v[c][a];
      }
    /* seen within 60 degrees of the normal by some view, unoccluded */
    double e0[3], e1[3], nrm[3];
    for (int a = 0; a < 3; a++) e0[a] = v[1][a] - v[0][a], e1[a] = v[2][a] - v[0][a];
    nrm[0] = e0[1] * e1[2] - e0[2] * e1[1];
    nrm[1] = e0[2] * e1[0] - e0[0] * e1[2];
    nrm[2] = e0[0] * e1[1] - e0[1] * e1[0];
    double nn = sqrt(dot(nrm, nrm));
    for (size_t k = 0; nn > 0 && k < man.n_views && !out->away[q]; k++) {
      const hearth_view_pose *vp = hearth_poses_find(&pth, state, man.views[k].view);
      if (!vp) continue;
      const double *o = vp->T_world_from_cam.t;
      double d[3] = {o[0] - p[0], o[1] - p[1], o[2] - p[2]}, dl = sqrt(dot(d, d));
      if (dl <= 0 || dot(d, nrm) < cos_away * dl * nn) continue;
      hearth_rigid Tc;
      hearth_rigid_inverse(&vp->T_world_from_cam, &Tc);
      double xc[3], uv[2];
      hearth_rigid_apply(&Tc, p, xc);
      if (!hearth_camera_project(&rig.thermal, xc, uv, NULL) || uv[0] < -0.5 || uv[1] < -0.5 ||
          uv[0] > rig.thermal.width - 0.5 || uv[1] > rig.thermal.height - 0.5)
        continue;
      double dir[3] = {-d[0] / dl, -d[1] / dl, -d[2] / dl};
      hearth_ray_hit hit;
      double slack = 1e-3 + 1e-3 * dl;
      if (!hearth_raycast(rc, o, dir, 0.0, dl - slack, &hit)) out->away[q] = 1;
    }
    /* into the truth's frame, to the nearest true surface point */
    double x[3] = {S.s * p[0], S.s * p[1], S.s * p[2]}, y[3], cp[3], uvt[2];
    hearth_rigid_apply(&S.T, x, y);
    uint32_t gtri = 0;
    double dist = grid_nearest(&g, y, &gtri, cp);
    uv_at(&gt, gtri, cp, uvt);
    long col = (long)floor(uvt[0] * (double)Rg), row = (long)floor(uvt[1] * (double)Rg);
    if (col < 0 || row < 0 || col >= (long)Rg || row >= (long)Rg) continue;
    size_t t = (size_t)row * Rg + (size_t)col;
    double reach = truth_reach(&gt, gtri, Rg);
    out->dist_m[q] = (float)dist;
    double tv = hb_truth_sample(T, Rg, 1, 0, gpos, cp, uvt, reach);
    out->t_true[q] = isfinite(tv) ? (float)tv : T[t];
    if (A && ta.shape[0] == Rg) {
      tv = hb_truth_sample(A, Rg, 1, 0, gpos, cp, uvt, reach);
      out->t_apparent[q] = isfinite(tv) ? (float)tv : A[t];
    }
    if (C && tc.shape[0] == Rg)
      for (int c = 0; c < 3; c++) out->conditions[3 * q + c] = C[3 * t + c];
  }
done:
  grid_free(&g);
  hearth_raycaster_free(rc);
  free(tri);
  free(bary);
  free(gpos);
  hearth_mesh_free(&mesh);
  hearth_mesh_free(&gt);
  hearth_poses_free(&prgb);
  hearth_poses_free(&pgt);
  hearth_poses_free(&pth);
  hearth_manifest_free(&man);
  hearth_npy_free(&tt);
  hearth_npy_free(&ta);
  hearth_npy_free(&tc);
  if (s) hearth_truth_match_free(out);
  return s;
}
