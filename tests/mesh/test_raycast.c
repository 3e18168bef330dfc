/* Ray caster against closed forms: a unit cube and an icosphere. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/core.h"
#include "hearth/geom.h"
#include "hearth/mesh.h"
#include "test_util.h"
#include "mesh/cube_mesh.h"

/* icosphere of radius 1 with `sub` subdivisions (no vertex sharing needed) */
static void make_icosphere(hearth_mesh *m, int sub) {
  const double p = (1.0 + sqrt(5.0)) / 2.0;
  double v[12][3] = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                     {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  static const int f[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  size_t ntri = 20;
  for (int s = 0; s < sub; s++) ntri *= 4;
  double *tris = malloc(ntri * 9 * sizeof(double));
  size_t cur = 20;
  for (int i = 0; i < 20; i++)
    for (int k = 0; k < 3; k++) {
      double n = sqrt(v[f[i][k]][0] * v[f[i][k]][0] + v[f[i][k]][1] * v[f[i][k]][1] +
                      v[f[i][k]][2] * v[f[i][k]][2]);
      for (int c = 0; c < 3; c++) tris[i * 9 + k * 3 + c] = v[f[i][k]][c] / n;
    }
  for (int s = 0; s < sub; s++) {
    double *nt = malloc(cur * 4 * 9 * sizeof(double));
    for (size_t i = 0; i < cur; i++) {
      const double *a = tris + i * 9, *b = a + 3, *c = a + 6;
      double ab[3], bc[3], ca[3];
      for (int d = 0; d < 3; d++) {
        ab[d] = a[d] + b[d];
        bc[d] = b[d] + c[d];
        ca[d] = c[d] + a[d];
      }
      double *mids[3] = {ab, bc, ca};
      for (int q = 0; q < 3; q++) {
        double n =
            sqrt(mids[q][0] * mids[q][0] + mids[q][1] * mids[q][1] + mids[q][2] * mids[q][2]);
        for (int d = 0; d < 3; d++) mids[q][d] /= n;
      }
      const double *out[4][3] = {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}};
      for (int q = 0; q < 4; q++)
        for (int k = 0; k < 3; k++)
          for (int d = 0; d < 3; d++) nt[(i * 4 + q) * 9 + k * 3 + d] = out[q][k][d];
    }
    free(tris);
    tris = nt;
    cur *= 4;
  }
  hearth_err err;
  CHECK_OK(hearth_mesh_alloc(m, ntri * 3, ntri, 0, &err), &err);
  for (size_t i = 0; i < ntri * 9; i++) m->positions[i] = (float)tris[i];
  for (size_t i = 0; i < ntri * 3; i++) m->indices[i] = (uint32_t)i;
  free(tris);
}

typedef struct par_ctx {
  const hearth_raycaster *rc;
  const float *org, *dir;
  hearth_ray_hit *hits;
} par_ctx;

static void par_single(void *vctx, size_t b, size_t e, int t) {
  par_ctx *c = vctx;
  for (size_t i = b; i < e; i++) {
    double o[3] = {c->org[i * 3], c->org[i * 3 + 1], c->org[i * 3 + 2]};
    double d[3] = {c->dir[i * 3], c->dir[i * 3 + 1], c->dir[i * 3 + 2]};
    if (!hearth_raycast(c->rc, o, d, 0.0, INFINITY, &c->hits[i])) c->hits[i].prim = UINT32_MAX;
  }
}

/* Batch (16-wide packets) and single casts agree exactly, except that a ray
 * through an edge or vertex shared by several triangles at the same t may
 * report either triangle (traversal order differs); such a tie must have
 * the same t and lie on the boundary of both triangles. */
static int on_boundary(const hearth_ray_hit *h) {
  double b0 = 1.0 - h->b1 - h->b2;
  return fmin(b0, fmin(h->b1, h->b2)) < 1e-4;
}

static int same_hit(const hearth_ray_hit *a, const hearth_ray_hit *b) {
  if ((a->prim == UINT32_MAX) != (b->prim == UINT32_MAX)) return 0;
  if (a->prim == UINT32_MAX) return 1;
  if (a->prim != b->prim) return a->t == b->t && on_boundary(a) && on_boundary(b);
  return a->t == b->t && a->b1 == b->b1 && a->b2 == b->b2 && a->front == b->front;
}

int main(void) {
  hearth_err err;
  hearth_mesh cube;
  make_cube(&cube);
  CHECK_OK(hearth_mesh_validate(&cube, "cube", &err), &err);
  hearth_raycaster *rc = NULL;
  CHECK_OK(hearth_raycaster_new(&cube, &rc, &err), &err);
  /* from outside along each axis: hits the facing face at 2.5, front side;
   * the normal of each face's triangles points outward, so this also pins
   * the sign convention of `front` */
  for (int axis = 0; axis < 3; axis++)
    for (int sgn = -1; sgn <= 1; sgn += 2) {
      double o[3] = {0.1, -0.2, 0.15}, d[3] = {0, 0, 0};
      o[axis] = 3.0 * sgn;
      d[axis] = -sgn;
      hearth_ray_hit h;
      CHECK(hearth_raycast(rc, o, d, 0.0, INFINITY, &h) == 1);
      CHECK_NEAR(h.t, 2.5, 1e-6);
      CHECK(h.front == 1);
      int face = axis * 2 + (sgn > 0);
      CHECK_MSG(h.prim / 2 == (uint32_t)face, "axis %d sign %d: hit triangle %u", axis, sgn,
                h.prim);
      /* barycentrics reproduce the hit point */
      const uint32_t *t = cube.indices + h.prim * 3;
      for (int k = 0; k < 3; k++) {
        double p = (1 - h.b1 - h.b2) * cube.positions[t[0] * 3 + k] +
                   h.b1 * cube.positions[t[1] * 3 + k] + h.b2 * cube.positions[t[2] * 3 + k];
        CHECK_NEAR(p, o[k] + h.t * d[k], 1e-6);
      }
      /* from inside going the same way: the far face, back side */
      double oi[3] = {0.1, -0.2, 0.15};
      CHECK(hearth_raycast(rc, oi, d, 0.0, INFINITY, &h) == 1);
      CHECK_NEAR(h.t, 0.5 - (-sgn) * oi[axis], 1e-6);
      CHECK(h.front == 0);
      CHECK(h.prim / 2 == (uint32_t)(axis * 2 + (sgn < 0)));
      /* tfar shorter than the hit: miss; tnear beyond the near face: far face */
      CHECK(hearth_raycast(rc, o, d, 0.0, 2.4, &h) == 0 && h.prim == UINT32_MAX);
      CHECK(hearth_raycast(rc, o, d, 2.6, INFINITY, &h) == 1);
      CHECK_NEAR(h.t, 3.5, 1e-6);
      CHECK(h.front == 0);
    }
  /* oblique ray from inside: t = 0.5 / max |d_i| for unit d */
  {
    hearth_rng rng;
    hearth_rng_seed(&rng, 3);
    for (int i = 0; i < 1000; i++) {
      double d[3] = {hearth_rng_normal(&rng), hearth_rng_normal(&rng), hearth_rng_normal(&rng)};
      double n = hearth_norm3(d);
      for (int k = 0; k < 3; k++) d[k] /= n;
      double o[3] = {0, 0, 0}, mx = fmax(fabs(d[0]), fmax(fabs(d[1]), fabs(d[2])));
      hearth_ray_hit h;
      CHECK(hearth_raycast(rc, o, d, 0.0, INFINITY, &h) == 1);
      CHECK_NEAR(h.t, 0.5 / mx, 1e-5);
      CHECK(h.front == 0);
    }
  }
  /* misses: parallel offset, pointing away, degenerate direction */
  {
    double o[3] = {0.7, 0, -3}, d[3] = {0, 0, 1}, z[3] = {0, 0, 0}, far[3] = {0, 0, -3},
           away[3] = {0, 0, -1};
    hearth_ray_hit h;
    CHECK(hearth_raycast(rc, o, d, 0.0, INFINITY, &h) == 0);
    CHECK(h.prim == UINT32_MAX);
    CHECK(hearth_raycast(rc, far, away, 0.0, INFINITY, &h) == 0);
    CHECK(hearth_raycast(rc, far, z, 0.0, INFINITY, &h) == 0);
    double nanv[3] = {NAN, 0, 1};
    CHECK(hearth_raycast(rc, far, nanv, 0.0, INFINITY, &h) == 0);
  }
  /* any-hit queries: the cube's closed form off its edges, the same answer
   * as the nearest-hit query everywhere (edges and corners included), and
   * the (tnear, tfar) interval respected */
  {
    int n_in = 0;
    for (int iy = -24; iy <= 24; iy++)
      for (int ix = -24; ix <= 24; ix++) {
        double o[3] = {ix * 0.025, iy * 0.025, -3.0}, d[3] = {0.01 * ix, -0.005 * iy, 1.0};
        hearth_ray_hit h;
        int any = hearth_raycast_any(rc, o, d, 0.0, INFINITY);
        CHECK_MSG(any == hearth_raycast(rc, o, d, 0.0, INFINITY, &h), "ray %d %d", ix, iy);
        /* where the ray enters the plane z = -0.5 */
        double x = o[0] + 2.5 * d[0], y = o[1] + 2.5 * d[1];
        if (fabs(fabs(x) - 0.5) > 1e-6 && fabs(fabs(y) - 0.5) > 1e-6 && fabs(x) < 0.5 &&
            fabs(y) < 0.5) {
          CHECK_MSG(any == 1, "ray %d %d through the face", ix, iy);
          n_in++;
        }
      }
    CHECK(n_in > 100);
    double o[3] = {0.1, -0.2, -3.0}, d[3] = {0, 0, 1}, nanv[3] = {NAN, 0, 1}, z[3] = {0, 0, 0};
    CHECK(hearth_raycast_any(rc, o, d, 0.0, 2.4) == 0);
    CHECK(hearth_raycast_any(rc, o, d, 2.6, INFINITY) == 1);
    CHECK(hearth_raycast_any(rc, o, d, 3.6, INFINITY) == 0);
    CHECK(hearth_raycast_any(rc, o, nanv, 0.0, INFINITY) == 0);
    CHECK(hearth_raycast_any(rc, o, z, 0.0, INFINITY) == 0);
  }
  hearth_raycaster_free(rc);

  /* a mesh with an out-of-range index is refused with the triangle named */
  {
    hearth_mesh bad;
    CHECK_OK(hearth_mesh_copy(&cube, &bad, &err), &err);
    bad.indices[7 * 3 + 1] = 8;
    hearth_raycaster *r2 = (hearth_raycaster *)1;
    CHECK(hearth_raycaster_new(&bad, &r2, &err) == HEARTH_E_RANGE);
    CHECK(r2 == NULL);
    CHECK_MSG(strstr(err.msg, "triangle 7") != NULL, "message: %s", err.msg);
    hearth_mesh_free(&bad);
  }

  /* icosphere: closed-form bounds, batch == single, thread independence */
  {
    hearth_mesh ico;
    make_icosphere(&ico, 4); /* 5120 triangles */
    hearth_raycaster *r3 = NULL;
    CHECK_OK(hearth_raycaster_new(&ico, &r3, &err), &err);
    /* inradius: smallest distance from the centre to a triangle's plane */
    double r_in = 1.0;
    for (size_t t = 0; t < ico.n_triangles; t++) {
      const float *a = ico.positions + t * 9, *b = a + 3, *c = a + 6;
      double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, nrm[3];
      double av[3] = {a[0], a[1], a[2]};
      hearth_cross3(e1, e2, nrm);
      double dist = hearth_dot3(nrm, av) / hearth_norm3(nrm);
      CHECK(dist > 0); /* counter-clockwise seen from outside */
      r_in = fmin(r_in, dist);
    }
    size_t n = 20000;
    float *org = malloc(n * 3 * sizeof(float)), *dir = malloc(n * 3 * sizeof(float));
    hearth_ray_hit *hb = malloc(n * sizeof *hb), *hs = malloc(n * sizeof *hs);
    hearth_rng rng;
    hearth_rng_seed(&rng, 11);
    for (size_t i = 0; i < n; i++) {
      /* half from outside towards a point near the centre, half from inside */
      double o[3], target[3], d[3];
      int outside = (i % 2) == 0;
      for (int k = 0; k < 3; k++) {
        o[k] = outside ? 3.0 * hearth_rng_normal(&rng) : 0.3 * hearth_rng_range(&rng, -1, 1);
        target[k] = hearth_rng_range(&rng, -1.4, 1.4) * (outside ? 1.0 : 0.0) +
                    (outside ? 0.0 : hearth_rng_normal(&rng));
      }
      if (outside && hearth_norm3(o) < 1.5) o[0] += 3.0;
      for (int k = 0; k < 3; k++) d[k] = target[k] - o[k];
      double nd = hearth_norm3(d);
      for (int k = 0; k < 3; k++) {
        org[i * 3 + k] = (float)o[k];
        dir[i * 3 + k] = (float)(d[k] / nd);
      }
    }
    double t0 = hearth_now();
    hearth_raycast_batch(r3, n, org, dir, 0.0f, INFINITY, hb);
    double t1 = hearth_now();
    par_ctx pc = {r3, org, dir, hs};
    hearth_parallel_for(n, 2, par_single, &pc);
    size_t mismatches = 0, hits = 0, checked = 0;
    for (size_t i = 0; i < n; i++) {
      if (!same_hit(&hb[i], &hs[i])) mismatches++;
      if (hb[i].prim == UINT32_MAX) continue;
      hits++;
      /* the hit point lies between the inscribed and circumscribed spheres */
      double p[3];
      for (int k = 0; k < 3; k++) p[k] = org[i * 3 + k] + (double)hb[i].t * dir[i * 3 + k];
      double rp = hearth_norm3(p);
      CHECK_MSG(rp <= 1.0 + 1e-5 && rp >= r_in - 1e-5, "ray %zu: hit radius %g", i, rp);
      /* closed-form front flag: rays from outside hit the outer side */
      double o[3] = {org[i * 3], org[i * 3 + 1], org[i * 3 + 2]};
      CHECK(hb[i].front == (hearth_norm3(o) > 1.0));
      {
        const float *q = ico.positions + hb[i].prim * 9;
        double e1[3] = {q[3] - q[0], q[4] - q[1], q[5] - q[2]};
        double e2[3] = {q[6] - q[0], q[7] - q[1], q[8] - q[2]}, nc[3];
        double dd[3] = {dir[i * 3], dir[i * 3 + 1], dir[i * 3 + 2]};
        hearth_cross3(e1, e2, nc);
        CHECK(hb[i].front == (hearth_dot3(dd, nc) < 0.0));
      }
      /* the barycentric point equals the ray point */
      const float *a = ico.positions + hb[i].prim * 9;
      for (int k = 0; k < 3; k++) {
        double q = (1 - hb[i].b1 - hb[i].b2) * a[k] + hb[i].b1 * a[3 + k] + hb[i].b2 * a[6 + k];
        CHECK_NEAR(q, p[k], 1e-5);
      }
      checked++;
    }
    /* every ray from inside must hit; outside rays aimed inside radius ~0.8 as well */
    for (size_t i = 1; i < n; i += 2) CHECK(hb[i].prim != UINT32_MAX);
    printf("icosphere: %zu rays, %zu hits, %zu batch/single mismatches, batch %.0f rays/s\n", n,
           hits, mismatches, (double)n / (t1 - t0));
    CHECK(mismatches == 0);
    CHECK(checked == hits && hits > n / 2);
    /* determinism: a second batch is bit-identical */
    hearth_raycast_batch(r3, n, org, dir, 0.0f, INFINITY, hs);
    CHECK(memcmp(hb, hs, n * sizeof *hb) == 0 || mismatches != 0);
    for (size_t i = 0; i < n; i++) CHECK(same_hit(&hb[i], &hs[i]));
    /* the same batch on one thread is bit-identical */
    setenv("HEARTH_THREADS", "1", 1);
    hearth_raycast_batch(r3, n, org, dir, 0.0f, INFINITY, hs);
    unsetenv("HEARTH_THREADS");
    for (size_t i = 0; i < n; i++)
      CHECK(hb[i].prim == hs[i].prim && (hb[i].prim == UINT32_MAX || hb[i].t == hs[i].t));
    /* a small batch (single-threaded path, partial packet) agrees too */
    hearth_raycast_batch(r3, 37, org + 3 * 100, dir + 3 * 100, 0.0f, INFINITY, hs);
    for (size_t i = 0; i < 37; i++) CHECK(same_hit(&hb[100 + i], &hs[i]));
    /* tfar cuts every hit */
    hearth_raycast_batch(r3, 1000, org, dir, 0.0f, 1e-3f, hs);
    for (size_t i = 0; i < 1000; i++) CHECK(hs[i].prim == UINT32_MAX || hs[i].t <= 1e-3f);
    free(org);
    free(dir);
    free(hb);
    free(hs);
    hearth_raycaster_free(r3);
    hearth_mesh_free(&ico);
  }

  /* an empty mesh builds and never hits */
  {
    hearth_mesh empty;
    CHECK_OK(hearth_mesh_alloc(&empty, 0, 0, 0, &err), &err);
    hearth_raycaster *r4 = NULL;
    CHECK_OK(hearth_raycaster_new(&empty, &r4, &err), &err);
    double o[3] = {0, 0, 0}, d[3] = {0, 0, 1};
    hearth_ray_hit h;
    if (r4) CHECK(hearth_raycast(r4, o, d, 0, INFINITY, &h) == 0);
    hearth_raycaster_free(r4);
    hearth_mesh_free(&empty);
  }
  hearth_mesh_free(&cube);
  TEST_MAIN_END();
}
