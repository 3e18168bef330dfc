/* Surface distances between two meshes for the recon tests: every vertex
 * of one mesh to the nearest point of the other's triangles (a uniform
 * grid of triangles, exact point-triangle distances). */
#ifndef HEARTH_TEST_MESH_DISTANCE_H
#define HEARTH_TEST_MESH_DISTANCE_H

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/mesh.h"

/* ---- point to mesh distance through a uniform grid of triangles ---------- */
typedef struct tri_grid {
  const hearth_mesh *m;
  double lo[3], cell;
  int n[3];
  size_t *start; /* n0*n1*n2 + 1 */
  uint32_t *tris;
} tri_grid;

static size_t cell_of(const tri_grid *g, int i, int j, int k) {
  return ((size_t)k * g->n[1] + j) * g->n[0] + i;
}

static void tri_grid_build(tri_grid *g, const hearth_mesh *m, double cell) {
  memset(g, 0, sizeof *g);
  g->m = m;
  g->cell = cell;
  double hi[3];
  hearth_mesh_bounds(m, g->lo, hi);
  for (int a = 0; a < 3; a++) g->n[a] = (int)((hi[a] - g->lo[a]) / cell) + 1;
  size_t nc = (size_t)g->n[0] * g->n[1] * g->n[2];
  g->start = calloc(nc + 1, sizeof *g->start);
  for (int pass = 0; pass < 2; pass++) {
    size_t *fill = pass ? calloc(nc, sizeof *fill) : NULL;
    for (size_t t = 0; t < m->n_triangles; t++) {
      int lo[3], up[3];
      for (int a = 0; a < 3; a++) {
        double mn = DBL_MAX, mx = -DBL_MAX;
        for (int c = 0; c < 3; c++) {
          double x = m->positions[3 * (size_t)m->indices[3 * t + c] + a];
          mn = x < mn ? x : mn;
          mx = x > mx ? x : mx;
        }
        lo[a] = (int)((mn - g->lo[a]) / cell);
        up[a] = (int)((mx - g->lo[a]) / cell);
        if (up[a] >= g->n[a]) up[a] = g->n[a] - 1;
      }
      for (int k = lo[2]; k <= up[2]; k++)
        for (int j = lo[1]; j <= up[1]; j++)
          for (int i = lo[0]; i <= up[0]; i++) {
            size_t c = cell_of(g, i, j, k);
            if (pass) g->tris[g->start[c] + fill[c]++] = (uint32_t)t;
            else g->start[c + 1]++;
          }
    }
    if (!pass) {
      for (size_t c = 0; c < nc; c++) g->start[c + 1] += g->start[c];
      g->tris = malloc((g->start[nc] + 1) * sizeof *g->tris);
    }
    free(fill);
  }
}

static void tri_grid_free(tri_grid *g) {
  free(g->start);
  free(g->tris);
}

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Squared distance from p to triangle abc and the closest point q
 * (Voronoi regions of the triangle, Ericson's closest-point construction
 * written out). */
static double point_tri_closest(const double p[3], const double a[3], const double b[3],
                                const double c[3], double q[3]) {
  double ab[3], ac[3], ap[3];
  for (int i = 0; i < 3; i++) {
    ab[i] = b[i] - a[i];
    ac[i] = c[i] - a[i];
    ap[i] = p[i] - a[i];
  }
  double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
  if (d1 <= 0 && d2 <= 0) {
    memcpy(q, a, 3 * sizeof *q);
    goto out;
  }
  double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
  double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= 0 && d4 <= d3) {
    memcpy(q, b, 3 * sizeof *q);
    goto out;
  }
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double v = d1 / (d1 - d3);
    for (int i = 0; i < 3; i++) q[i] = a[i] + v * ab[i];
    goto out;
  }
  double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= 0 && d5 <= d6) {
    memcpy(q, c, 3 * sizeof *q);
    goto out;
  }
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double w = d2 / (d2 - d6);
    for (int i = 0; i < 3; i++) q[i] = a[i] + w * ac[i];
    goto out;
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    for (int i = 0; i < 3; i++) q[i] = b[i] + w * (c[i] - b[i]);
    goto out;
  }
  {
    double den = 1.0 / (va + vb + vc), v = vb * den, w = vc * den;
    for (int i = 0; i < 3; i++) q[i] = a[i] + ab[i] * v + ac[i] * w;
  }
out:
  return (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
         (p[2] - q[2]) * (p[2] - q[2]);
}

static inline double point_tri_d2(const double p[3], const double a[3], const double b[3],
                                  const double c[3]) {
  double q[3];
  return point_tri_closest(p, a, b, c, q);
}

/* Distance from p to the mesh of g (searching rings of cells outwards);
 * tri and q (both may be NULL) get the nearest triangle and point. */
static double tri_grid_nearest(const tri_grid *g, const double p[3], uint32_t *tri, double q[3]);
static inline double tri_grid_dist(const tri_grid *g, const double p[3]) {
  return tri_grid_nearest(g, p, NULL, NULL);
}
static double tri_grid_nearest(const tri_grid *g, const double p[3], uint32_t *tri, double q[3]) {
  int c0[3];
  for (int a = 0; a < 3; a++) c0[a] = (int)floor((p[a] - g->lo[a]) / g->cell);
  double best = DBL_MAX;
  int maxr = g->n[0] + g->n[1] + g->n[2];
  for (int r = 0; r <= maxr; r++) {
    for (int k = c0[2] - r; k <= c0[2] + r; k++)
      for (int j = c0[1] - r; j <= c0[1] + r; j++)
        for (int i = c0[0] - r; i <= c0[0] + r; i++) {
          if (abs(i - c0[0]) != r && abs(j - c0[1]) != r && abs(k - c0[2]) != r) continue;
          if (i < 0 || j < 0 || k < 0 || i >= g->n[0] || j >= g->n[1] || k >= g->n[2]) continue;
          size_t c = cell_of(g, i, j, k);
          for (size_t q_ = g->start[c]; q_ < g->start[c + 1]; q_++) {
            const uint32_t *f = g->m->indices + 3 * (size_t)g->tris[q_];
            double v[3][3];
            for (int e = 0; e < 3; e++)
              for (int a = 0; a < 3; a++) v[e][a] = g->m->positions[3 * (size_t)f[e] + a];
            double qq[3], d2 = point_tri_closest(p, v[0], v[1], v[2], qq);
            if (d2 < best) {
              best = d2;
              if (tri) *tri = g->tris[q_];
              if (q) memcpy(q, qq, sizeof qq);
            }
          }
        }
    /* every point within r cells of p's cell has been seen */
    if (best < DBL_MAX && sqrt(best) <= r * g->cell) break;
  }
  return sqrt(best);
}

/* RMS and max distance of a's vertices to mesh b. */
static inline void mesh_to_mesh(const hearth_mesh *a, const hearth_mesh *b, double *rms,
                                double *mx) {
  tri_grid g;
  tri_grid_build(&g, b, 0.004);
  double s = 0, m = 0;
  for (size_t v = 0; v < a->n_vertices; v++) {
    double p[3] = {a->positions[3 * v], a->positions[3 * v + 1], a->positions[3 * v + 2]};
    double d = tri_grid_dist(&g, p);
    s += d * d;
    if (d > m) m = d;
  }
  *rms = a->n_vertices ? sqrt(s / a->n_vertices) : 0;
  *mx = m;
  tri_grid_free(&g);
}

#endif
