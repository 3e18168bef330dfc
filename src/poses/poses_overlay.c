/* Alignment overlays: the projected mesh outline on the Turbo-coloured
 * thermal image, per view and as a contact sheet (include/hearth/poses.h).
 *
 * The thermal camera is the same in every view, so the rays through its
 * sub-pixel centres are undistorted once (ov_grid). The contact sheet's
 * cells, at the camera's own pixels, pool the enlarged outlines (a pixel is
 * on the outline when one of its sub-pixels is) instead of casting again.
 *
 * A ray caster sees back faces too, but where the mesh is closed (every edge
 * shared by two triangles running it in opposite directions, vertices
 * welded by position), faces outward (positive signed volume) and lies
 * wholly in front of the camera (so the camera is outside it), the nearest
 * surface along every ray is a front face: there the grid is cast by
 * rasterising the front faces through its ray fan (include/hearth/mesh.h),
 * exact like the ray caster up to float rounding along silhouettes.
 * Otherwise the rays are rotated per pose and traced in packets, only inside
 * the box the mesh's vertices project to (the whole grid when a hit touches
 * the box's border).
 * Views are drawn in parallel, each worker with scratch of its own; the
 * contact sheet is assembled in view order afterwards. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/dataset.h"
#include "hearth/thermal.h"
#include "poses/poses_internal.h"

#define OV_MARGIN 4   /* px around the mesh's projected vertices */
#define OV_BATCH 4096 /* rays per cast */

/* the rays of hearth_camera_ray through the centres of a zoom x zoom grid
 * inside every pixel, row-major over the zoomed image */
typedef struct ov_grid {
  int zoom;
  size_t w, h;
  hearth_camera cam; /* the camera the grid is of */
  /* 3 per sub-pixel, camera frame; NaN where the lens cannot be inverted.
     NULL with a fan: the few views the fan cannot cast compute their rays
     as they trace them */
  double *dir;
  /* the same sub-pixels as the pixel grid of the camera enlarged zoom
     times; NULL where the mesh does not allow it or it cannot be made
     (then rays are traced) */
  hearth_ray_fan *fan;
} ov_grid;

/* per worker */
typedef struct ov_scratch {
  float *depth;     /* w x h of the largest grid: distance along the ray, INFINITY: no surface */
  uint8_t *edge;    /* w x h: outline sub-pixels */
  size_t eb[4];     /* x0, x1, y0, y1 (exclusive): no outline sub-pixel outside it */
  uint8_t *cell[2]; /* per side (before, after): the outline pooled to camera pixels */
  float org[3 * OV_BATCH], dir[3 * OV_BATCH];
  hearth_ray_hit hits[OV_BATCH];
  size_t pix[OV_BATCH];     /* grid index of each ray of the batch */
  void *fan_scratch;        /* hearth_ray_fan_scratch_size of the largest fan */
  hearth_ray_hit *fan_hits; /* w x h of the largest grid */
  double *vals;             /* thermal pixels, for the range */
  uint8_t *turbo;           /* 3 per thermal pixel */
  hearth_image temps;
  hearth_image big; /* the per-view file's image, reused from view to view */
} ov_scratch;

/* the ray of sub-pixel (x, y) of g into d (NaN where the lens cannot be
   inverted) */
static void ov_grid_ray(const ov_grid *g, size_t x, size_t y, double d[3]) {
  double u = -0.5 + ((double)x + 0.5) / g->zoom, v = -0.5 + ((double)y + 0.5) / g->zoom;
  if (hearth_camera_ray(&g->cam, u, v, d) < 0) d[0] = d[1] = d[2] = NAN;
}

/* the grid at zoom, and with with_fan its ray fan (NULL where it cannot
   be made: then rays are traced) */
static hearth_status ov_grid_make(const hearth_camera *cam, int zoom, int with_fan, ov_grid *g,
                                  hearth_err *err) {
  g->zoom = zoom;
  g->cam = *cam;
  g->w = (size_t)cam->width * (size_t)zoom;
  g->h = (size_t)cam->height * (size_t)zoom;
  size_t n = g->w * g->h;
  /* sub-pixel (x, y) is pixel (x, y) of the camera whose pixel coordinates
     are zoom (u + 1/2) - 1/2: focal lengths times zoom, the centre moved
     with them */
  if (with_fan) {
    hearth_camera cz = *cam;
    cz.width = (int)g->w;
    cz.height = (int)g->h;
    cz.fx = cam->fx * zoom;
    cz.fy = cam->fy * zoom;
    cz.cx = zoom * (cam->cx + 0.5) - 0.5;
    cz.cy = zoom * (cam->cy + 0.5) - 0.5;
    if (g->w <= INT32_MAX && g->h <= INT32_MAX && hearth_ray_fan_new(&cz, 1, &g->fan, NULL))
      g->fan = NULL;
  }
  /* a grid with a fan rasterises every view: its rays are never traced */
  if (g->fan) return HEARTH_OK;
  g->dir = hearth_alloc_array(n ? n : 1, 3 * sizeof *g->dir);
  if (!g->dir) return hearth_err_set(err, HEARTH_E_NOMEM, "overlay: out of memory");
  for (size_t y = 0; y < g->h; y++)
    for (size_t x = 0; x < g->w; x++) ov_grid_ray(g, x, y, g->dir + 3 * (y * g->w + x));
  return HEARTH_OK;
}

static void ov_grid_free(ov_grid *g) {
  free(g->dir);
  hearth_ray_fan_free(g->fan);
}

static int cmp_edge(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

int rf_mesh_closed_outward(const hearth_mesh *m) {
  const size_t nv = m->n_vertices, nt = m->n_triangles;
  if (!nv || !nt || nv > UINT32_MAX || nt > SIZE_MAX / 3) return 0;
  uint32_t *id = hearth_alloc_array(nv, sizeof *id);
  uint64_t *e = hearth_alloc_array(3 * nt, sizeof *e);
  /* welded: a position shared by several vertices is one id (a non-finite
     position fails the weld, and the mesh is not taken as closed) */
  int ok = id && e && !hearth_mesh_weld_ids(m, id, NULL);
  if (ok) {
    /* directed edges a -> b as a << 32 | b */
    double vol = 0.0;
    for (size_t t = 0; ok && t < nt; t++) {
      const uint32_t *ix = m->indices + 3 * t;
      for (int k = 0; k < 3; k++) {
        uint32_t a = id[ix[k]], b = id[ix[(k + 1) % 3]];
        ok = a != b;
        e[3 * t + (size_t)k] = (uint64_t)a << 32 | b;
      }
      const float *p0 = m->positions + 3 * (size_t)ix[0], *p1 = m->positions + 3 * (size_t)ix[1],
                  *p2 = m->positions + 3 * (size_t)ix[2];
      vol += (double)p0[0] * ((double)p1[1] * p2[2] - (double)p1[2] * p2[1]) -
             (double)p0[1] * ((double)p1[0] * p2[2] - (double)p1[2] * p2[0]) +
             (double)p0[2] * ((double)p1[0] * p2[1] - (double)p1[1] * p2[0]);
    }
    ok = ok && vol > 0.0;
    if (ok) {
      /* each directed edge once, and its reverse there too */
      qsort(e, 3 * nt, sizeof *e, cmp_edge);
      for (size_t i = 0; ok && i < 3 * nt; i++) {
        ok = !(i && e[i] == e[i - 1]);
        uint64_t r = e[i] << 32 | e[i] >> 32;
        ok = ok && bsearch(&r, e, 3 * nt, sizeof *e, cmp_edge) != NULL;
      }
    }
  }
  free(id);
  free(e);
  return ok;
}

static void ov_scratch_free(ov_scratch *s) {
  if (!s) return;
  free(s->depth);
  free(s->edge);
  free(s->cell[0]);
  free(s->cell[1]);
  free(s->vals);
  free(s->turbo);
  free(s->fan_scratch);
  free(s->fan_hits);
  hearth_image_free(&s->temps);
  hearth_image_free(&s->big);
}

/* scratch for grids of up to n_sub sub-pixels and images of n_px pixels,
 * and (fan_bytes > 0) fan casts of that many bytes of scratch; NULL when
 * out of memory */
static ov_scratch *ov_scratch_new(size_t n_sub, size_t n_px, size_t fan_bytes) {
  ov_scratch *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  s->depth = hearth_alloc_array(n_sub ? n_sub : 1, sizeof *s->depth);
  s->edge = hearth_alloc_array(n_sub ? n_sub : 1, 1);
  s->cell[0] = hearth_alloc_array(n_px ? n_px : 1, 1);
  s->cell[1] = hearth_alloc_array(n_px ? n_px : 1, 1);
  s->vals = hearth_alloc_array(n_px ? n_px : 1, sizeof *s->vals);
  s->turbo = hearth_alloc_array(n_px ? n_px : 1, 3);
  if (fan_bytes) {
    s->fan_scratch = calloc(1, fan_bytes);
    s->fan_hits = hearth_alloc_array(n_sub ? n_sub : 1, sizeof *s->fan_hits);
  }
  if (!s->depth || !s->edge || !s->cell[0] || !s->cell[1] || !s->vals || !s->turbo ||
      (fan_bytes && (!s->fan_scratch || !s->fan_hits))) {
    ov_scratch_free(s);
    free(s);
    return NULL;
  }
  return s;
}

/* cast the batch's n rays and keep the distances of the hits */
static void ov_flush(const hearth_raycaster *rc, ov_scratch *s, size_t n) {
  hearth_raycast_batch_mt(rc, n, s->org, s->dir, 0.0f, INFINITY, s->hits, 1);
  for (size_t i = 0; i < n; i++)
    if (s->hits[i].prim != UINT32_MAX) s->depth[s->pix[i]] = s->hits[i].t;
}

/* cast the grid's sub-pixels [x0, x1) x [y0, y1) from T into s->depth, in
 * 4 x 4 tiles so that each packet of 16 rays is a tight bundle */
static void ov_cast(const hearth_raycaster *rc, const ov_grid *g, const hearth_rigid *T, size_t x0,
                    size_t x1, size_t y0, size_t y1, ov_scratch *s) {
  const float o[3] = {(float)T->t[0], (float)T->t[1], (float)T->t[2]};
  size_t n = 0;
  for (size_t ty = y0; ty < y1; ty += 4)
    for (size_t tx = x0; tx < x1; tx += 4)
      for (size_t y = ty; y < ty + 4 && y < y1; y++)
        for (size_t x = tx; x < tx + 4 && x < x1; x++) {
          size_t p = y * g->w + x;
          double own[3];
          const double *dc = g->dir ? g->dir + 3 * p : own;
          if (!g->dir) ov_grid_ray(g, x, y, own);
          if (isnan(dc[0])) continue;
          double dw[3];
          hearth_rigid_rotate(T, dc, dw);
          for (int k = 0; k < 3; k++) {
            s->org[3 * n + (size_t)k] = o[k];
            s->dir[3 * n + (size_t)k] = (float)dw[k];
          }
          s->pix[n++] = p;
          if (n == OV_BATCH) {
            ov_flush(rc, s, n);
            n = 0;
          }
        }
  if (n) ov_flush(rc, s, n);
}

/* 1 if a sub-pixel on a side of the box [x0, x1) x [y0, y1) that is not the
 * grid's own border has a surface */
static int ov_hit_on_border(const ov_grid *g, const float *depth, const size_t b[4]) {
  const size_t x0 = b[0], x1 = b[1], y0 = b[2], y1 = b[3];
  for (size_t x = x0; x < x1; x++) {
    if (y0 > 0 && isfinite(depth[y0 * g->w + x])) return 1;
    if (y1 < g->h && isfinite(depth[(y1 - 1) * g->w + x])) return 1;
  }
  for (size_t y = y0; y < y1; y++) {
    if (x0 > 0 && isfinite(depth[y * g->w + x0])) return 1;
    if (x1 < g->w && isfinite(depth[y * g->w + x1 - 1])) return 1;
  }
  return 0;
}

/* mark outline sub-pixels (silhouette and depth jumps) of the mesh seen
 * from T in s->edge, and their box in s->eb; mesh (may be NULL: cast
 * everything) bounds the cast */
static void ov_outline(const hearth_raycaster *rc, const hearth_mesh *mesh,
                       const hearth_camera *cam, const ov_grid *g, const hearth_rigid *T,
                       ov_scratch *s) {
  const size_t w = g->w, h = g->h, zoom = (size_t)g->zoom;
  float *depth = s->depth;
  uint8_t *edge = s->edge;
  for (size_t i = 0; i < w * h; i++) depth[i] = INFINITY;
  size_t b[4] = {0, w, 0, h}; /* x0, x1, y0, y1 */
  int pb[4];
  size_t fb[4];
  if (mesh && g->fan && s->fan_scratch &&
      !hearth_ray_fan_cast(g->fan, mesh, T, s->fan_scratch, s->fan_hits, fb, NULL)) {
    /* every hit lies in the fan's box */
    if (fb[0] > fb[1]) b[0] = b[1] = b[2] = b[3] = 0;
    else b[0] = fb[0], b[1] = fb[1] + 1, b[2] = fb[2], b[3] = fb[3] + 1;
    for (size_t y = b[2]; y < b[3]; y++)
      for (size_t x = b[0]; x < b[1]; x++) {
        const hearth_ray_hit *hit = s->fan_hits + y * w + x;
        if (hit->prim != UINT32_MAX) depth[y * w + x] = hit->t;
      }
  } else if (mesh && rf_mesh_box(mesh, cam, T, OV_MARGIN, pb)) {
    b[0] = (size_t)pb[0] * zoom;
    b[1] = (size_t)pb[2] * zoom;
    b[2] = (size_t)pb[1] * zoom;
    b[3] = (size_t)pb[3] * zoom;
    ov_cast(rc, g, T, b[0], b[1], b[2], b[3], s);
    if (ov_hit_on_border(g, depth, b)) {
      /* the surface may go on beyond the box: cast the whole grid */
      ov_cast(rc, g, T, 0, w, 0, h, s);
      b[0] = 0, b[1] = w, b[2] = 0, b[3] = h;
    }
  } else {
    ov_cast(rc, g, T, 0, w, 0, h, s);
  }
  memset(edge, 0, w * h);
  /* every surface sub-pixel lies in the box */
  for (size_t y = b[2]; y < b[3]; y++)
    for (size_t x = b[0]; x < b[1]; x++) {
      float d = depth[y * w + x];
      if (!isfinite(d)) continue;
      const long dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
      for (int k = 0; k < 4; k++) {
        long nx = (long)x + dx[k], ny = (long)y + dy[k];
        if (nx < 0 || ny < 0 || nx >= (long)w || ny >= (long)h) continue;
        float dn = depth[(size_t)ny * w + (size_t)nx];
        /* both sides of the jump, so the line is two sub-pixels wide */
        if (!isfinite(dn) || dn > d * 1.05f)
          edge[y * w + x] = edge[(size_t)ny * w + (size_t)nx] = 1;
      }
    }
  /* an outline sub-pixel is a surface one or its neighbour */
  if (b[0] < b[1] && b[2] < b[3]) {
    s->eb[0] = b[0] ? b[0] - 1 : 0;
    s->eb[1] = b[1] < w ? b[1] + 1 : w;
    s->eb[2] = b[2] ? b[2] - 1 : 0;
    s->eb[3] = b[3] < h ? b[3] + 1 : h;
  } else {
    s->eb[0] = s->eb[1] = s->eb[2] = s->eb[3] = 0;
  }
}

/* the outline sub-pixels inside box eb (x0, x1, y0, y1; NULL: the whole
   image) painted rgb */
static void ov_paint(hearth_image *out, const uint8_t *edge, const size_t *eb,
                     const uint8_t rgb[3]) {
  uint8_t *o = out->data;
  const size_t w = out->width, all[4] = {0, w, 0, out->height};
  if (!eb) eb = all;
  for (size_t y = eb[2]; y < eb[3]; y++)
    for (size_t x = eb[0]; x < eb[1]; x++)
      if (edge[y * w + x]) memcpy(o + 3 * (y * w + x), rgb, 3);
}

/* the zoom x zoom outline sub-pixels of g (all inside box eb) pooled into
 * camera pixels: a pixel is on the outline when any of its sub-pixels is */
static void ov_pool(const uint8_t *edge, const ov_grid *g, const size_t eb[4], uint8_t *cell) {
  const size_t z = (size_t)g->zoom, cw = g->w / z, ch = g->h / z;
  memset(cell, 0, cw * ch);
  const size_t cx0 = eb[0] / z, cx1 = (eb[1] + z - 1) / z;
  for (size_t y = eb[2]; y < eb[3]; y++) {
    const uint8_t *e = edge + y * g->w;
    uint8_t *c = cell + (y / z) * cw;
    for (size_t x = cx0; x < cx1; x++) {
      uint8_t any = 0;
      for (size_t k = 0; k < z; k++) any |= e[z * x + k];
      c[x] |= any;
    }
  }
}

/* the 2..98 % range of the image, so low-contrast states stay readable */
static void ov_auto_range(const hearth_image *temps, double *vals, double *lo, double *hi) {
  size_t n = temps->width * temps->height;
  const float *t = temps->data;
  for (size_t i = 0; i < n; i++) vals[i] = t[i];
  size_t k = n / 50;
  *lo = rf_select(vals, n, k);
  /* what lies above position k is the rest of the order */
  *hi = k + 1 < n ? rf_select(vals + k + 1, n - k - 1, n - 2 - 2 * k) : vals[k];
  if (!(*hi > *lo)) *hi = *lo + 1.0;
}

/* Turbo colour of every thermal pixel over [lo, hi]. A pixel's colour
   depends on its value's bits alone, and a thermal image holds few distinct
   values (its CSV's decimals), so colours are kept in a direct-mapped table
   by those bits and each distinct value is coloured about once. */
static void ov_colours(const hearth_image *temps, double lo, double hi, uint8_t *turbo) {
  enum { OV_TURBO_BITS = 12, OV_TURBO_N = 1 << OV_TURBO_BITS };
  uint32_t key[OV_TURBO_N];
  uint8_t col[OV_TURBO_N][3], used[OV_TURBO_N];
  memset(used, 0, sizeof used);
  const float *t = temps->data;
  for (size_t i = 0; i < temps->width * temps->height; i++) {
    uint32_t b;
    memcpy(&b, &t[i], sizeof b);
    uint32_t slot = (b * 2654435761u) >> (32 - OV_TURBO_BITS);
    if (!used[slot] || key[slot] != b) {
      hearth_turbo((t[i] - lo) / (hi - lo), col[slot]);
      key[slot] = b;
      used[slot] = 1;
    }
    memcpy(turbo + 3 * i, col[slot], 3);
  }
}

/* the colours enlarged zoom times (nearest) into out: a new image, or
   out's pixels where it already has that size (a worker's own, reused) */
static hearth_status ov_background(const uint8_t *turbo, size_t tw, size_t th, size_t zoom,
                                   hearth_image *out, hearth_err *err) {
  size_t w = tw * zoom, h = th * zoom;
  if (!(out->data && out->width == w && out->height == h && out->channels == 3 &&
        out->type == HEARTH_PIX_U8)) {
    hearth_image_free(out);
    hearth_status s = hearth_image_alloc(out, w, h, 3, HEARTH_PIX_U8, err);
    if (s) return s;
  }
  uint8_t *o = out->data;
  for (size_t ty = 0; ty < th; ty++) {
    uint8_t *row = o + 3 * (ty * zoom) * w;
    for (size_t tx = 0; tx < tw; tx++)
      for (size_t r = 0; r < zoom; r++)
        memcpy(row + 3 * (tx * zoom + r), turbo + 3 * (ty * tw + tx), 3);
    for (size_t r = 1; r < zoom; r++) memcpy(row + 3 * r * w, row, 3 * w);
  }
  return HEARTH_OK;
}

hearth_status hearth_overlay_render(const hearth_raycaster *rc, const hearth_camera *cam,
                                    const hearth_image *temps, const hearth_rigid *T_world_from_cam,
                                    int zoom, double lo, double hi, const uint8_t rgb[3],
                                    hearth_image *out, hearth_err *err) {
  if (!temps || temps->type != HEARTH_PIX_F32 || temps->channels != 1 ||
      temps->width != (size_t)cam->width || temps->height != (size_t)cam->height)
    return hearth_err_set(err, HEARTH_E_SIZE, "overlay: expected a %dx%d temperature image",
                          cam->width, cam->height);
  if (zoom < 1 || zoom > 16)
    return hearth_err_set(err, HEARTH_E_ARG, "overlay: zoom %d outside 1..16", zoom);
  size_t n = temps->width * temps->height, w = temps->width * (size_t)zoom,
         h = temps->height * (size_t)zoom;
  ov_scratch *s = ov_scratch_new(w * h, n, 0);
  ov_grid g = {0};
  hearth_status st = HEARTH_OK;
  if (!s) return hearth_err_set(err, HEARTH_E_NOMEM, "overlay: out of memory");
  if (!(lo < hi)) ov_auto_range(temps, s->vals, &lo, &hi);
  if (!out->data) {
    ov_colours(temps, lo, hi, s->turbo);
    if ((st = ov_background(s->turbo, temps->width, temps->height, (size_t)zoom, out, err)))
      goto done;
  } else if (out->width != w || out->height != h || out->channels != 3) {
    st = hearth_err_set(err, HEARTH_E_SIZE, "overlay: target image has the wrong size");
    goto done;
  }
  if ((st = ov_grid_make(cam, zoom, 0, &g, err))) goto done;
  ov_outline(rc, NULL, cam, &g, T_world_from_cam, s);
  ov_paint(out, s->edge, s->eb, rgb);
done:
  ov_grid_free(&g);
  ov_scratch_free(s);
  free(s);
  return st;
}

/* ---- the release stage ------------------------------------------------------ */

typedef struct ov_ctx {
  const hearth_overlay_job *job;
  const hearth_mesh *mesh;
  const hearth_raycaster *rc;
  const hearth_camera *cam;
  const hearth_manifest *man;
  const hearth_poses *before, *after; /* before: NULL when there is none */
  const char *after_path, *dir;
  const char *rig_path;      /* the camera's document, named in size errors */
  const ov_grid *big;        /* at the job's zoom; a fan only where the mesh allows
                                 it (see above) */
  ov_scratch **scratch;      /* per worker */
  hearth_image (*thumbs)[2]; /* per view: the sheet's before and after cells */
  hearth_status *st;         /* per view */
  hearth_err *errs;          /* per view */
} ov_ctx;

/* view k: its own file, and its two contact-sheet cells in thumbs */
static hearth_status ov_view(const ov_ctx *c, ov_scratch *s, size_t k, hearth_image thumbs[2],
                             hearth_err *err) {
  const hearth_overlay_job *job = c->job;
  const hearth_view_files *vf = &c->man->views[k];
  const char *state = job->state;
  const hearth_view_pose *pa = hearth_poses_find(c->after, state, vf->view);
  const hearth_view_pose *pb = c->before ? hearth_poses_find(c->before, state, vf->view) : NULL;
  if (!pa)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: no pose for state '%s' view '%s'",
                          c->after_path, state, vf->view);
  char path[RF_PATH];
  size_t cw = (size_t)c->cam->width, ch = (size_t)c->cam->height;
  rf_pathf(path, "%s/instances/%s/raw/%s/%s", job->root, job->instance, state, vf->thermal);
  hearth_image_free(&s->temps);
  hearth_status st = hearth_thermal_read_csv_camera(path, cw, ch, c->rig_path, &s->temps, err);
  if (st) return st;
  double lo = job->lo, hi = job->hi;
  if (!(lo < hi)) ov_auto_range(&s->temps, s->vals, &lo, &hi);
  ov_colours(&s->temps, lo, hi, s->turbo);
  /* the per-view file: before in magenta under after in white */
  const uint8_t white[3] = {255, 255, 255}, magenta[3] = {255, 0, 255};
  hearth_image *ov = &s->big;
  if ((st = ov_background(s->turbo, cw, ch, (size_t)c->big->zoom, ov, err))) return st;
  /* the sheet's cells (camera pixels) pool the enlarged outlines: no cast
     of their own */
  if (pb) {
    ov_outline(c->rc, c->mesh, c->cam, c->big, &pb->T_world_from_cam, s);
    ov_paint(ov, s->edge, s->eb, magenta);
    ov_pool(s->edge, c->big, s->eb, s->cell[0]);
  }
  ov_outline(c->rc, c->mesh, c->cam, c->big, &pa->T_world_from_cam, s);
  ov_paint(ov, s->edge, s->eb, white);
  ov_pool(s->edge, c->big, s->eb, s->cell[1]);
  hearth_draw_text(ov, 4, 4, vf->view, white, 2);
  rf_pathf(path, "%s/%s.png", c->dir, vf->view);
  st = hearth_png_write_picture(path, ov, err);
  for (int side = 0; side < 2 && !st; side++) {
    if (!(side ? pa : pb)) continue;
    if ((st = ov_background(s->turbo, cw, ch, 1, &thumbs[side], err))) break;
    ov_paint(&thumbs[side], s->cell[side], NULL, white);
  }
  return st;
}

/* views [b, e) on worker t; a chunk stops at its first failure, so the
 * lowest failing view is always reached whatever the thread count */
static void ov_range(void *ctx, size_t b, size_t e, int t) {
  const ov_ctx *c = ctx;
  for (size_t k = b; k < e; k++)
    if ((c->st[k] = ov_view(c, c->scratch[t], k, c->thumbs[k], &c->errs[k]))) break;
}

hearth_status hearth_overlay_run(const hearth_overlay_job *job, size_t *n_written,
                                 hearth_err *err) {
  if (!job || !job->root || !job->instance || !job->state)
    return hearth_err_set(err, HEARTH_E_ARG, "overlay: root, instance and state are required");
  const char *root = job->root, *inst = job->instance, *state = job->state;
  char rig_path[RF_PATH], mesh_path[RF_PATH], before_path[RF_PATH], after_path[RF_PATH],
      dir[RF_PATH], path[RF_PATH];
  if (job->rig_path) snprintf(rig_path, RF_PATH, "%s", job->rig_path);
  else rf_pathf(rig_path, "%s/calibration/rig.json", root);
  if (job->mesh_path) snprintf(mesh_path, RF_PATH, "%s", job->mesh_path);
  else rf_pathf(mesh_path, "%s/instances/%s/derived/mesh.glb", root, inst);
  if (job->before_path) snprintf(before_path, RF_PATH, "%s", job->before_path);
  else rf_pathf(before_path, "%s/instances/%s/derived/poses_thermal_transferred.json", root, inst);
  if (job->after_path) snprintf(after_path, RF_PATH, "%s", job->after_path);
  else rf_pathf(after_path, "%s/instances/%s/derived/poses_thermal.json", root, inst);
  int zoom = job->zoom > 0 ? job->zoom : 3;
  hearth_rig rig;
  hearth_poses before = {0}, after = {0};
  hearth_mesh mesh = {0};
  hearth_raycaster *rc = NULL;
  hearth_manifest man = {0};
  hearth_image sheet = {0};
  ov_grid big = {0};
  ov_ctx c = {0};
  int nt = 0;
  size_t written = 0;
  hearth_status s;
  if ((s = hearth_rig_read(rig_path, &rig, err)) ||
      (s = hearth_rig_require_stereo(&rig, rig_path, "the pose overlay", err)))
    goto done;
  int have_before = hearth_path_exists(before_path);
  if (have_before && (s = hearth_poses_read(before_path, &before, err))) goto done;
  if ((s = hearth_poses_read(after_path, &after, err))) goto done;
  hearth_glb_read_opts gopts = {0};
  if ((s = hearth_glb_read(mesh_path, &gopts, &mesh, err))) goto done;
  if ((s = hearth_raycaster_new(&mesh, &rc, err))) goto done;
  rf_pathf(path, "%s/instances/%s/raw/%s/manifest.json", root, inst, state);
  if ((s = hearth_manifest_read(path, &man, err))) goto done;
  rf_pathf(dir, "%s/instances/%s/derived/overlay/%s", root, inst, state);
  if ((s = hearth_mkdirs(dir, err))) goto done;
  /* contact sheet: one cell per view, before (left) and after (right) */
  size_t cw = (size_t)rig.thermal.width, ch = (size_t)rig.thermal.height, label = 12;
  size_t cols = 4, rows = (man.n_views + cols - 1) / cols;
  if ((s = hearth_image_alloc(&sheet, cols * (2 * cw + 8), rows * (ch + label + 8) + 16, 3,
                              HEARTH_PIX_U8, err)))
    goto done;
  memset(sheet.data, 40, hearth_image_bytes(&sheet));
  const uint8_t white[3] = {255, 255, 255}, grey[3] = {190, 190, 190};
  char title[160];
  snprintf(title, sizeof title, "%s %s  left: before  right: after (white outline)", inst, state);
  hearth_draw_text(&sheet, 4, 4, title, white, 1);
  if (!man.n_views) goto sheet;
  /* the rays of the thermal camera, once for every view */
  int fan = rf_mesh_closed_outward(&mesh);
  if ((s = ov_grid_make(&rig.thermal, zoom, fan, &big, err))) goto done;
  nt = job->threads > 0 ? job->threads : hearth_default_threads();
  if ((size_t)nt > man.n_views) nt = (int)man.n_views;
  if (nt < 1) nt = 1;
  c = (ov_ctx){job,    &mesh,      rc,  &rig.thermal, &man, have_before ? &before : NULL,
               &after, after_path, dir, rig_path,     &big, NULL,
               NULL,   NULL,       NULL};
  c.scratch = calloc((size_t)nt, sizeof *c.scratch);
  c.thumbs = calloc(man.n_views, sizeof *c.thumbs);
  c.st = calloc(man.n_views, sizeof *c.st);
  c.errs = calloc(man.n_views, sizeof *c.errs);
  int nomem = !c.scratch || !c.thumbs || !c.st || !c.errs;
  size_t fan_bytes = big.fan ? hearth_ray_fan_scratch_size(big.fan, mesh.n_vertices) : 0;
  for (int t = 0; t < nt && !nomem; t++)
    nomem = !(c.scratch[t] = ov_scratch_new(big.w * big.h, cw * ch, fan_bytes));
  if (nomem) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "overlay: out of memory");
    goto done;
  }
  /* a view that was not reached (its chunk failed earlier) stays marked */
  for (size_t k = 0; k < man.n_views; k++) c.st[k] = HEARTH_E_ARG;
  if ((s = hearth_parallel_for(man.n_views, nt, ov_range, &c))) {
    hearth_err_set(err, s, "overlay: cannot start worker threads");
    goto done;
  }
  for (size_t k = 0; k < man.n_views; k++) {
    if (c.st[k]) {
      s = c.st[k];
      if (err) *err = c.errs[k];
      goto done;
    }
    written++;
  }
  /* the sheet in view order: label, then the before and after cells */
  for (size_t k = 0; k < man.n_views; k++) {
    size_t cx = (k % cols) * (2 * cw + 8) + 4, cy = (k / cols) * (ch + label + 8) + 16;
    hearth_draw_text(&sheet, cx, cy, man.views[k].view, grey, 1);
    for (int side = 0; side < 2; side++)
      if (c.thumbs[k][side].data)
        hearth_image_blit(&sheet, &c.thumbs[k][side], cx + (size_t)side * cw, cy + label);
  }
sheet:
  rf_pathf(path, "%s/contact_sheet.png", dir);
  if ((s = hearth_png_write_picture(path, &sheet, err))) goto done;
  written++;
  if (n_written) *n_written = written;
done:
  if (c.scratch)
    for (int t = 0; t < nt; t++) {
      ov_scratch_free(c.scratch[t]);
      free(c.scratch[t]);
    }
  if (c.thumbs)
    for (size_t k = 0; k < man.n_views; k++) {
      hearth_image_free(&c.thumbs[k][0]);
      hearth_image_free(&c.thumbs[k][1]);
    }
  free(c.scratch);
  free(c.thumbs);
  free(c.st);
  free(c.errs);
  ov_grid_free(&big);
  hearth_image_free(&sheet);
  hearth_manifest_free(&man);
  hearth_raycaster_free(rc);
  hearth_mesh_free(&mesh);
  hearth_poses_free(&before);
  hearth_poses_free(&after);
  return s;
}

void hearth_overlay_job_default(hearth_overlay_job *job) {
  memset(job, 0, sizeof *job);
  job->zoom = 3;
}
