/* Ordering candidate hole centres by the plate's triangular lattice.
 *
 * Every hole has six lattice neighbours that come in opposite pairs; that is
 * affine invariant, so a seed hole and its neighbours fix a local lattice
 * basis (up to the six lattice rotations). A breadth-first walk predicts each
 * neighbour with a locally refitted affine map, so perspective and lens
 * distortion only need to be locally mild. The labelled set must then be
 * exactly the plate's 84 positions under one of the six rotations: the 11/10
 * row pattern admits only one, which fixes the orientation. Anything else is
 * a reasoned failure, never a guess. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"

#define KNN 8
#define LAB_HALF 48
#define LAB_SIDE (2 * LAB_HALF + 1)
#define MAX_CAND 4000

/* lattice offsets of the six neighbours in increasing image angle */
static const int NB[6][2] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};

typedef struct order_ctx {
  const double (*p)[2];
  size_t n;
  int (*knn)[KNN];
  int *lab_a, *lab_b, *has;
  double (*A)[4]; /* local affine lattice -> image: col (1,0) then (0,1) */
  int *grid;      /* LAB_SIDE^2 point index or -1 */
} order_ctx;

static double dist2(const double *a, const double *b) {
  double dx = a[0] - b[0], dy = a[1] - b[1];
  return dx * dx + dy * dy;
}

static void build_knn(order_ctx *c) {
  for (size_t i = 0; i < c->n; i++) {
    double best[KNN];
    for (int k = 0; k < KNN; k++) {
      best[k] = INFINITY;
      c->knn[i][k] = -1;
    }
    for (size_t j = 0; j < c->n; j++) {
      if (j == i) continue;
      double d = dist2(c->p[i], c->p[j]);
      if (d >= best[KNN - 1]) continue;
      int k = KNN - 1;
      while (k > 0 && best[k - 1] > d) {
        best[k] = best[k - 1];
        c->knn[i][k] = c->knn[i][k - 1];
        k--;
      }
      best[k] = d;
      c->knn[i][k] = (int)j;
    }
  }
}

/* least-squares affine from lattice offsets l to image offsets v */
static int fit_affine(const int (*l)[2], const double (*v)[2], int m, double A[4]) {
  double S[4] = {0}, Bx[2] = {0}, By[2] = {0};
  for (int k = 0; k < m; k++) {
    double a = l[k][0], b = l[k][1];
    S[0] += a * a;
    S[1] += a * b;
    S[3] += b * b;
    Bx[0] += a * v[k][0];
    Bx[1] += b * v[k][0];
    By[0] += a * v[k][1];
    By[1] += b * v[k][1];
  }
  S[2] = S[1];
  double det = S[0] * S[3] - S[1] * S[2];
  if (fabs(det) < 1e-9) return 0;
  /* A = [ax bx; ay by] with image = A * (a, b) */
  double ax = (S[3] * Bx[0] - S[1] * Bx[1]) / det, bx = (S[0] * Bx[1] - S[2] * Bx[0]) / det;
  double ay = (S[3] * By[0] - S[1] * By[1]) / det, by = (S[0] * By[1] - S[2] * By[0]) / det;
  A[0] = ax;
  A[1] = bx;
  A[2] = ay;
  A[3] = by;
  return ax * by - bx * ay > 0; /* orientation preserving */
}

/* is point i the centre of a clean hexagon of its six nearest neighbours? */
static int seed_basis(const order_ctx *c, size_t i, double A[4], int nb_idx[6]) {
  const double *p = c->p[i];
  int idx[6];
  double ang[6], v[6][2];
  for (int k = 0; k < 6; k++) {
    idx[k] = c->knn[i][k];
    if (idx[k] < 0) return 0;
  }
  /* sixth and seventh neighbours must be clearly separated */
  if (c->knn[i][6] >= 0) {
    double d6 = dist2(p, c->p[c->knn[i][5]]), d7 = dist2(p, c->p[c->knn[i][6]]);
    if (d7 < d6 * 1.1) return 0;
  }
  for (int k = 0; k < 6; k++) {
    v[k][0] = c->p[idx[k]][0] - p[0];
    v[k][1] = c->p[idx[k]][1] - p[1];
    ang[k] = atan2(v[k][1], v[k][0]);
  }
  /* sort by angle */
  for (int a = 1; a < 6; a++)
    for (int b = a; b > 0 && ang[b - 1] > ang[b]; b--) {
      double t = ang[b];
      ang[b] = ang[b - 1];
      ang[b - 1] = t;
      int ti = idx[b];
      idx[b] = idx[b - 1];
      idx[b - 1] = ti;
      double tv[2] = {v[b][0], v[b][1]};
      v[b][0] = v[b - 1][0];
      v[b][1] = v[b - 1][1];
      v[b - 1][0] = tv[0];
      v[b - 1][1] = tv[1];
    }
  /* opposite pairs cancel and v1 = v0 + v2 (hexagon relations) */
  double scale = 0;
  for (int k = 0; k < 6; k++) scale += hypot(v[k][0], v[k][1]);
  scale /= 6;
  double tol = 0.15 * scale;
  for (int k = 0; k < 3; k++)
    if (hypot(v[k][0] + v[k + 3][0], v[k][1] + v[k + 3][1]) > tol) return 0;
  for (int k = 0; k < 6; k++) {
    int a = k, b = (k + 1) % 6, d = (k + 2) % 6;
    if (hypot(v[a][0] + v[d][0] - v[b][0], v[a][1] + v[d][1] - v[b][1]) > tol) return 0;
  }
  if (!fit_affine(NB, (const double(*)[2])v, 6, A)) return 0;
  for (int k = 0; k < 6; k++) nb_idx[k] = idx[k];
  return 1;
}

static int *grid_at(order_ctx *c, int a, int b) {
  if (a < -LAB_HALF || a > LAB_HALF || b < -LAB_HALF || b > LAB_HALF) return NULL;
  return &c->grid[(b + LAB_HALF) * LAB_SIDE + (a + LAB_HALF)];
}

/* refit point i's local affine from its labelled lattice neighbours */
static void refit_local(order_ctx *c, int i) {
  int l[6][2];
  double v[6][2];
  int m = 0;
  for (int k = 0; k < 6; k++) {
    int *g = grid_at(c, c->lab_a[i] + NB[k][0], c->lab_b[i] + NB[k][1]);
    if (!g || *g < 0) continue;
    l[m][0] = NB[k][0];
    l[m][1] = NB[k][1];
    v[m][0] = c->p[*g][0] - c->p[i][0];
    v[m][1] = c->p[*g][1] - c->p[i][1];
    m++;
  }
  double A[4];
  if (m >= 3 && fit_affine((const int(*)[2])l, (const double(*)[2])v, m, A))
    memcpy(c->A[i], A, sizeof A);
}

/* breadth-first labelling from seed; returns labelled count or -1 on conflict */
static int walk(order_ctx *c, int seed, const double A0[4], char *reason, size_t rs) {
  int *queue = malloc(sizeof(int) * c->n);
  if (!queue) {
    snprintf(reason, rs, "out of memory");
    return -1;
  }
  for (size_t i = 0; i < c->n; i++) c->has[i] = 0;
  for (int i = 0; i < LAB_SIDE * LAB_SIDE; i++) c->grid[i] = -1;
  int head = 0, tail = 0, count = 1;
  c->has[seed] = 1;
  c->lab_a[seed] = c->lab_b[seed] = 0;
  memcpy(c->A[seed], A0, sizeof(double) * 4);
  *grid_at(c, 0, 0) = seed;
  queue[tail++] = seed;
  while (head < tail) {
    int i = queue[head++];
    refit_local(c, i);
    const double *A = c->A[i];
    for (int k = 0; k < 6; k++) {
      int a = c->lab_a[i] + NB[k][0], b = c->lab_b[i] + NB[k][1];
      double pred[2] = {c->p[i][0] + A[0] * NB[k][0] + A[1] * NB[k][1],
                        c->p[i][1] + A[2] * NB[k][0] + A[3] * NB[k][1]};
      double step = hypot(A[0] * NB[k][0] + A[1] * NB[k][1], A[2] * NB[k][0] + A[3] * NB[k][1]);
      /* nearest candidate to the prediction among i's neighbours */
      int best = -1;
      double bd = INFINITY;
      for (int q = 0; q < KNN; q++) {
        int j = c->knn[i][q];
        if (j < 0) break;
        double d = dist2(c->p[j], pred);
        if (d < bd) {
          bd = d;
          best = j;
        }
      }
      if (best < 0 || sqrt(bd) > 0.3 * step) continue;
      int *g = grid_at(c, a, b);
      if (!g) {
        free(queue);
        snprintf(reason, rs, "lattice walk left the plate's extent");
        return -1;
      }
      if (c->has[best]) {
        if (c->lab_a[best] != a || c->lab_b[best] != b) {
          free(queue);
          snprintf(reason, rs, "inconsistent lattice (a blob matches two holes)");
          return -1;
        }
        continue;
      }
      if (*g >= 0) {
        free(queue);
        snprintf(reason, rs, "inconsistent lattice (two blobs claim one hole)");
        return -1;
      }
      c->has[best] = 1;
      c->lab_a[best] = a;
      c->lab_b[best] = b;
      memcpy(c->A[best], A, sizeof(double) * 4);
      *g = best;
      queue[tail++] = best;
      count++;
    }
  }
  free(queue);
  return count;
}

/* plate index of lattice label (a, b) (b = row), or -1 */
static int plate_index(int a, int b) {
  if (b < 0 || b >= HEARTH_PLATE_ROWS) return -1;
  int c = a + b / 2;
  int ncol = (b & 1) ? 10 : 11;
  if (c < 0 || c >= ncol) return -1;
  return (b / 2) * 21 + ((b & 1) ? 11 : 0) + c;
}

int hearth_plate_order(const double (*pts)[2], size_t n, double centres[HEARTH_PLATE_HOLES][2],
                       char *reason, size_t rs) {
  char dummy[8];
  if (!reason) {
    reason = dummy;
    rs = sizeof dummy;
  }
  reason[0] = 0;
  if (n < HEARTH_PLATE_HOLES) {
    snprintf(reason, rs, "only %zu holes visible", n);
    return 0;
  }
  if (n > MAX_CAND) {
    snprintf(reason, rs, "%zu blob candidates (clutter), at most %d handled", n, MAX_CAND);
    return 0;
  }
  order_ctx c;
  memset(&c, 0, sizeof c);
  c.p = pts;
  c.n = n;
  c.knn = malloc(sizeof(*c.knn) * n);
  c.lab_a = malloc(sizeof(int) * n);
  c.lab_b = malloc(sizeof(int) * n);
  c.has = malloc(sizeof(int) * n);
  c.A = malloc(sizeof(*c.A) * n);
  c.grid = malloc(sizeof(int) * LAB_SIDE * LAB_SIDE);
  int ok = 0;
  if (!c.knn || !c.lab_a || !c.lab_b || !c.has || !c.A || !c.grid) {
    snprintf(reason, rs, "out of memory");
    goto done;
  }
  build_knn(&c);
  /* seeds: clean hexagon centres, most central first */
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; i++) {
    mx += pts[i][0];
    my += pts[i][1];
  }
  mx /= (double)n;
  my /= (double)n;
  int best_count = 0, tried = 0;
  char why[256] = "no hole with six lattice neighbours (plate not found)";
  for (int attempt = 0; attempt < 5 && !ok; attempt++) {
    int seed = -1;
    double sd = INFINITY, A0[4];
    int nb[6];
    for (size_t i = 0; i < n; i++) {
      double A[4];
      double d = (pts[i][0] - mx) * (pts[i][0] - mx) + (pts[i][1] - my) * (pts[i][1] - my);
      if (d >= sd) continue;
      /* skip seeds whose walk was already tried */
      if (attempt > 0 && c.has[i]) continue;
      if (!seed_basis(&c, i, A, nb)) continue;
      sd = d;
      seed = (int)i;
      memcpy(A0, A, sizeof A);
    }
    if (seed < 0) break;
    tried++;
    int cnt = walk(&c, seed, A0, why, sizeof why);
    if (cnt < 0) continue;
    if (cnt > best_count) best_count = cnt;
    if (cnt < HEARTH_PLATE_HOLES) {
      snprintf(why, sizeof why, "only %d holes visible on the lattice", cnt);
      continue;
    }
    if (cnt > HEARTH_PLATE_HOLES) {
      snprintf(why, sizeof why, "%d blobs on the lattice, the plate has %d", cnt,
               HEARTH_PLATE_HOLES);
      continue;
    }
    /* the labels are the plate's up to an orientation-preserving lattice
     * map: one of the six rotations, or, when foreshortening made a
     * second-shell hole look nearer than a first-shell one, a sheared basis.
     * Try every unimodular M with small entries; the 11/10 row pattern
     * admits exactly one. */
    int matches = 0, mm[4] = {0}, match_da = 0, match_db = 0;
    for (int m0 = -2; m0 <= 2; m0++)
      for (int m1 = -2; m1 <= 2; m1++)
        for (int m2 = -2; m2 <= 2; m2++)
          for (int m3 = -2; m3 <= 2; m3++) {
            if (m0 * m3 - m1 * m2 != 1) continue;
            int minb = 1 << 30, mina = 1 << 30;
            for (size_t i = 0; i < n; i++) {
              if (!c.has[i]) continue;
              int b = m2 * c.lab_a[i] + m3 * c.lab_b[i];
              if (b < minb) minb = b;
            }
            for (size_t i = 0; i < n; i++) {
              if (!c.has[i]) continue;
              int a = m0 * c.lab_a[i] + m1 * c.lab_b[i], b = m2 * c.lab_a[i] + m3 * c.lab_b[i];
              if (b == minb && a < mina) mina = a;
            }
            int good = 1;
            unsigned char seen[HEARTH_PLATE_HOLES] = {0};
            for (size_t i = 0; i < n && good; i++) {
              if (!c.has[i]) continue;
              int a = m0 * c.lab_a[i] + m1 * c.lab_b[i], b = m2 * c.lab_a[i] + m3 * c.lab_b[i];
              int pi = plate_index(a - mina, b - minb);
              if (pi < 0 || seen[pi]) good = 0;
              else seen[pi] = 1;
            }
            if (good) {
              matches++;
              mm[0] = m0;
              mm[1] = m1;
              mm[2] = m2;
              mm[3] = m3;
              match_da = -mina;
              match_db = -minb;
            }
          }
    if (matches != 1) {
      snprintf(why, sizeof why, "84 lattice holes do not form the 11/10 row pattern");
      continue;
    }
    for (size_t i = 0; i < n; i++) {
      if (!c.has[i]) continue;
      int a = mm[0] * c.lab_a[i] + mm[1] * c.lab_b[i], b = mm[2] * c.lab_a[i] + mm[3] * c.lab_b[i];
      int pi = plate_index(a + match_da, b + match_db);
      centres[pi][0] = pts[i][0];
      centres[pi][1] = pts[i][1];
    }
    ok = 1;
  }
  if (!ok) snprintf(reason, rs, "%s", why);
  (void)tried;
done:
  free(c.knn);
  free(c.lab_a);
  free(c.lab_b);
  free(c.has);
  free(c.A);
  free(c.grid);
  return ok;
}
