/* UV islands and texel rasterisation against closed forms. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/core.h"
#include "hearth/mesh.h"
#include "test_util.h"

/* append an axis-aligned UV quad [u0,u1]x[v0,v1] as two triangles with their
 * own 4 vertices; `flip` reverses the winding */
static void add_quad(hearth_mesh *m, size_t *nv, size_t *nt, float u0, float v0, float u1, float v1,
                     int flip) {
  float uv[4][2] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
  size_t b = *nv;
  for (int k = 0; k < 4; k++) {
    m->uvs[(b + k) * 2] = uv[k][0];
    m->uvs[(b + k) * 2 + 1] = uv[k][1];
    m->positions[(b + k) * 3] = uv[k][0];
    m->positions[(b + k) * 3 + 1] = uv[k][1];
    m->positions[(b + k) * 3 + 2] = 0.0f;
  }
  uint32_t t[6] = {0, 1, 2, 0, 2, 3};
  if (flip) {
    t[1] = 2;
    t[2] = 1;
    t[4] = 3;
    t[5] = 2;
  }
  for (int k = 0; k < 6; k++) m->indices[*nt * 3 + k] = (uint32_t)(b + t[k]);
  *nv += 4;
  *nt += 2;
}

/* number of texel centres (c+0.5)/R in [a, b] (closed interval) */
static long centres_in(double a, double b, size_t R) {
  long lo = (long)ceil(a * (double)R - 0.5), hi = (long)floor(b * (double)R - 0.5);
  if (lo < 0) lo = 0;
  if (hi > (long)R - 1) hi = (long)R - 1;
  return hi >= lo ? hi - lo + 1 : 0;
}

int main(void) {
  hearth_err err;
  /* two separated quads -> 2 islands; each quad (2 triangles sharing the
   * diagonal, with duplicated but identical UV vertices) -> 1 island */
  {
    hearth_mesh m;
    CHECK_OK(hearth_mesh_alloc(&m, 8, 4, 1, &err), &err);
    size_t nv = 0, nt = 0;
    add_quad(&m, &nv, &nt, 0.1f, 0.1f, 0.4f, 0.3f, 0);
    add_quad(&m, &nv, &nt, 0.6f, 0.5f, 0.9f, 0.8f, 1);
    uint32_t isl[4], n = 0;
    CHECK_OK(hearth_uv_islands(&m, isl, &n, &err), &err);
    CHECK(n == 2);
    CHECK(isl[0] == 0 && isl[1] == 0 && isl[2] == 1 && isl[3] == 1);
    /* duplicate the shared diagonal vertices: welding must still join them */
    hearth_mesh w;
    CHECK_OK(hearth_mesh_alloc(&w, 6, 2, 1, &err), &err);
    float uvs[6][2] = {{0.1f, 0.1f}, {0.4f, 0.1f}, {0.4f, 0.3f},
                       {0.1f, 0.1f}, {0.4f, 0.3f}, {0.1f, 0.3f}};
    for (int i = 0; i < 6; i++) {
      w.uvs[i * 2] = uvs[i][0];
      w.uvs[i * 2 + 1] = uvs[i][1];
      w.positions[i * 3] = w.positions[i * 3 + 1] = w.positions[i * 3 + 2] = 0.0f;
      w.indices[i] = (uint32_t)i;
    }
    CHECK_OK(hearth_uv_islands(&w, isl, &n, &err), &err);
    CHECK(n == 1 && isl[0] == 0 && isl[1] == 0);
    /* touching at one corner only is not an edge: two islands */
    w.uvs[3 * 2] = 0.4f;
    w.uvs[3 * 2 + 1] = 0.3f; /* tri 1 = (0.4,0.3),(0.7,0.3),(0.7,0.5) */
    w.uvs[4 * 2] = 0.7f;
    w.uvs[4 * 2 + 1] = 0.3f;
    w.uvs[5 * 2] = 0.7f;
    w.uvs[5 * 2 + 1] = 0.5f;
    CHECK_OK(hearth_uv_islands(&w, isl, &n, &err), &err);
    CHECK(n == 2 && isl[0] == 0 && isl[1] == 1);
    /* a seam: same 3-D edge but different UVs -> separate islands even with
     * a shared position index */
    hearth_mesh_free(&w);

    /* a fan of 200 triangles around one centre (a vertex with hundreds of
     * edges): neighbours join along their shared spoke, except across the
     * closing spoke, whose two sides carry different UVs (a seam), and
     * across spoke 0-101, which triangle 99 no longer has -> two islands */
    {
      enum { NF = 200 };
      hearth_mesh f;
      CHECK_OK(hearth_mesh_alloc(&f, NF + 2, NF, 1, &err), &err);
      f.uvs[0] = 0.5f, f.uvs[1] = 0.5f; /* centre */
      for (int i = 0; i <= NF; i++) {   /* ring vertices 1..NF+1 (NF+1 duplicates 1 in 3-D) */
        double a = 2.0 * 3.141592653589793 * (i % NF) / NF;
        f.uvs[2 * (1 + i)] = (float)(0.5 + 0.4 * cos(a));
        f.uvs[2 * (1 + i) + 1] = (float)(0.5 + 0.4 * sin(a));
      }
      f.uvs[2 * (NF + 1)] += 0.01f; /* the closing spoke's second copy: a seam */
      for (size_t k = 0; k < 3 * (size_t)(NF + 2); k++) f.positions[k] = 0.0f;
      for (int t = 0; t < NF; t++) {
        f.indices[3 * t] = 0;
        f.indices[3 * t + 1] = (uint32_t)(1 + t);
        f.indices[3 * t + 2] = (uint32_t)(2 + t);
      }
      /* triangle 99 loses its corner 101 (degenerate now, but it still
         shares spoke 0-100 with triangle 98) */
      f.indices[3 * 99 + 2] = 0;
      uint32_t fisl[NF], fn = 0;
      CHECK_OK(hearth_uv_islands(&f, fisl, &fn, &err), &err);
      CHECK_MSG(fn == 2, "fan: %u islands", fn);
      int ok = 1;
      for (int t = 0; t < NF; t++) ok &= fisl[t] == (t < 100 ? 0u : 1u);
      CHECK(ok);
      hearth_mesh_free(&f);
    }

    /* rasterised coverage of a quad equals the closed-form texel count */
    size_t Rs[3] = {64, 100, 1024};
    for (int ri = 0; ri < 3; ri++) {
      size_t R = Rs[ri];
      uint32_t *tri = malloc(R * R * sizeof *tri);
      float *bary = malloc(R * R * 3 * sizeof *bary);
      CHECK_OK(hearth_uv_rasterize(&m, R, tri, bary, &err), &err);
      long cov[2] = {0, 0};
      double worst = 0.0;
      for (size_t row = 0; row < R; row++)
        for (size_t col = 0; col < R; col++) {
          uint32_t t = tri[row * R + col];
          if (t == UINT32_MAX) continue;
          CHECK(t < 4);
          cov[t / 2]++;
          /* barycentrics reproduce the texel-centre UV */
          const float *b = bary + (row * R + col) * 3;
          double u = 0, v = 0;
          for (int k = 0; k < 3; k++) {
            uint32_t vi = m.indices[t * 3 + k];
            u += b[k] * m.uvs[vi * 2];
            v += b[k] * m.uvs[vi * 2 + 1];
          }
          worst = fmax(worst, fmax(fabs(u - (col + 0.5) / R), fabs(v - (row + 0.5) / R)));
          CHECK(b[0] >= -1e-6f && b[1] >= -1e-6f && b[2] >= -1e-6f);
          CHECK(fabs(b[0] + b[1] + b[2] - 1.0) < 1e-5);
        }
      long e0 = centres_in(0.1f, 0.4f, R) * centres_in(0.1f, 0.3f, R);
      long e1 = centres_in(0.6f, 0.9f, R) * centres_in(0.5f, 0.8f, R);
      printf("R=%zu: coverage %ld, %ld (closed form %ld, %ld), barycentric UV error %.3g\n", R,
             cov[0], cov[1], e0, e1, worst);
      CHECK(cov[0] == e0 && cov[1] == e1);
      CHECK(worst < 1e-5);
      /* without barycentrics: same triangle map */
      uint32_t *tri2 = malloc(R * R * sizeof *tri2);
      CHECK_OK(hearth_uv_rasterize(&m, R, tri2, NULL, &err), &err);
      CHECK(memcmp(tri, tri2, R * R * sizeof *tri) == 0);
      free(tri2);
      free(tri);
      free(bary);
    }
    /* texels on the shared diagonal go to the lower triangle index: with
     * R = 10 and a quad [0.05, 0.95]^2 the diagonal passes through centres */
    {
      hearth_mesh d;
      CHECK_OK(hearth_mesh_alloc(&d, 4, 2, 1, &err), &err);
      size_t nv2 = 0, nt2 = 0;
      add_quad(&d, &nv2, &nt2, 0.05f, 0.05f, 0.95f, 0.95f, 0);
      /* use exactly representable coordinates: 0.0625 and 0.9375 on R = 16 */
      float q[4][2] = {{0.03125f, 0.03125f},
                       {0.96875f, 0.03125f},
                       {0.96875f, 0.96875f},
                       {0.03125f, 0.96875f}};
      for (int k = 0; k < 4; k++) {
        d.uvs[k * 2] = q[k][0];
        d.uvs[k * 2 + 1] = q[k][1];
      }
      size_t R = 16;
      uint32_t tri[256];
      CHECK_OK(hearth_uv_rasterize(&d, R, tri, NULL, &err), &err);
      /* centres (c+0.5)/16 all lie in [1/32, 31/32]: full coverage */
      int full = 1;
      for (int i = 0; i < 256; i++) full &= tri[i] != UINT32_MAX;
      CHECK(full);
      /* diagonal (row == col) belongs to both; lowest index 0 wins; the
       * triangle (0,1,2) is the part with col >= row */
      for (size_t r = 0; r < R; r++)
        for (size_t c = 0; c < R; c++) CHECK(tri[r * R + c] == (c >= r ? 0u : 1u));
      /* swap the triangle order: the diagonal goes to the new lowest */
      for (int k = 0; k < 3; k++) {
        uint32_t tmp = d.indices[k];
        d.indices[k] = d.indices[3 + k];
        d.indices[3 + k] = tmp;
      }
      CHECK_OK(hearth_uv_rasterize(&d, R, tri, NULL, &err), &err);
      for (size_t r = 0; r < R; r++)
        for (size_t c = 0; c < R; c++) CHECK(tri[r * R + c] == (c > r ? 1u : 0u));
      hearth_mesh_free(&d);
    }
    /* bad input: index out of range names the triangle */
    m.indices[3 * 3 + 2] = 99;
    uint32_t tri1[16];
    CHECK(hearth_uv_rasterize(&m, 4, tri1, NULL, &err) == HEARTH_E_RANGE);
    CHECK_MSG(strstr(err.msg, "triangle 3") != NULL, "%s", err.msg);
    CHECK(hearth_uv_islands(&m, isl, &n, &err) == HEARTH_E_RANGE);
    m.indices[3 * 3 + 2] = 5;
    m.uvs[5] = NAN;
    CHECK(hearth_uv_rasterize(&m, 4, tri1, NULL, &err) == HEARTH_E_RANGE);
    CHECK_MSG(strstr(err.msg, "vertex 2") != NULL, "%s", err.msg);
    hearth_mesh_free(&m);
  }

  /* a large random-ish mesh: a 300x300 grid of UV squares in 2 triangles
   * each (180k triangles) on R = 1024. The grid is one island; the union of
   * triangles covers every texel of its square exactly once. */
  {
    size_t G = 300, nt = G * G * 2, nv = (G + 1) * (G + 1);
    hearth_mesh g;
    CHECK_OK(hearth_mesh_alloc(&g, nv, nt, 1, &err), &err);
    for (size_t j = 0; j <= G; j++)
      for (size_t i = 0; i <= G; i++) {
        size_t v = j * (G + 1) + i;
        /* jitter interior grid points deterministically to make slanted edges */
        double du = 0, dv = 0;
        if (i > 0 && i < G && j > 0 && j < G) {
          du = 0.3 * sin((double)(i * 7 + j * 3));
          dv = 0.3 * cos((double)(i * 5 + j * 11));
        }
        g.uvs[v * 2] = (float)((0.1 + 0.8 * (i + du) / G));
        g.uvs[v * 2 + 1] = (float)((0.1 + 0.8 * (j + dv) / G));
        g.positions[v * 3] = g.uvs[v * 2];
        g.positions[v * 3 + 1] = g.uvs[v * 2 + 1];
        g.positions[v * 3 + 2] = 0;
      }
    for (size_t j = 0; j < G; j++)
      for (size_t i = 0; i < G; i++) {
        uint32_t a = (uint32_t)(j * (G + 1) + i), b = a + 1, c = a + (uint32_t)G + 2,
                 d = a + (uint32_t)G + 1;
        uint32_t *t = g.indices + (j * G + i) * 6;
        t[0] = a;
        t[1] = b;
        t[2] = c;
        t[3] = a;
        t[4] = c;
        t[5] = d;
      }
    uint32_t *isl = malloc(nt * sizeof *isl), n = 0;
    double t0 = hearth_now();
    CHECK_OK(hearth_uv_islands(&g, isl, &n, &err), &err);
    double t1 = hearth_now();
    CHECK(n == 1);
    size_t R = 1024;
    uint32_t *tri = malloc(R * R * sizeof *tri);
    float *bary = malloc(R * R * 3 * sizeof *bary);
    CHECK_OK(hearth_uv_rasterize(&g, R, tri, bary, &err), &err);
    double t2 = hearth_now();
    /* no holes: every centre inside the outer square [0.1, 0.9]^2 (whose
     * border is not jittered) is covered, and none outside */
    long holes = 0, outside = 0;
    for (size_t r = 0; r < R; r++)
      for (size_t c = 0; c < R; c++) {
        double u = (c + 0.5) / R, v = (r + 0.5) / R;
        int in = u >= 0.1f && u <= 0.9f && v >= 0.1f && v <= 0.9f;
        uint32_t t = tri[r * R + c];
        if (in && t == UINT32_MAX) holes++;
        if (!in && t != UINT32_MAX) outside++;
      }
    printf("grid %zu triangles: islands %.3f s, rasterise R=%zu %.3f s, holes %ld, outside %ld\n",
           nt, t1 - t0, R, t2 - t1, holes, outside);
    CHECK(holes == 0 && outside == 0);
    /* deterministic regardless of thread count */
    uint32_t *tri1t = malloc(R * R * sizeof *tri1t);
    setenv("HEARTH_THREADS", "1", 1);
    CHECK_OK(hearth_uv_rasterize(&g, R, tri1t, NULL, &err), &err);
    unsetenv("HEARTH_THREADS");
    CHECK(memcmp(tri, tri1t, R * R * sizeof *tri) == 0);
    free(tri1t);
    free(tri);
    free(bary);
    free(isl);
    hearth_mesh_free(&g);
  }
  TEST_MAIN_END();
}
