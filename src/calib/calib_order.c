/* Ordering candidate hole centres by the target's lattice.
 *
 * On a hex lattice every hole has six neighbours, on a grid four, in
 * opposite pairs; that is affine invariant, so a seed hole and its
 * neighbours fix a local lattice basis (up to the lattice rotations). A
 * breadth-first walk predicts each neighbour with a locally refitted affine
 * map, so perspective and lens distortion only need to be locally mild. The
 * labelled set must then be exactly the target's holes under one
 * orientation-preserving lattice map. The paper's 11/10 row pattern admits
 * only one; a grid or an even-rowed hex target also matches turned by 180
 * degrees (a square grid by 90), and then the image fixes the order: the
 * target's x axis must point to the right in the image, well away from the
 * turn where the choice would flip (docs/dataset.md). Anything else is a
 * reasoned failure, never a guess. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calib/calib_internal.h"

#define KNN 8
#define LAB_HALF 80
#define LAB_SIDE (2 * LAB_HALF + 1)
#define MAX_CAND 4000

/* lattice offsets of the neighbours in increasing image angle: six on a hex
 * lattice (basis (1, 0) and (1/2, sqrt(3)/2) pitches), four on a grid */
static const int NB6[6][2] = {{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}};
static const int NB4[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};

typedef struct order_ctx {
  const int (*nb)[2];
  int nnb;
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

/* is point i the centre of a clean hexagon (grid: cross) of its nearest
 * neighbours? */
static int seed_basis(const order_ctx *c, size_t i, double A[4], int nb_idx[6]) {
  const double *p = c->p[i];
  int k6 = c->nnb, idx[6];
  double ang[6], v[6][2];
  for (int k = 0; k < k6; k++) {
    idx[k] = c->knn[i][k];
    if (idx[k] < 0) return 0;
  }
  /* the last neighbour and the next one must be clearly separated */
  if (c->knn[i][k6] >= 0) {
    double d6 = dist2(p, c->p[c->knn[i][k6 - 1]]), d7 = dist2(p, c->p[c->knn[i][k6]]);
    if (d7 < d6 * 1.1) return 0;
  }
  for (int k = 0; k < k6; k++) {
    v[k][0] = c->p[idx[k]][0] - p[0];
    v[k][1] = c->p[idx[k]][1] - p[1];
    ang[k] = atan2(v[k][1], v[k][0]);
  }
  /* sort by angle */
  for (int a = 1; a < k6; a++)
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
  /* opposite pairs cancel; on a hexagon also v1 = v0 + v2 */
  double scale = 0;
  for (int k = 0; k < k6; k++) scale += hypot(v[k][0], v[k][1]);
  scale /= k6;
  double tol = 0.15 * scale;
  int half = k6 / 2;
  for (int k = 0; k < half; k++)
    if (hypot(v[k][0] + v[k + half][0], v[k][1] + v[k + half][1]) > tol) return 0;
  if (k6 == 6)
    for (int k = 0; k < 6; k++) {
      int a = k, b = (k + 1) % 6, d = (k + 2) % 6;
      if (hypot(v[a][0] + v[d][0] - v[b][0], v[a][1] + v[d][1] - v[b][1]) > tol) return 0;
    }
  if (!fit_affine(c->nb, (const double(*)[2])v, k6, A)) return 0;
  for (int k = 0; k < k6; k++) nb_idx[k] = idx[k];
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
  for (int k = 0; k < c->nnb; k++) {
    int *g = grid_at(c, c->lab_a[i] + c->nb[k][0], c->lab_b[i] + c->nb[k][1]);
    if (!g || *g < 0) continue;
    l[m][0] = c->nb[k][0];
    l[m][1] = c->nb[k][1];
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
    for (int k = 0; k < c->nnb; k++) {
      const int *nk = c->nb[k];
      int a = c->lab_a[i] + nk[0], b = c->lab_b[i] + nk[1];
      double pred[2] = {c->p[i][0] + A[0] * nk[0] + A[1] * nk[1],
                        c->p[i][1] + A[2] * nk[0] + A[3] * nk[1]};
      double step = hypot(A[0] * nk[0] + A[1] * nk[1], A[2] * nk[0] + A[3] * nk[1]);
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

/* target index of lattice label (a, b) (b = row), or -1; row_start[r] is
 * the index of row r's first hole */
static int target_index(const hearth_target *t, const int *row_start, int a, int b) {
  if (b < 0 || b >= t->rows) return -1;
  int c = t->lattice == HEARTH_LATTICE_GRID ? a : a + b / 2;
  if (c < 0 || c >= hearth_target_row_holes(t, b)) return -1;
  return row_start[b] + c;
}

/* angle (radians) of the image direction of the target's x axis: the x
 * column of the least-squares affine map from plate to image coordinates */
static double x_axis_angle(const double (*obj)[3], const double (*img)[2], size_t n) {
  double mx = 0, my = 0, mu = 0, mv = 0;
  for (size_t i = 0; i < n; i++) {
    mx += obj[i][0];
    my += obj[i][1];
    mu += img[i][0];
    mv += img[i][1];
  }
  mx /= (double)n;
  my /= (double)n;
  mu /= (double)n;
  mv /= (double)n;
  double sxx = 0, sxy = 0, syy = 0, sxu = 0, syu = 0, sxv = 0, syv = 0;
  for (size_t i = 0; i < n; i++) {
    double x = obj[i][0] - mx, y = obj[i][1] - my, u = img[i][0] - mu, v = img[i][1] - mv;
    sxx += x * x;
    sxy += x * y;
    syy += y * y;
    sxu += x * u;
    syu += y * u;
    sxv += x * v;
    syv += y * v;
  }
  double det = sxx * syy - sxy * sxy;
  /* u = a x + b y: a = (syy sxu - sxy syu) / det */
  double au = (syy * sxu - sxy * syu) / det, av = (syy * sxv - sxy * syv) / det;
  return atan2(av, au);
}

#define MAX_MATCH 8
/* a symmetric target's order is taken only with its x axis this far (degrees)
 * inside the half-turn (square grid: quarter-turn) the choice covers */
#define SYMMETRY_MARGIN_DEG 15.0

int hearth_target_order(const hearth_target *target, const double (*pts)[2], size_t n,
                        double (*centres)[2], char *reason, size_t rs) {
  char dummy[8];
  if (!reason) {
    reason = dummy;
    rs = sizeof dummy;
  }
  reason[0] = 0;
  hearth_target tdef;
  const hearth_target *t = hearth_target_or_default(target, &tdef);
  const size_t holes = hearth_target_holes(t);
  if (holes == 0 || holes > HEARTH_TARGET_MAX_HOLES) {
    snprintf(reason, rs, "invalid target");
    return 0;
  }
  int row_start[65];
  row_start[0] = 0;
  for (int r = 0; r < t->rows; r++) row_start[r + 1] = row_start[r] + hearth_target_row_holes(t, r);
  if (n < holes) {
    snprintf(reason, rs, "only %zu holes visible", n);
    return 0;
  }
  if (n > MAX_CAND) {
    snprintf(reason, rs, "%zu blob candidates (clutter), at most %d handled", n, MAX_CAND);
    return 0;
  }
  double(*obj)[3] = malloc(sizeof(*obj) * holes);
  order_ctx c;
  memset(&c, 0, sizeof c);
  c.nb = t->lattice == HEARTH_LATTICE_GRID ? NB4 : NB6;
  c.nnb = t->lattice == HEARTH_LATTICE_GRID ? 4 : 6;
  c.p = pts;
  c.n = n;
  c.knn = malloc(sizeof(*c.knn) * n);
  c.lab_a = malloc(sizeof(int) * n);
  c.lab_b = malloc(sizeof(int) * n);
  c.has = malloc(sizeof(int) * n);
  c.A = malloc(sizeof(*c.A) * n);
  c.grid = malloc(sizeof(int) * LAB_SIDE * LAB_SIDE);
  double(*cand)[2] = malloc(sizeof(*cand) * holes);
  int ok = 0;
  if (!obj || !cand || !c.knn || !c.lab_a || !c.lab_b || !c.has || !c.A || !c.grid) {
    snprintf(reason, rs, "out of memory");
    goto done;
  }
  hearth_target_points(t, obj);
  build_knn(&c);
  /* seeds: clean hexagon (cross) centres, most central first */
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; i++) {
    mx += pts[i][0];
    my += pts[i][1];
  }
  mx /= (double)n;
  my /= (double)n;
  char why[256];
  snprintf(why, sizeof why, "no hole with %d lattice neighbours (target not found)", c.nnb);
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
    int cnt = walk(&c, seed, A0, why, sizeof why);
    if (cnt < 0) continue;
    if ((size_t)cnt < holes) {
      snprintf(why, sizeof why, "only %d holes visible on the lattice", cnt);
      continue;
    }
    if ((size_t)cnt > holes) {
      snprintf(why, sizeof why, "%d blobs on the lattice, the target has %zu", cnt, holes);
      continue;
    }
    /* the labels are the target's up to an orientation-preserving lattice
     * map: a rotation, or, when foreshortening made a second-shell hole
     * look nearer than a first-shell one, a sheared basis. Try every
     * unimodular M with small entries and keep those that land every label
     * on a distinct hole. */
    int matches = 0, mm[MAX_MATCH][4], mda[MAX_MATCH], mdb[MAX_MATCH];
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
            unsigned char seen[HEARTH_TARGET_MAX_HOLES] = {0};
            for (size_t i = 0; i < n && good; i++) {
              if (!c.has[i]) continue;
              int a = m0 * c.lab_a[i] + m1 * c.lab_b[i], b = m2 * c.lab_a[i] + m3 * c.lab_b[i];
              int pi = target_index(t, row_start, a - mina, b - minb);
              if (pi < 0 || seen[pi]) good = 0;
              else seen[pi] = 1;
            }
            if (good && matches < MAX_MATCH) {
              mm[matches][0] = m0;
              mm[matches][1] = m1;
              mm[matches][2] = m2;
              mm[matches][3] = m3;
              mda[matches] = -mina;
              mdb[matches] = -minb;
            }
            if (good) matches++;
          }
    /* the paper plate is asymmetric: exactly one */
    if (matches < 1 || matches > 4 || (matches > 1 && hearth_target_is_default(t))) {
      if (hearth_target_is_default(t))
        snprintf(why, sizeof why, "84 lattice holes do not form the 11/10 row pattern");
      else
        snprintf(why, sizeof why, "%zu lattice holes do not form the %s %d x %d pattern", holes,
                 hearth_lattice_name(t->lattice), t->rows, t->cols);
      continue;
    }
    /* each match's order; several: the target is symmetric, the one whose x
     * axis points most nearly along +u wins, if it is clear of the turn */
    int pick = 0;
    double best = INFINITY;
    for (int k = 0; k < matches; k++) {
      for (size_t i = 0; i < n; i++) {
        if (!c.has[i]) continue;
        int a = mm[k][0] * c.lab_a[i] + mm[k][1] * c.lab_b[i];
        int b = mm[k][2] * c.lab_a[i] + mm[k][3] * c.lab_b[i];
        int pi = target_index(t, row_start, a + mda[k], b + mdb[k]);
        cand[pi][0] = pts[i][0];
        cand[pi][1] = pts[i][1];
      }
      if (matches == 1) break;
      double ang = fabs(x_axis_angle((const double(*)[3])obj, (const double(*)[2])cand, holes));
      if (ang < best) {
        best = ang;
        pick = k;
      }
    }
    if (matches > 1) {
      double limit = 180.0 / matches - SYMMETRY_MARGIN_DEG;
      if (best * 180.0 / 3.14159265358979323846 > limit) {
        snprintf(why, sizeof why,
                 "symmetric target turned %.0f degrees in the image (order fixed only within "
                 "%.0f of upright)",
                 best * 180.0 / 3.14159265358979323846, limit);
        break;
      }
      for (size_t i = 0; i < n; i++) {
        if (!c.has[i]) continue;
        int a = mm[pick][0] * c.lab_a[i] + mm[pick][1] * c.lab_b[i];
        int b = mm[pick][2] * c.lab_a[i] + mm[pick][3] * c.lab_b[i];
        int pi = target_index(t, row_start, a + mda[pick], b + mdb[pick]);
        cand[pi][0] = pts[i][0];
        cand[pi][1] = pts[i][1];
      }
    }
    memcpy(centres, cand, sizeof(*cand) * holes);
    ok = 1;
  }
  if (!ok) snprintf(reason, rs, "%s", why);
done:
  free(obj);
  free(cand);
  free(c.knn);
  free(c.lab_a);
  free(c.lab_b);
  free(c.has);
  free(c.A);
  free(c.grid);
  return ok;
}

int hearth_plate_order(const double (*pts)[2], size_t n, double centres[HEARTH_PLATE_HOLES][2],
                       char *reason, size_t rs) {
  hearth_target t = hearth_target_default();
  return hearth_target_order(&t, pts, n, centres, reason, rs);
}
