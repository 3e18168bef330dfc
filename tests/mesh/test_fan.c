/* The ray fan (a camera's pixel grid cast by rasterisation) against an
 * independent reference: Embree, continued past back faces, pixel by pixel.
 * Meshes: a welded torus (dense, non-convex: it occludes itself and shows
 * back faces in front of front faces), a cube (triangles spanning many
 * pixels under strong distortion, where the lens margin matters) and a
 * plane whose vertices sit on pixel centres (watertightness). Also: stride,
 * ties, and a vertex behind the camera. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/camera.h"
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/mesh.h"
#include "test_util.h"
#include "mesh/cube_mesh.h"

/* camera at c looking at the origin, world up +z (x right, y down) */
static hearth_rigid look_at(double cx, double cy, double cz) {
  double f[3] = {-cx, -cy, -cz}, up[3] = {0, 0, 1}, x[3], y[3];
  double l = hearth_norm3(f);
  for (int k = 0; k < 3; k++) f[k] /= l;
  hearth_cross3(f, up, x);
  l = hearth_norm3(x);
  if (l < 1e-9) { /* looking along z */
    double up2[3] = {0, 1, 0};
    hearth_cross3(f, up2, x);
    l = hearth_norm3(x);
  }
  for (int k = 0; k < 3; k++) x[k] /= l;
  hearth_cross3(f, x, y);
  hearth_rigid T;
  for (int k = 0; k < 3; k++) {
    T.R[3 * k] = x[k];
    T.R[3 * k + 1] = y[k];
    T.R[3 * k + 2] = f[k];
  }
  T.t[0] = cx;
  T.t[1] = cy;
  T.t[2] = cz;
  return T;
}

/* torus around z, major radius a, minor b, nu x nv welded vertices */
static void make_torus(hearth_mesh *m, double a, double b, size_t nu, size_t nv) {
  hearth_err err;
  CHECK_OK(hearth_mesh_alloc(m, nu * nv, 2 * nu * nv, 0, &err), &err);
  for (size_t i = 0; i < nu; i++)
    for (size_t j = 0; j < nv; j++) {
      double u = 2 * M_PI * (double)i / (double)nu, v = 2 * M_PI * (double)j / (double)nv;
      float *p = m->positions + 3 * (i * nv + j);
      p[0] = (float)((a + b * cos(v)) * cos(u));
      p[1] = (float)((a + b * cos(v)) * sin(u));
      p[2] = (float)(b * sin(v));
    }
  size_t t = 0;
  for (size_t i = 0; i < nu; i++)
    for (size_t j = 0; j < nv; j++) {
      uint32_t p00 = (uint32_t)(i * nv + j), p10 = (uint32_t)(((i + 1) % nu) * nv + j),
               p01 = (uint32_t)(i * nv + (j + 1) % nv),
               p11 = (uint32_t)(((i + 1) % nu) * nv + (j + 1) % nv);
      /* counter-clockwise seen from outside: along u then v */
      uint32_t *ix = m->indices + 3 * t;
      ix[0] = p00;
      ix[1] = p10;
      ix[2] = p11;
      ix[3] = p00;
      ix[4] = p11;
      ix[5] = p01;
      t += 2;
    }
}

/* the reference: Embree's nearest hit, continued past back faces */
static hearth_ray_hit reference(const hearth_raycaster *rc, const hearth_rigid *T, const float *d) {
  double dc[3] = {d[0], d[1], d[2]}, w[3], o[3] = {T->t[0], T->t[1], T->t[2]};
  hearth_ray_hit h = {INFINITY, UINT32_MAX, 0, 0, 0};
  if (dc[0] == 0 && dc[1] == 0 && dc[2] == 0) return h;
  hearth_rigid_rotate(T, dc, w);
  double tn = 0.0;
  for (int k = 0; k < 32; k++) {
    if (!hearth_raycast(rc, o, w, tn, INFINITY, &h)) return h;
    if (h.front) return h;
    tn = (double)h.t * (1.0 + 1e-6) + 1e-7;
  }
  h.prim = UINT32_MAX;
  return h;
}

typedef struct compare_stats {
  size_t hits, ref_hits, hit_miss, other_tri, bad_t, bad_b;
  size_t loose; /* extents more than 8 pixels beyond the hits' box on a side */
} compare_stats;

/* cast the fan and the reference from T; tally the differences */
static void compare(const hearth_mesh *m, const hearth_camera *cam, size_t stride,
                    const hearth_rigid *T, compare_stats *st) {
  hearth_err err = {0};
  hearth_ray_fan *fan = NULL;
  hearth_raycaster *rc = NULL;
  CHECK_OK(hearth_ray_fan_new(cam, stride, &fan, &err), &err);
  CHECK_OK(hearth_raycaster_new(m, &rc, &err), &err);
  if (!fan || !rc) return;
  size_t w, h;
  const float *dirs = hearth_ray_fan_dirs(fan, &w, &h);
  CHECK(w == ((size_t)cam->width + stride - 1) / stride &&
        h == ((size_t)cam->height + stride - 1) / stride);
  size_t ss = hearth_ray_fan_scratch_size(fan, m->n_vertices);
  unsigned char *scratch = calloc(1, ss);
  hearth_ray_hit *hits = malloc(w * h * sizeof *hits);
  /* a first cast from elsewhere must leave no trace in the scratch */
  hearth_rigid other = look_at(0.2, -1.3, 0.4);
  size_t box[4];
  CHECK_OK(hearth_ray_fan_cast(fan, m, &other, scratch, hits, box, &err), &err);
  for (size_t p = 0; p < w * h; p++) hits[p] = (hearth_ray_hit){-1.0f, 12345u, -1.0f, -1.0f, 7};
  CHECK_OK(hearth_ray_fan_cast(fan, m, T, scratch, hits, box, &err), &err);
  size_t nz = 0;
  for (size_t k = ss - w * h * 8; k < ss; k++) nz += scratch[k] != 0;
  CHECK_MSG(nz == 0, "%zu scratch bytes left set", nz);
  /* the extent, made without the fan, holds the hits' box (how much more
     depends on the triangles' size: counted in loose) */
  {
    size_t ext[4];
    CHECK_OK(hearth_ray_fan_extent(cam, stride, m, T, 1.0, ext, &err), &err);
    CHECK(box[0] <= box[1]);
    if (box[0] <= box[1]) {
      CHECK_MSG(ext[0] <= box[0] && ext[1] >= box[1] && ext[2] <= box[2] && ext[3] >= box[3],
                "extent [%zu, %zu] x [%zu, %zu], hits [%zu, %zu] x [%zu, %zu]", ext[0], ext[1],
                ext[2], ext[3], box[0], box[1], box[2], box[3]);
      st->loose +=
          box[0] > ext[0] + 8 || ext[1] > box[1] + 8 || box[2] > ext[2] + 8 || ext[3] > box[3] + 8;
    }
  }
  /* the framed cast: the same box, the frame the box grown by 3 and
     clipped, the grid cast's hits inside the box and misses around it */
  {
    hearth_ray_hit *fh = malloc(w * h * sizeof *fh);
    size_t fbox[4], fr[4];
    for (size_t p = 0; fh && p < w * h; p++) fh[p] = (hearth_ray_hit){-1.0f, 12345u, -1, -1, 7};
    if (fh) CHECK_OK(hearth_ray_fan_cast_framed(fan, m, T, scratch, 3, fh, fbox, fr, &err), &err);
    CHECK(fh && !memcmp(fbox, box, sizeof box) && box[0] <= box[1]);
    if (fh && box[0] <= box[1]) {
      CHECK(fr[0] == (box[0] >= 3 ? box[0] - 3 : 0) && fr[1] == (box[2] >= 3 ? box[2] - 3 : 0));
      CHECK(fr[0] + fr[2] == (box[1] + 3 < w ? box[1] + 4 : w));
      CHECK(fr[1] + fr[3] == (box[3] + 3 < h ? box[3] + 4 : h));
      size_t bad = 0;
      for (size_t y = fr[1]; y < fr[1] + fr[3]; y++)
        for (size_t x = fr[0]; x < fr[0] + fr[2]; x++) {
          const hearth_ray_hit *a = &fh[(y - fr[1]) * fr[2] + (x - fr[0])];
          int in_box = x >= box[0] && x <= box[1] && y >= box[2] && y <= box[3];
          if (in_box) bad += memcmp(a, &hits[y * w + x], sizeof *a) != 0;
          else bad += a->prim != UINT32_MAX;
        }
      /* nothing written beyond the frame */
      for (size_t p = fr[2] * fr[3]; p < w * h; p++) bad += fh[p].prim != 12345u;
      CHECK_MSG(bad == 0, "framed cast: %zu pixels differ from the grid cast", bad);
    }
    free(fh);
  }
  for (size_t p = 0; p < w * h; p++) {
    hearth_ray_hit r = reference(rc, T, dirs + 3 * p);
    size_t px = p % w, py = p / w;
    int in_box = px >= box[0] && px <= box[1] && py >= box[2] && py <= box[3];
    /* written inside the box; outside it, untouched and a miss */
    if (!in_box) {
      CHECK(hits[p].prim == 12345u);
      hits[p].prim = UINT32_MAX;
    }
    int a = hits[p].prim != UINT32_MAX, b = r.prim != UINT32_MAX;
    st->hits += (size_t)a;
    st->ref_hits += (size_t)b;
    if (a != b) {
      st->hit_miss++;
      continue;
    }
    if (!a) continue;
    CHECK(hits[p].front == 1);
    if (hits[p].prim != r.prim) {
      /* a ray through an edge or a vertex: a neighbour at the same depth */
      st->other_tri++;
      if (fabs(hits[p].t - r.t) > 1e-4 * r.t) st->bad_t++;
      continue;
    }
    /* both in float; grazing hits lose a few more digits */
    if (fabs(hits[p].t - r.t) > 2e-5 * r.t) st->bad_t++;
    if (fabs(hits[p].b1 - r.b1) > 1e-3 || fabs(hits[p].b2 - r.b2) > 1e-3) st->bad_b++;
  }
  free(scratch);
  free(hits);
  hearth_raycaster_free(rc);
  hearth_ray_fan_free(fan);
}

static void check_stats(const char *what, const compare_stats *s, size_t min_hits) {
  fprintf(
      stderr,
      "%s: %zu hits (reference %zu), hit/miss %zu, other triangle %zu, t off %zu, bary off %zu\n",
      what, s->hits, s->ref_hits, s->hit_miss, s->other_tri, s->bad_t, s->bad_b);
  CHECK_MSG(s->hits >= min_hits, "%s: only %zu hits", what, s->hits);
  /* rays grazing an edge or a silhouette may go either way in float: a
     handful in ten thousand */
  CHECK_MSG(s->hit_miss * 5000 <= s->ref_hits + 5000, "%s: %zu hit/miss differences", what,
            s->hit_miss);
  CHECK_MSG(s->other_tri * 200 <= s->ref_hits + 200, "%s: %zu other triangles", what, s->other_tri);
  CHECK_MSG(s->bad_t == 0, "%s: %zu depths differ", what, s->bad_t);
  CHECK_MSG(s->bad_b == 0, "%s: %zu barycentrics differ", what, s->bad_b);
}

int main(void) {
  hearth_err err = {0};
  hearth_camera lens = {160, 120, 150.0, 148.0, 81.3, 58.2, {-0.32, 0.11, 0.0012, -0.0009, -0.015}};
  hearth_camera pin = {160, 120, 150.0, 150.0, 79.5, 59.5, {0, 0, 0, 0, 0}};

  /* torus: dense, self-occluding, from eight directions, with and without
     distortion, full and strided grids */
  {
    hearth_mesh torus = {0};
    make_torus(&torus, 0.3, 0.1, 160, 64); /* 20480 triangles, most under a pixel */
    compare_stats s = {0}, s2 = {0};
    for (int k = 0; k < 8; k++) {
      double az = 2 * M_PI * k / 8.0 + 0.1, el = (k % 3 - 1) * 0.6;
      hearth_rigid T =
          look_at(1.1 * cos(el) * cos(az), 1.1 * cos(el) * sin(az), 1.1 * sin(el) + 0.05);
      compare(&torus, k % 2 ? &lens : &pin, 1, &T, &s);
      compare(&torus, &lens, 3, &T, &s2);
    }
    check_stats("torus", &s, 8 * 3000);
    check_stats("torus, stride 3", &s2, 8 * 300);
    /* triangles under a pixel: the extent is the hits' box but for the
       margins */
    CHECK_MSG(s.loose == 0 && s2.loose == 0, "torus: %zu + %zu loose extents", s.loose, s2.loose);
    /* a lens the extent's bound is not derived for: refused, no box */
    hearth_camera r8 = lens;
    r8.model = HEARTH_LENS_RATIONAL8;
    hearth_rigid T = look_at(1.1, 0.0, 0.05);
    size_t ext[4];
    CHECK(hearth_ray_fan_extent(&r8, 1, &torus, &T, 1.0, ext, &err) == HEARTH_E_UNSUPPORTED);
    CHECK_MSG(strstr(err.msg, "rational8") != NULL, "%s", err.msg);
    CHECK(ext[0] > ext[1]);
    hearth_mesh_free(&torus);
  }

  /* cube: triangles spanning many pixels under strong distortion, seen from
     near enough that it fills the image and its edges curve */
  {
    hearth_mesh cube = {0};
    make_cube(&cube);
    compare_stats s = {0};
    hearth_camera strong = lens;
    strong.dist[0] = -0.45;
    strong.dist[1] = 0.22;
    for (int k = 0; k < 6; k++) {
      double az = 0.7 + k, el = 0.3 * (k % 3) - 0.3;
      hearth_rigid T = look_at(1.6 * cos(el) * cos(az), 1.6 * cos(el) * sin(az), 1.6 * sin(el));
      compare(&cube, &strong, 1, &T, &s);
    }
    check_stats("cube", &s, 6 * 5000);
    hearth_mesh_free(&cube);
  }

  /* plane at z = 1 in front of a distortion-free camera, its vertices on
     the pixels' points: every pixel lies on a vertex or an edge, and each
     must still hit */
  {
    const size_t n = 81; /* vertices per side, one every second pixel */
    hearth_mesh plane = {0};
    CHECK_OK(hearth_mesh_alloc(&plane, n * n, 2 * (n - 1) * (n - 1), 0, &err), &err);
    for (size_t j = 0; j < n; j++)
      for (size_t i = 0; i < n; i++) {
        float *p = plane.positions + 3 * (j * n + i);
        p[0] = (float)(((double)(2 * i) - 1.0 - pin.cx) / pin.fx);
        p[1] = (float)(((double)(2 * j) - 21.0 - pin.cy) / pin.fy);
        p[2] = 1.0f;
      }
    size_t t = 0;
    for (size_t j = 0; j + 1 < n; j++)
      for (size_t i = 0; i + 1 < n; i++) {
        uint32_t a = (uint32_t)(j * n + i), b = a + 1, c = a + (uint32_t)n, d = c + 1;
        /* facing -z (towards the camera): clockwise in x-right, y-down */
        uint32_t *ix = plane.indices + 3 * t;
        if ((i + j) % 2) {
          ix[0] = a;
          ix[1] = c;
          ix[2] = b;
          ix[3] = b;
          ix[4] = c;
          ix[5] = d;
        } else {
          ix[0] = a;
          ix[1] = d;
          ix[2] = b;
          ix[3] = a;
          ix[4] = c;
          ix[5] = d;
        }
        t += 2;
      }
    hearth_rigid I;
    hearth_rigid_identity(&I);
    hearth_ray_fan *fan = NULL;
    CHECK_OK(hearth_ray_fan_new(&pin, 1, &fan, &err), &err);
    void *scratch = calloc(1, hearth_ray_fan_scratch_size(fan, plane.n_vertices));
    size_t box[4];
    hearth_ray_hit *hits = malloc(160 * 120 * sizeof *hits);
    CHECK_OK(hearth_ray_fan_cast(fan, &plane, &I, scratch, hits, box, &err), &err);
    CHECK(box[0] == 0 && box[1] >= 158 && box[2] == 0 && box[3] == 119);
    size_t holes = 0, inside = 0;
    for (size_t v = 0; v < 120; v++)
      for (size_t u = 0; u < 160; u++) {
        /* pixels strictly inside the plane's extent: columns 0..158, rows
           0..119 (the plane spans columns -1..159, rows -21..139) */
        if (u > 158) continue;
        inside++;
        const hearth_ray_hit *h = &hits[v * 160 + u];
        if (h->prim == UINT32_MAX) holes++;
        else
          CHECK_NEAR(h->t,
                     sqrt(1.0 + pow((u - pin.cx) / pin.fx, 2) + pow((v - pin.cy) / pin.fy, 2)),
                     1e-5);
      }
    CHECK_MSG(holes == 0, "%zu of %zu pixels fell through the plane", holes, inside);

    /* ties: a copy of triangle TT (mid-image) put first; the lower index
       must win */
    const size_t TT = 2 * (20 * (n - 1) + 40) + 1;
    hearth_mesh twin = {0};
    CHECK_OK(hearth_mesh_alloc(&twin, plane.n_vertices, plane.n_triangles + 1, 0, &err), &err);
    memcpy(twin.positions, plane.positions, plane.n_vertices * 3 * sizeof(float));
    memcpy(twin.indices + 3, plane.indices, plane.n_triangles * 3 * sizeof(uint32_t));
    memcpy(twin.indices, plane.indices + 3 * TT, 3 * sizeof(uint32_t)); /* triangle 0 = old TT */
    CHECK_OK(hearth_ray_fan_cast(fan, &twin, &I, scratch, hits, box, &err), &err);
    size_t won = 0, lost = 0;
    for (size_t p = 0; p < 160 * 120; p++) {
      won += hits[p].prim == 0;
      lost += hits[p].prim == TT + 1; /* the same triangle, later */
    }
    CHECK(won > 0);
    CHECK(lost == 0);

    /* a vertex behind the camera: refused, naming it */
    plane.positions[3 * 7 + 2] = -0.5f;
    hearth_ray_hit *h2 = hits;
    CHECK(hearth_ray_fan_cast(fan, &plane, &I, scratch, h2, box, &err) == HEARTH_E_UNSUPPORTED);
    CHECK(strstr(err.msg, "vertex 7") != NULL);
    free(scratch);
    free(hits);
    hearth_ray_fan_free(fan);
    hearth_mesh_free(&twin);
    hearth_mesh_free(&plane);
  }
  return g_test_failures;
}
