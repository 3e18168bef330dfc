/* A camera's pixel grid cast at a mesh by rasterisation
 * (see include/hearth/mesh.h).
 *
 * The ray of grid pixel p meets the camera's plane z = 1 at its undistorted
 * centre s_p = (x, y). A triangle with every vertex in front of the camera
 * projects to a triangle of that plane, and the ray meets the 3D triangle
 * exactly when s_p lies in the projected one; the 2D barycentrics l_i of
 * s_p there give the 3D ones as (l_i/z_i) / w with w = sum_j l_j/z_j, and
 * the hit's depth is 1/w. So the nearest hit is a depth test on w (larger
 * is nearer) over the front faces whose projection holds s_p.
 *
 * Which pixels to test for a triangle: the lens map D (normalised
 * coordinates to pixels) takes every s_p back to its pixel. For a point s
 * of the triangle, D(s) differs from the same combination of D at the
 * vertices by at most 1/2 M d^2 (Taylor), where d is the triangle's
 * diameter and M bounds D's second derivative over its bounding box (in
 * closed form for the Brown-Conrady model below). So every pixel whose
 * centre can lie in the triangle is inside the box of the projected
 * vertices grown by that margin (plus a small slack for float rounding and
 * for the grid's own undistortion residual, measured when the fan is
 * made). Most triangles of a dense mesh are smaller than a pixel, and their
 * grown boxes hold no pixel centre at all: they cost a few multiplications.
 *
 * The inside test is inclusive and evaluates every edge from its
 * lower-index endpoint, so the two triangles sharing an edge compute the
 * same number with opposite signs and a point is never outside both: no
 * gaps along shared edges. Equal depths go to the lower triangle index
 * (triangles are visited in index order; only a strictly nearer one
 * replaces the current). */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/camera.h"
#include "hearth/mesh.h"

/* slack added to every margin, pixels: float rounding of the projected
   vertices and of the pixels' points, and the inclusive inside test,
   amount to well under a thousandth of a pixel */
#define FAN_SLACK_PX 0.01

struct hearth_ray_fan {
  hearth_camera cam;
  size_t stride, pw, ph, n;
  float *dirs; /* 3 per pixel, unit; zero where the lens cannot be inverted */
  float *pt;   /* 2 per pixel: the point in the plane z = 1 (NaN where none) */
  float slack; /* pixels */
  /* the margin's curvature factor for triangles within |x| <= ax, |y| <= ay
     (the pixels' points, with room): pixels per squared plane unit */
  float ax, ay, mu_reg, mv_reg;
};

void hearth_ray_fan_free(hearth_ray_fan *f) {
  if (!f) return;
  free(f->dirs);
  free(f->pt);
  free(f);
}

const float *hearth_ray_fan_dirs(const hearth_ray_fan *f, size_t *w, size_t *h) {
  if (w) *w = f->pw;
  if (h) *h = f->ph;
  return f->dirs;
}

/* Half the bound on the lens map's second derivative (pixels per squared
 * plane unit, any direction) over |x| <= A, |y| <= B, for u and v. With
 * s = x^2 + y^2 and g(s) = 1 + k1 s + k2 s^2 + k3 s^3, the second partials
 * of xd are 6x g' + 4x^3 g'' + 6 p2 (xx), 2y g' + 4x^2 y g'' + 2 p1 (xy) and
 * 2x g' + 4x y^2 g'' + 2 p2 (yy); those of yd are the same with x, y and
 * p1, p2 swapped. |g'| <= G1 and |g''| <= G2 over the box; a direction's
 * second derivative is at most max(|xx|, |yy|) + |xy|. */
static void lens_curvature(const hearth_camera *cam, float A, float B, float *hu, float *hv) {
  const float k1 = (float)fabs(cam->dist[0]), k2 = (float)fabs(cam->dist[1]),
              p1 = (float)fabs(cam->dist[2]), p2 = (float)fabs(cam->dist[3]),
              k3 = (float)fabs(cam->dist[4]);
  float S = A * A + B * B;
  float G1 = k1 + S * (2.0f * k2 + 3.0f * k3 * S), G2 = 2.0f * k2 + 6.0f * k3 * S;
  float xxu = 6.0f * A * G1 + 4.0f * A * A * A * G2 + 6.0f * p2;
  float yyu = 2.0f * A * G1 + 4.0f * A * B * B * G2 + 2.0f * p2;
  float xyu = 2.0f * B * G1 + 4.0f * A * A * B * G2 + 2.0f * p1;
  float yyv = 6.0f * B * G1 + 4.0f * B * B * B * G2 + 6.0f * p1;
  float xxv = 2.0f * B * G1 + 4.0f * A * A * B * G2 + 2.0f * p1;
  float xyv = 2.0f * A * G1 + 4.0f * A * B * B * G2 + 2.0f * p2;
  /* 1.001: room for the float arithmetic of the bound itself */
  *hu = 0.5f * 1.001f * (float)cam->fx * ((xxu > yyu ? xxu : yyu) + xyu);
  *hv = 0.5f * 1.001f * (float)cam->fy * ((yyv > xxv ? yyv : xxv) + xyv);
}

hearth_status hearth_ray_fan_new(const hearth_camera *cam, size_t stride, hearth_ray_fan **out,
                                 hearth_err *err) {
  *out = NULL;
  if (stride < 1) stride = 1;
  if (cam->width <= 0 || cam->height <= 0 || !(cam->fx > 0.0) || !(cam->fy > 0.0))
    return hearth_err_set(err, HEARTH_E_ARG, "ray fan: the camera has no size or focal length");
  if (cam->model != HEARTH_LENS_BROWN5)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "ray fan: the %s lens model is not supported (the fan's error bound "
                          "is derived for the 5-parameter model)",
                          hearth_lens_name(cam->model));
  size_t pw = ((size_t)cam->width + stride - 1) / stride,
         ph = ((size_t)cam->height + stride - 1) / stride;
  if (pw > (size_t)INT32_MAX / 2 || ph > (size_t)INT32_MAX / 2 || pw * ph > (size_t)UINT32_MAX / 2)
    return hearth_err_set(err, HEARTH_E_LIMIT, "ray fan: %zu x %zu pixels exceed the limit", pw,
                          ph);
  hearth_ray_fan *f = calloc(1, sizeof *f);
  if (!f) return hearth_err_set(err, HEARTH_E_NOMEM, "ray fan: out of memory");
  f->cam = *cam;
  f->stride = stride;
  f->pw = pw;
  f->ph = ph;
  f->n = pw * ph;
  f->dirs = hearth_alloc_array(f->n, 3 * sizeof *f->dirs);
  f->pt = hearth_alloc_array(f->n, 2 * sizeof *f->pt);
  if (!f->dirs || !f->pt) {
    hearth_ray_fan_free(f);
    return hearth_err_set(err, HEARTH_E_NOMEM, "ray fan: out of memory for %zu x %zu pixels", pw,
                          ph);
  }
  hearth_camera_ray_grid(cam, stride, f->dirs);
  /* the pixels' points, and how far the lens map puts each point from its
     pixel once rounded to float (the grid's residual and the rounding) */
  double worst = 0.0;
  for (size_t p = 0; p < f->n; p++) {
    float *d = f->dirs + 3 * p;
    if (!(isfinite(d[0]) && isfinite(d[1]) && isfinite(d[2]) && d[2] > 0.0f)) {
      d[0] = d[1] = d[2] = 0.0f; /* never cast */
      f->pt[2 * p] = f->pt[2 * p + 1] = NAN;
      continue;
    }
    float x = (float)((double)d[0] / (double)d[2]), y = (float)((double)d[1] / (double)d[2]);
    f->pt[2 * p] = x;
    f->pt[2 * p + 1] = y;
    double xd, yd;
    hearth_distort(cam->dist, x, y, &xd, &yd, NULL);
    double du = fabs(cam->fx * xd + cam->cx - (double)((p % pw) * stride));
    double dv = fabs(cam->fy * yd + cam->cy - (double)((p / pw) * stride));
    if (du > worst) worst = du;
    if (dv > worst) worst = dv;
  }
  f->slack = (float)(worst + FAN_SLACK_PX);
  /* the region: the points' extent grown by a tenth */
  float ax = 0.0f, ay = 0.0f;
  for (size_t p = 0; p < f->n; p++) {
    float x = fabsf(f->pt[2 * p]), y = fabsf(f->pt[2 * p + 1]);
    if (x > ax) ax = x; /* NaN compares false */
    if (y > ay) ay = y;
  }
  f->ax = 1.1f * ax + 1e-3f;
  f->ay = 1.1f * ay + 1e-3f;
  lens_curvature(cam, f->ax, f->ay, &f->mu_reg, &f->mv_reg);
  *out = f;
  return HEARTH_OK;
}

/* per vertex: the projection and its pixel (1/z is kept apart: only the
   inside tests need it) */
typedef struct fan_vertex {
  float x, y, u, v;
} fan_vertex;

/* per pixel: the nearest front face so far; w = 0 (all zero bits) for none,
   which is how every cast finds and leaves the scratch */
typedef struct fan_best {
  float w;
  uint32_t tri;
} fan_best;

size_t hearth_ray_fan_scratch_size(const hearth_ray_fan *f, size_t n_vertices) {
  return (n_vertices ? n_vertices : 1) * (sizeof(fan_vertex) + sizeof(float)) +
         f->n * sizeof(fan_best);
}

/* one edge of a triangle: from its lower-index endpoint (ax, ay) along
 * (dx, dy), times sign (-1 when the triangle runs the other way). Both
 * triangles sharing the edge get the same numbers but the sign. */
typedef struct fan_edge {
  float ax, ay, dx, dy, sign;
} fan_edge;

static inline fan_edge edge_of(const fan_vertex *V, uint32_t p, uint32_t q) {
  const fan_vertex *a = V + (p < q ? p : q), *b = V + (p < q ? q : p);
  return (fan_edge){a->x, a->y, b->x - a->x, b->y - a->y, p < q ? 1.0f : -1.0f};
}

static inline float edge_eval(const fan_edge *e, float x, float y) {
  return e->sign * (e->dx * (y - e->ay) - e->dy * (x - e->ax));
}

static inline float min3f(float a, float b, float c) {
  float m = a < b ? a : b;
  return m < c ? m : c;
}
static inline float max3f(float a, float b, float c) {
  float m = a > b ? a : b;
  return m > c ? m : c;
}

/* the grid indices in [lo, hi] among 0..n-1 (i0 > i1 when none; NaN
   bounds count as unbounded), without branches */
static inline void grid_range(float lo, float hi, long n, long *i0, long *i1) {
  lo = lo > -0.5f ? lo : -0.5f;
  lo = lo < (float)n ? lo : (float)n;
  long c = (long)lo; /* truncation: ceil(lo) is c or c + 1 */
  *i0 = c + ((float)c < lo);
  hi = hi < (float)(n - 1) ? hi : (float)(n - 1);
  hi = hi > -1.0f ? hi : -1.0f;
  *i1 = (long)(hi + 1.0f) - 1; /* floor, hi >= -1 */
}

/* The cast behind both entry points: the hits' box in box; with frame,
 * the hits written within the frame of the box grown by grow pixels
 * (clipped to the grid; frame = {x0, y0, w, h}, misses where the box does
 * not reach), else grid-indexed within the box. */
static hearth_status fan_cast(const hearth_ray_fan *f, const hearth_mesh *m,
                              const hearth_rigid *T_world_from_cam, void *scratch,
                              hearth_ray_hit *hits, size_t grow, size_t box[4], size_t frame[4],
                              hearth_err *err) {
  box[0] = box[2] = 1;
  box[1] = box[3] = 0;
  if (frame) frame[0] = frame[1] = frame[2] = frame[3] = 0;
  if (!m->n_triangles) return HEARTH_OK;
  fan_vertex *V = scratch;
  float *IZ = (float *)(void *)(V + (m->n_vertices ? m->n_vertices : 1));
  fan_best *best = (fan_best *)(void *)(IZ + (m->n_vertices ? m->n_vertices : 1));
  const double *R = T_world_from_cam->R, *t = T_world_from_cam->t;
  const hearth_camera *cam = &f->cam;
  /* vertices into the camera frame (x_cam = R^T (x - t)), projected to the
     plane and through the lens to pixels; one float value per vertex, shared
     by all its triangles */
  const float r00 = (float)R[0], r01 = (float)R[1], r02 = (float)R[2], r10 = (float)R[3],
              r11 = (float)R[4], r12 = (float)R[5], r20 = (float)R[6], r21 = (float)R[7],
              r22 = (float)R[8];
  const float t0 = (float)t[0], t1 = (float)t[1], t2 = (float)t[2];
  /* the pixels in float: their rounding (about 1e-7 relative, some 1e-4
     pixel) is far inside the slack */
  const float kd[5] = {(float)cam->dist[0], (float)cam->dist[1], (float)cam->dist[2],
                       (float)cam->dist[3], (float)cam->dist[4]};
  const float ffx = (float)cam->fx, ffy = (float)cam->fy, fcx = (float)cam->cx,
              fcy = (float)cam->cy;
  int behind = 0;
  const float *restrict pos = m->positions;
  /* in blocks of 64: the positions split into one array per coordinate,
     every value computed into an array of its own (a loop the compiler runs
     four vertices at a time: three times faster than one loop over the
     interleaved arrays), then interleaved */
  enum { VERT_BLOCK = 64 };
  for (size_t i0 = 0; i0 < m->n_vertices; i0 += VERT_BLOCK) {
    const size_t nb = m->n_vertices - i0 < VERT_BLOCK ? m->n_vertices - i0 : VERT_BLOCK;
    const float *restrict pp = pos + 3 * i0;
    float px[VERT_BLOCK], py[VERT_BLOCK], pz[VERT_BLOCK];
    float sx[VERT_BLOCK], sy[VERT_BLOCK], su[VERT_BLOCK], sv[VERT_BLOCK], siz[VERT_BLOCK];
    for (size_t k = 0; k < nb; k++) {
      px[k] = pp[3 * k];
      py[k] = pp[3 * k + 1];
      pz[k] = pp[3 * k + 2];
    }
    for (size_t k = 0; k < nb; k++) {
      float dx = px[k] - t0, dy = py[k] - t1, dz = pz[k] - t2;
      float x = r00 * dx + r10 * dy + r20 * dz;
      float y = r01 * dx + r11 * dy + r21 * dz;
      float z = r02 * dx + r12 * dy + r22 * dz;
      behind |= !(z > 0.0f);
      float iz = 1.0f / z;
      x *= iz;
      y *= iz;
      float xd, yd;
      hearth_distort_xyf(kd, x, y, &xd, &yd);
      sx[k] = x;
      sy[k] = y;
      su[k] = ffx * xd + fcx;
      sv[k] = ffy * yd + fcy;
      siz[k] = iz;
    }
    for (size_t k = 0; k < nb; k++) {
      V[i0 + k] = (fan_vertex){sx[k], sy[k], su[k], sv[k]};
      IZ[i0 + k] = siz[k];
    }
  }
  if (behind)
    for (size_t i = 0; i < m->n_vertices; i++) {
      const float *p = pos + 3 * i;
      float z = r02 * (p[0] - t0) + r12 * (p[1] - t1) + r22 * (p[2] - t2);
      if (!(z > 0.0f))
        return hearth_err_set(
            err, HEARTH_E_UNSUPPORTED,
            "ray fan: vertex %zu is not in front of the camera (z = %g): cast rays instead", i,
            (double)z);
    }
  long bx0 = LONG_MAX, bx1 = -1, by0 = LONG_MAX, by1 = -1; /* the hits' box */
  const float slack = f->slack, inv_st = 1.0f / (float)f->stride;
  const long pw = (long)f->pw, ph = (long)f->ph;
  /* triangles in blocks: first every front face's candidate pixels (most
     have none, and whether one has is a coin toss: appended without a
     branch), then the inside tests of those with some, in index order */
  enum { FAN_BLOCK = 256 };
  struct {
    uint32_t tri;
    int32_t i0, i1, j0, j1;
    float area;
  } cand[FAN_BLOCK];
  for (size_t blk = 0; blk < m->n_triangles; blk += FAN_BLOCK) {
    const size_t blk_end = blk + FAN_BLOCK < m->n_triangles ? blk + FAN_BLOCK : m->n_triangles;
    size_t nc = 0;
    for (size_t tri = blk; tri < blk_end; tri++) {
      const uint32_t *ix = m->indices + 3 * tri;
      const fan_vertex *a = V + ix[0], *b = V + ix[1], *c = V + ix[2];
      /* front faces (counter-clockwise seen from outside) project clockwise
         in this frame (x right, y down): negative signed area */
      float area = (b->x - a->x) * (c->y - a->y) - (b->y - a->y) * (c->x - a->x);
      if (!(area < 0.0f)) continue;
      float minx = min3f(a->x, b->x, c->x), maxx = max3f(a->x, b->x, c->x);
      float miny = min3f(a->y, b->y, c->y), maxy = max3f(a->y, b->y, c->y);
      float dx = maxx - minx, dy = maxy - miny, d2 = dx * dx + dy * dy;
      /* the margin: the lens curvature over the box (the region's bound for
         the usual triangle inside it) times the squared diameter */
      float hu = f->mu_reg, hv = f->mv_reg;
      float A = maxx > -minx ? maxx : -minx, B = maxy > -miny ? maxy : -miny;
      if (!(A <= f->ax && B <= f->ay)) lens_curvature(cam, A, B, &hu, &hv);
      float mu = hu * d2 + slack, mv = hv * d2 + slack;
      long i0, i1, j0, j1;
      grid_range((min3f(a->u, b->u, c->u) - mu) * inv_st, (max3f(a->u, b->u, c->u) + mu) * inv_st,
                 pw, &i0, &i1);
      grid_range((min3f(a->v, b->v, c->v) - mv) * inv_st, (max3f(a->v, b->v, c->v) + mv) * inv_st,
                 ph, &j0, &j1);
      cand[nc].tri = (uint32_t)tri;
      cand[nc].i0 = (int32_t)i0;
      cand[nc].i1 = (int32_t)i1;
      cand[nc].j0 = (int32_t)j0;
      cand[nc].j1 = (int32_t)j1;
      cand[nc].area = area;
      nc += (i0 <= i1) & (j0 <= j1);
    }
    for (size_t k = 0; k < nc; k++) {
      const size_t tri = cand[k].tri;
      const uint32_t *ix = m->indices + 3 * tri;
      const uint32_t ia = ix[0], ib = ix[1], ic = ix[2];
      const float area = cand[k].area;
      const fan_edge ea = edge_of(V, ib, ic), eb = edge_of(V, ic, ia), ec = edge_of(V, ia, ib);
      const float inv_area = 1.0f / area;
      for (long j = cand[k].j0; j <= cand[k].j1; j++)
        for (long i = cand[k].i0; i <= cand[k].i1; i++) {
          size_t p = (size_t)j * (size_t)pw + (size_t)i;
          float x = f->pt[2 * p], y = f->pt[2 * p + 1];
          /* signed areas opposite a, b and c: all <= 0 inside (area < 0);
             a pixel without a point (NaN) is never inside */
          float la = edge_eval(&ea, x, y), lb = edge_eval(&eb, x, y), lc = edge_eval(&ec, x, y);
          if (!(la <= 0.0f && lb <= 0.0f && lc <= 0.0f)) continue;
          float w = (la * IZ[ia] + lb * IZ[ib] + lc * IZ[ic]) * inv_area;
          if (!(w > best[p].w)) continue;
          best[p] = (fan_best){w, (uint32_t)tri};
          bx0 = i < bx0 ? i : bx0;
          bx1 = i > bx1 ? i : bx1;
          by0 = j < by0 ? j : by0;
          by1 = j > by1 ? j : by1;
        }
    }
  }
  /* the hits within their box, which leaves the scratch all zero again */
  if (bx1 < 0) return HEARTH_OK;
  box[0] = (size_t)bx0;
  box[1] = (size_t)bx1;
  box[2] = (size_t)by0;
  box[3] = (size_t)by1;
  /* where hit (i, j) goes: hits + (j - oy) * ow + (i - ox) */
  long ox = 0, oy = 0, ow = pw;
  if (frame) {
    const long g = (long)grow;
    ox = bx0 >= g ? bx0 - g : 0;
    oy = by0 >= g ? by0 - g : 0;
    ow = (bx1 + g < pw ? bx1 + g : pw - 1) - ox + 1;
    const long oh = (by1 + g < ph ? by1 + g : ph - 1) - oy + 1;
    frame[0] = (size_t)ox;
    frame[1] = (size_t)oy;
    frame[2] = (size_t)ow;
    frame[3] = (size_t)oh;
    /* the frame's pixels outside the box: misses */
    for (long j = oy; j < oy + oh; j++)
      for (long i = ox; i < ox + ow; i++)
        if (j < by0 || j > by1 || i < bx0 || i > bx1)
          hits[(j - oy) * ow + (i - ox)] = (hearth_ray_hit){INFINITY, UINT32_MAX, 0.0f, 0.0f, 0};
  }
  for (long j = by0; j <= by1; j++)
    for (long i = bx0; i <= bx1; i++) {
      size_t p = (size_t)j * (size_t)pw + (size_t)i;
      hearth_ray_hit *out = hits + (size_t)((j - oy) * ow + (i - ox));
      if (!(best[p].w > 0.0f)) {
        *out = (hearth_ray_hit){INFINITY, UINT32_MAX, 0.0f, 0.0f, 0};
        continue;
      }
      const uint32_t *ix = m->indices + 3 * (size_t)best[p].tri;
      float x = f->pt[2 * p], y = f->pt[2 * p + 1];
      fan_edge ea = edge_of(V, ix[1], ix[2]), eb = edge_of(V, ix[2], ix[0]),
               ec = edge_of(V, ix[0], ix[1]);
      double wa = (double)edge_eval(&ea, x, y) * IZ[ix[0]],
             wb = (double)edge_eval(&eb, x, y) * IZ[ix[1]],
             wc = (double)edge_eval(&ec, x, y) * IZ[ix[2]], ws = wa + wb + wc;
      /* depth 1/w along z; the distance along the unit direction is
         depth / d_z */
      *out = (hearth_ray_hit){(float)(1.0 / ((double)best[p].w * (double)f->dirs[3 * p + 2])),
                              best[p].tri, (float)(wb / ws), (float)(wc / ws), 1};
      best[p] = (fan_best){0.0f, 0};
    }
  return HEARTH_OK;
}

hearth_status hearth_ray_fan_cast(const hearth_ray_fan *f, const hearth_mesh *m,
                                  const hearth_rigid *T_world_from_cam, void *scratch,
                                  hearth_ray_hit *hits, size_t box[4], hearth_err *err) {
  return fan_cast(f, m, T_world_from_cam, scratch, hits, 0, box, NULL, err);
}

hearth_status hearth_ray_fan_cast_framed(const hearth_ray_fan *f, const hearth_mesh *m,
                                         const hearth_rigid *T_world_from_cam, void *scratch,
                                         size_t grow, hearth_ray_hit *hits, size_t box[4],
                                         size_t frame[4], hearth_err *err) {
  return fan_cast(f, m, T_world_from_cam, scratch, hits, grow, box, frame, err);
}

hearth_status hearth_ray_fan_extent(const hearth_camera *cam, size_t stride, const hearth_mesh *m,
                                    const hearth_rigid *T_world_from_cam, double slack_px,
                                    size_t box[4], hearth_err *err) {
  box[0] = box[2] = 1;
  box[1] = box[3] = 0;
  if (stride < 1) stride = 1;
  if (cam->model != HEARTH_LENS_BROWN5)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "ray fan: the %s lens model is not supported (the extent's bound is "
                          "derived for the 5-parameter model)",
                          hearth_lens_name(cam->model));
  if (!m->n_triangles) return HEARTH_OK;
  hearth_rigid T_cam_from_world;
  hearth_rigid_inverse(T_world_from_cam, &T_cam_from_world);
  /* per vertex: its point in the plane z = 1 and its pixel */
  double *V = hearth_alloc_array(m->n_vertices ? m->n_vertices : 1, 4 * sizeof *V);
  if (!V) return hearth_err_set(err, HEARTH_E_NOMEM, "ray fan: out of memory");
  for (size_t i = 0; i < m->n_vertices; i++) {
    const float *p = m->positions + 3 * i;
    const double xw[3] = {p[0], p[1], p[2]};
    double c[3];
    hearth_rigid_apply(&T_cam_from_world, xw, c);
    if (!hearth_camera_project(cam, c, V + 4 * i + 2, NULL)) {
      free(V);
      return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                            "ray fan: vertex %zu is not in front of the camera (z = %g)", i, c[2]);
    }
    V[4 * i] = c[0] / c[2];
    V[4 * i + 1] = c[1] / c[2];
  }
  const long pw = (long)(((size_t)cam->width + stride - 1) / stride),
             ph = (long)(((size_t)cam->height + stride - 1) / stride);
  long bx0 = LONG_MAX, bx1 = -1, by0 = LONG_MAX, by1 = -1;
  /* every triangle, whichever way it faces (back faces only widen the box):
     the pixels of its projection, grown by the cast's margin */
  for (size_t tri = 0; tri < m->n_triangles; tri++) {
    const uint32_t *ix = m->indices + 3 * tri;
    const double *a = V + 4 * (size_t)ix[0], *b = V + 4 * (size_t)ix[1], *c = V + 4 * (size_t)ix[2];
    double minx = fmin(a[0], fmin(b[0], c[0])), maxx = fmax(a[0], fmax(b[0], c[0]));
    double miny = fmin(a[1], fmin(b[1], c[1])), maxy = fmax(a[1], fmax(b[1], c[1]));
    double d2 = (maxx - minx) * (maxx - minx) + (maxy - miny) * (maxy - miny);
    float hu, hv;
    lens_curvature(cam, (float)fmax(maxx, -minx), (float)fmax(maxy, -miny), &hu, &hv);
    double mu = hu * d2 + slack_px, mv = hv * d2 + slack_px;
    long i0, i1, j0, j1;
    grid_range((float)((fmin(a[2], fmin(b[2], c[2])) - mu) / (double)stride),
               (float)((fmax(a[2], fmax(b[2], c[2])) + mu) / (double)stride), pw, &i0, &i1);
    grid_range((float)((fmin(a[3], fmin(b[3], c[3])) - mv) / (double)stride),
               (float)((fmax(a[3], fmax(b[3], c[3])) + mv) / (double)stride), ph, &j0, &j1);
    if (i0 > i1 || j0 > j1) continue;
    bx0 = i0 < bx0 ? i0 : bx0;
    bx1 = i1 > bx1 ? i1 : bx1;
    by0 = j0 < by0 ? j0 : by0;
    by1 = j1 > by1 ? j1 : by1;
  }
  free(V);
  if (bx1 < 0) return HEARTH_OK;
  box[0] = (size_t)bx0;
  box[1] = (size_t)bx1;
  box[2] = (size_t)by0;
  box[3] = (size_t)by1;
  return HEARTH_OK;
}
