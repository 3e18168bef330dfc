/* recon_atlas_pack.c - the flattened charts packed into the unit square:
 * each chart turned to its minimal-area box, rasterised conservatively on
 * a packing grid (every cell its triangles touch, kept as runs per row, so
 * a curved chart's hollow stays free), that footprint grown by the gutter, and placed first-fit where it
 * reaches least far down (then leftmost), as it lies or turned a quarter,
 * clear of every chart placed before; the common scale is the largest
 * that fits (bisection). */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "recon_atlas.h"

static int cmp_pt(const void *pa, const void *pb) {
  const double *a = pa, *b = pb;
  if (a[0] != b[0]) return a[0] < b[0] ? -1 : 1;
  return a[1] < b[1] ? -1 : a[1] > b[1];
}

static double turn(const double *o, const double *a, const double *b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/* Turn chart c so its minimal-area box is axis-aligned and lies wide;
 * moves its UVs to start at 0 and sets w, h. -1 without memory. */
static int orient_chart(atlas_chart *c) {
  size_t nv = c->n_vertices;
  double *pt = malloc(2 * nv * sizeof *pt), *hull = malloc(2 * (2 * nv + 1) * sizeof *hull);
  if (!pt || !hull) {
    free(pt), free(hull);
    return -1;
  }
  memcpy(pt, c->uv, 2 * nv * sizeof *pt);
  qsort(pt, nv, 2 * sizeof *pt, cmp_pt);
  size_t k = 0; /* Andrew's monotone chain */
  for (size_t i = 0; i < nv; i++) {
    while (k >= 2 && turn(hull + 2 * (k - 2), hull + 2 * (k - 1), pt + 2 * i) <= 0) k--;
    memcpy(hull + 2 * k++, pt + 2 * i, 2 * sizeof *pt);
  }
  for (size_t i = nv - 1, t = k + 1; i-- > 0;) {
    while (k >= t && turn(hull + 2 * (k - 2), hull + 2 * (k - 1), pt + 2 * i) <= 0) k--;
    memcpy(hull + 2 * k++, pt + 2 * i, 2 * sizeof *pt);
  }
  size_t nh = k > 1 ? k - 1 : k;
  double best = INFINITY, bc = 1, bs = 0;
  for (size_t e = 0; e < nh; e++) {
    const double *a = hull + 2 * e, *b = hull + 2 * ((e + 1) % nh);
    double dx = b[0] - a[0], dy = b[1] - a[1], l = sqrt(dx * dx + dy * dy);
    if (!(l > 0)) continue;
    double cs = dx / l, sn = dy / l;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (size_t i = 0; i < nh; i++) {
      double u = cs * hull[2 * i] + sn * hull[2 * i + 1],
             v = -sn * hull[2 * i] + cs * hull[2 * i + 1];
      lo[0] = fmin(lo[0], u), hi[0] = fmax(hi[0], u), lo[1] = fmin(lo[1], v),
      hi[1] = fmax(hi[1], v);
    }
    double ar = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    if (ar < best - 1e-12 * fabs(best)) best = ar, bc = cs, bs = sn;
  }
  free(pt), free(hull);
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (size_t i = 0; i < nv; i++) {
    double u = bc * c->uv[2 * i] + bs * c->uv[2 * i + 1],
           v = -bs * c->uv[2 * i] + bc * c->uv[2 * i + 1];
    c->uv[2 * i] = u, c->uv[2 * i + 1] = v;
    lo[0] = fmin(lo[0], u), hi[0] = fmax(hi[0], u), lo[1] = fmin(lo[1], v), hi[1] = fmax(hi[1], v);
  }
  int tall = hi[1] - lo[1] > hi[0] - lo[0];
  for (size_t i = 0; i < nv; i++) {
    double u = c->uv[2 * i] - lo[0], v = c->uv[2 * i + 1] - lo[1];
    if (tall) /* a quarter turn: (u, v) -> (H - v, u) */
      c->uv[2 * i] = (hi[1] - lo[1]) - v, c->uv[2 * i + 1] = u;
    else c->uv[2 * i] = u, c->uv[2 * i + 1] = v;
  }
  c->w = tall ? hi[1] - lo[1] : hi[0] - lo[0];
  c->h = tall ? hi[0] - lo[0] : hi[1] - lo[1];
  return 0;
}

/* the chart's UV area */
static double chart_area(const atlas_chart *c) {
  double a = 0;
  for (size_t f = 0; f < c->n_faces; f++) {
    const double *p = c->uv + 2 * (size_t)c->corner[3 * f],
                 *q = c->uv + 2 * (size_t)c->corner[3 * f + 1],
                 *r = c->uv + 2 * (size_t)c->corner[3 * f + 2];
    a += 0.5 * fabs((q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]));
  }
  return a;
}

/* ---- a chart on the grid ----------------------------------------------- */
/* Grid coordinates of chart vertex v at scale s (cells per surface unit),
 * as it lies (rot 0) or a quarter turn on, (u, v) -> (h - v, u). */
static void grid_xy(const atlas_chart *c, size_t v, double s, int rot, double *x, double *y) {
  double u = c->uv[2 * v], w = c->uv[2 * v + 1];
  *x = s * (rot ? c->h - w : u);
  *y = s * (rot ? u : w);
}

/* One chart's cells at one scale and turn: its own runs of cells and
 * those grown by the gutter, per row. */
typedef struct chart_runs {
  int32_t *own;       /* the chart's own runs: pairs (first, last cell) */
  int32_t *grown;     /* its grown runs: pairs */
  size_t *own_at;     /* per own row: its first run; rows + 1 */
  size_t *grown_at;   /* per grown row: its first run; rows + 1 */
  int32_t *grown_len; /* per grown row: its longest run */
} chart_runs;

/* The packing's state: the grid of G x G cells and, per row, the last
 * occupied cell at or left of each cell (-1 when none) and the longest
 * run of free cells. Scratch for one chart: its cell bitmap, the bitmap
 * grown sideways, and its runs of cells in each turn. */
typedef struct pack_grid {
  int G, d;
  int32_t *last;      /* G * G */
  int32_t *max_run;   /* per row: its longest run of free cells */
  uint8_t *stale;     /* per row: max_run is to be counted again */
  uint8_t *bits;      /* one chart's cells, rows of G */
  uint8_t *wide;      /* those grown by d sideways, rows of G */
  int32_t *count;     /* per column: grown cells in the rows under the window */
  chart_runs runs[2]; /* one chart's runs, as it lies and turned */
} pack_grid;

/* one placed or candidate footprint */
typedef struct footprint {
  int rows;       /* rows of the chart itself, H */
  int cmin, rmin; /* integer shift that brings its cells to start at 0 */
  int lo, hi;     /* first and last column over the grown runs */
  chart_runs *cr; /* its runs */
} footprint;

/* the runs of set cells of the n-cell row b into run (pairs, column
 * shift off); their count */
static size_t row_runs(const uint8_t *b, int n, int off, int32_t *run, int32_t *longest) {
  size_t k = 0;
  *longest = 0;
  for (int x = 0; x < n;) {
    if (!b[x]) {
      x++;
      continue;
    }
    int a = x;
    while (x < n && b[x]) x++;
    run[2 * k] = a + off, run[2 * k + 1] = x - 1 + off, k++;
    if (x - a > *longest) *longest = x - a;
  }
  return k;
}

/* Conservative cells of chart c at (s, rot): every cell (closed unit
 * square) a triangle meets, exactly from the triangle clipped to each
 * row's strip, as runs per row; then those cells grown by d in every
 * direction (Chebyshev), rows -d .. H + d stored at 0 .. H + 2d, columns
 * from -d. 0 when it cannot fit the grid. */
static int chart_cells(const atlas_chart *c, double s, int rot, pack_grid *g, footprint *fp) {
  const int G = g->G, d = g->d;
  chart_runs *cr = fp->cr = &g->runs[rot];
  double xmin = INFINITY, ymin = INFINITY, xmax = -INFINITY, ymax = -INFINITY;
  for (size_t v = 0; v < c->n_vertices; v++) {
    double x, y;
    grid_xy(c, v, s, rot, &x, &y);
    xmin = fmin(xmin, x), xmax = fmax(xmax, x), ymin = fmin(ymin, y), ymax = fmax(ymax, y);
  }
  if (!(xmax - xmin < G) || !(ymax - ymin < G)) return 0;
  fp->cmin = (int)floor(xmin), fp->rmin = (int)floor(ymin);
  const int H = (int)floor(ymax) - fp->rmin + 1, W = (int)floor(xmax) - fp->cmin + 1;
  if (H + 2 * d > G || W + 2 * d > G) return 0;
  fp->rows = H;
  const size_t Wg = (size_t)W + 2 * (size_t)d;
  memset(g->bits, 0, (size_t)H * (size_t)G);
  for (size_t f = 0; f < c->n_faces; f++) {
    double p[3][2];
    for (int j = 0; j < 3; j++) {
      grid_xy(c, c->corner[3 * f + j], s, rot, &p[j][0], &p[j][1]);
      p[j][0] -= fp->cmin, p[j][1] -= fp->rmin;
    }
    double y0 = fmin(p[0][1], fmin(p[1][1], p[2][1])), y1 = fmax(p[0][1], fmax(p[1][1], p[2][1]));
    int ra = (int)floor(y0), rb = (int)floor(y1);
    for (int r = ra < 0 ? 0 : ra; r <= rb && r < H; r++) {
      double lo = fmax(y0, r), hi = fmin(y1, r + 1.0), a = INFINITY, b = -INFINITY;
      for (int j = 0; j < 3; j++) {
        const double *P = p[j], *Q = p[(j + 1) % 3];
        if (P[1] >= lo && P[1] <= hi) a = fmin(a, P[0]), b = fmax(b, P[0]);
        if (P[1] == Q[1]) continue;
        for (int e = 0; e < 2; e++) {
          double yy = e ? hi : lo;
          if ((yy - P[1]) * (yy - Q[1]) > 0) continue;
          double x = P[0] + (yy - P[1]) * (Q[0] - P[0]) / (Q[1] - P[1]);
          a = fmin(a, x), b = fmax(b, x);
        }
      }
      if (!(a <= b)) continue;
      int ca = (int)floor(a), cb = (int)floor(b);
      ca = ca < 0 ? 0 : ca, cb = cb >= W ? W - 1 : cb;
      if (ca <= cb) memset(g->bits + (size_t)r * (size_t)G + ca, 1, (size_t)(cb - ca + 1));
    }
  }
  /* own runs; each row grown sideways: column x of wide is cell x - d */
  size_t k = 0;
  for (int r = 0; r < H; r++) {
    const uint8_t *b = g->bits + (size_t)r * (size_t)G;
    uint8_t *w = g->wide + (size_t)r * (size_t)G;
    int32_t longest;
    cr->own_at[r] = k;
    k += row_runs(b, W, 0, cr->own + 2 * k, &longest);
    memset(w, 0, Wg);
    for (size_t j = cr->own_at[r]; j < k; j++)
      memset(w + cr->own[2 * j], 1, (size_t)(cr->own[2 * j + 1] - cr->own[2 * j] + 1 + 2 * d));
  }
  cr->own_at[H] = k;
  /* grown row q is the union of wide rows q - 2d .. q: a count per column
     of the rows in that window */
  memset(g->count, 0, Wg * sizeof *g->count);
  uint8_t *acc = g->bits; /* the own bitmap is no longer needed: one row of scratch */
  fp->lo = INT_MAX, fp->hi = INT_MIN;
  k = 0;
  for (int q = 0; q < H + 2 * d; q++) {
    if (q < H) {
      const uint8_t *w = g->wide + (size_t)q * (size_t)G;
      for (size_t x = 0; x < Wg; x++) g->count[x] += w[x];
    }
    if (q - 2 * d - 1 >= 0) {
      const uint8_t *w = g->wide + (size_t)(q - 2 * d - 1) * (size_t)G;
      for (size_t x = 0; x < Wg; x++) g->count[x] -= w[x];
    }
    for (size_t x = 0; x < Wg; x++) acc[x] = g->count[x] > 0;
    cr->grown_at[q] = k;
    size_t nr = row_runs(acc, (int)Wg, -d, cr->grown + 2 * k, &cr->grown_len[q]);
    if (nr) {
      if (cr->grown[2 * k] < fp->lo) fp->lo = cr->grown[2 * k];
      if (cr->grown[2 * (k + nr) - 1] > fp->hi) fp->hi = cr->grown[2 * (k + nr) - 1];
    }
    k += nr;
  }
  cr->grown_at[H + 2 * d] = k;
  return fp->lo <= fp->hi && fp->hi - fp->lo < G;
}

/* With the chart's row 0 at grid row Y and column 0 at X: -1 when its
 * grown footprint is clear, else the next X worth trying. *hint: the grown
 * row that failed last, tried first. */
static int try_at(const pack_grid *g, const footprint *fp, int X, int Y, int *hint) {
  const int G = g->G, d = g->d, nq = fp->rows + 2 * d;
  const chart_runs *cr = fp->cr;
  for (int i = 0; i < nq; i++) {
    int q = i == 0 ? *hint : i <= *hint ? i - 1 : i;
    const int32_t *row = g->last + (size_t)(Y - d + q) * (size_t)G;
    for (size_t j = cr->grown_at[q]; j < cr->grown_at[q + 1]; j++) {
      int32_t a = cr->grown[2 * j], l = row[X + cr->grown[2 * j + 1]];
      if (l >= X + a) {
        *hint = q;
        return (int)l + 1 - a;
      }
    }
  }
  return -1;
}

/* the longest run of free cells in row y, counted again when stale */
static int32_t row_run(pack_grid *g, int y) {
  if (g->stale[y]) {
    const int32_t *row = g->last + (size_t)y * (size_t)g->G;
    int32_t best = 0;
    for (int x = 0; x < g->G; x++)
      if (row[x] != x && x - row[x] > best) best = x - row[x];
    g->max_run[y] = best;
    g->stale[y] = 0;
  }
  return g->max_run[y];
}

/* The first place (lowest Y, then X) where fp fits, Y below y_stop;
 * 0 when none. */
static int first_fit(pack_grid *g, const footprint *fp, int y_stop, int *px, int *py) {
  const int G = g->G, d = g->d, H = fp->rows;
  const chart_runs *cr = fp->cr;
  const int xa = -fp->lo, xb = G - 1 - fp->hi;
  int hint = 0, shortest = INT_MAX; /* the shortest grown run of a row */
  for (int q = 0; q < H + 2 * d; q++)
    if (cr->grown_len[q] && cr->grown_len[q] < shortest) shortest = cr->grown_len[q];
  for (int Y = d; Y + H - 1 + d <= G - 1 && Y < y_stop; Y++) {
    int ok = 1; /* a run of free cells as long as each grown run */
    for (int q = 0; q < H + 2 * d && ok; q++) {
      int32_t run = cr->grown_len[q] ? row_run(g, Y - d + q) : INT32_MAX;
      if (run >= cr->grown_len[q]) continue;
      ok = 0;
      /* a grid row too full for any run: no place that covers it */
      if (run < shortest) Y = Y + q;
    }
    if (!ok) continue;
    for (int X = xa; X <= xb;) {
      int nx = try_at(g, fp, X, Y, &hint);
      if (nx < 0) {
        *px = X, *py = Y;
        return 1;
      }
      X = nx;
    }
  }
  return 0;
}

/* occupy the chart's own cells (its own runs) at (X, Y) */
static void occupy(pack_grid *g, const footprint *fp, int X, int Y) {
  const int G = g->G;
  const chart_runs *cr = fp->cr;
  for (int r = 0; r < fp->rows; r++) {
    if (cr->own_at[r] == cr->own_at[r + 1]) continue;
    int32_t *row = g->last + (size_t)(Y + r) * (size_t)G;
    for (size_t j = cr->own_at[r]; j < cr->own_at[r + 1]; j++) {
      int a = X + cr->own[2 * j], b = X + cr->own[2 * j + 1];
      for (int x = a; x <= b; x++) row[x] = x;
      for (int x = b + 1; x < G && row[x] < b; x++) row[x] = b;
    }
    g->stale[Y + r] = 1;
  }
}

typedef struct placement {
  int X, Y, rot, cmin, rmin;
} placement;

/* Every chart in order ord at scale s; places into pl. 1 when all fit. */
static int pack_at(const atlas_chart *c, const size_t *ord, size_t n, double s, pack_grid *g,
                   placement *pl) {
  const size_t G = (size_t)g->G;
  for (size_t i = 0; i < G * G; i++) g->last[i] = -1;
  for (size_t r = 0; r < G; r++) g->max_run[r] = (int32_t)G, g->stale[r] = 0;
  for (size_t k = 0; k < n; k++) {
    const atlas_chart *ch = &c[ord[k]];
    placement best = {0, INT_MAX, 0, 0, 0};
    int best_reach = INT_MAX, found = 0;
    /* a quarter turn is worth trying unless the chart is square */
    int n_rot = fabs(ch->w - ch->h) * s >= 1 ? 2 : 1;
    footprint fps[2];
    for (int rot = 0; rot < n_rot; rot++) {
      footprint fp;
      if (!chart_cells(ch, s, rot, g, &fp)) continue;
      fps[rot] = fp;
      int X, Y;
      /* it can only do better if it starts above best_reach - rows */
      int y_stop = found ? best_reach - fp.rows + 1 : INT_MAX;
      if (!first_fit(g, &fp, y_stop, &X, &Y)) continue;
      int reach = Y + fp.rows;
      if (!found || reach < best_reach || (reach == best_reach && X < best.X)) {
        best = (placement){X, Y, rot, fp.cmin, fp.rmin};
        best_reach = reach;
        found = 1;
      }
    }
    if (!found) {
      return 0;
    }
    occupy(g, &fps[best.rot], best.X, best.Y);
    pl[ord[k]] = best;
  }
  return 1;
}

typedef struct pack_key {
  double area;
  size_t i;
} pack_key;

static int cmp_pack(const void *pa, const void *pb) {
  const pack_key *a = pa, *b = pb;
  if (a->area != b->area) return a->area > b->area ? -1 : 1;
  return a->i < b->i ? -1 : a->i > b->i;
}

/* ---- shelves of boxes ----------------------------------------------------- */
static int cmp_shelf(const void *pa, const void *pb) {
  const atlas_chart *const *a = pa, *const *b = pb;
  if ((*a)->h != (*b)->h) return (*a)->h > (*b)->h ? -1 : 1;
  if ((*a)->w != (*b)->w) return (*a)->w > (*b)->w ? -1 : 1;
  return *a < *b ? -1 : *a > *b;
}

/* The boxes (tallest first) in rows at scale s (UV per surface unit), g
 * (UV) between boxes and from the border; with pos (2 per chart, indexed
 * from c0) the places are written. 1 if everything fits into [0,1]^2. */
static int shelves(const atlas_chart *const *ord, size_t n, const atlas_chart *c0, double s,
                   double g, double *pos) {
  double x = g, y = g, sh = 0;
  for (size_t k = 0; k < n; k++) {
    double W = ord[k]->w * s, H = ord[k]->h * s;
    if (x + W + g > 1 && x > g) y += sh + g, x = g, sh = 0;
    if (x + W + g > 1) return 0;
    if (pos) pos[2 * (size_t)(ord[k] - c0)] = x, pos[2 * (size_t)(ord[k] - c0) + 1] = y;
    x += W + g;
    sh = fmax(sh, H);
  }
  return y + sh + g <= 1;
}

/* the largest scale (UV per surface unit) at which the shelves fit, 0 if
 * none, with the places in pos */
static double shelf_scale(const atlas_chart *const *ord, size_t n, const atlas_chart *c0,
                          double area, double g, double *pos) {
  double hi = area > 0 ? 1 / sqrt(area) : 1, lo = hi * 1e-9;
  if (!shelves(ord, n, c0, lo, g, NULL)) return 0;
  for (int it = 0; it < 60; it++) {
    double mid = 0.5 * (lo + hi);
    if (shelves(ord, n, c0, mid, g, NULL)) lo = mid;
    else hi = mid;
  }
  shelves(ord, n, c0, lo, g, pos);
  return lo;
}

hearth_status ra_pack(atlas_chart *charts, size_t n, int texture_size, double gutter_texels,
                      hearth_err *err) {
  double area = 0;
  for (size_t i = 0; i < n; i++) {
    if (orient_chart(&charts[i])) return hearth_err_set(err, HEARTH_E_NOMEM, "atlas: packing");
    area += chart_area(&charts[i]);
  }
  pack_grid g;
  memset(&g, 0, sizeof g);
  g.G = texture_size < RA_PACK_GRID_MAX ? texture_size : RA_PACK_GRID_MAX;
  /* the gutter in cells, rounded up: cells are at least as large as texels */
  g.d = (int)ceil(gutter_texels * g.G / texture_size - 1e-9);
  if (g.d < 0) g.d = 0;
  const size_t G = (size_t)g.G, rows = G + 1;
  /* a chart's cells fit G x G with their growth: at most G / 2 + 1 runs a row */
  const size_t runs = G * (G / 2 + 1);
  g.last = hearth_alloc_array(G * G, sizeof *g.last);
  g.max_run = hearth_alloc_array(G, sizeof *g.max_run);
  g.stale = hearth_alloc_array(G, sizeof *g.stale);
  g.bits = hearth_alloc_array(G * G, 1);
  g.wide = hearth_alloc_array(G * G, 1);
  g.count = hearth_alloc_array(G, sizeof *g.count);
  int runs_ok = 1;
  for (int k = 0; k < 2; k++) {
    chart_runs *cr = &g.runs[k];
    cr->own = hearth_alloc_array(2 * runs, sizeof *cr->own);
    cr->grown = hearth_alloc_array(2 * runs, sizeof *cr->grown);
    cr->own_at = hearth_alloc_array(rows, sizeof *cr->own_at);
    cr->grown_at = hearth_alloc_array(rows, sizeof *cr->grown_at);
    cr->grown_len = hearth_alloc_array(rows, sizeof *cr->grown_len);
    runs_ok = runs_ok && cr->own && cr->grown && cr->own_at && cr->grown_at && cr->grown_len;
  }
  pack_key *key = hearth_alloc_array(n ? n : 1, sizeof *key);
  size_t *ord = hearth_alloc_array(n ? n : 1, sizeof *ord);
  placement *pl = hearth_alloc_array(n ? n : 1, sizeof *pl);
  placement *best = hearth_alloc_array(n ? n : 1, sizeof *best);
  const atlas_chart **sord = hearth_alloc_array(n ? n : 1, sizeof *sord);
  double *spos = hearth_alloc_array(2 * (n ? n : 1), sizeof *spos);
  hearth_status s = HEARTH_OK;
  if (!g.last || !g.max_run || !g.stale || !g.bits || !g.wide || !g.count || !runs_ok || !key ||
      !ord || !pl || !best || !sord || !spos) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: packing");
    goto done;
  }
  /* the boxes in shelves first: rectangular charts fill them well */
  for (size_t i = 0; i < n; i++) sord[i] = &charts[i];
  qsort(sord, n, sizeof *sord, cmp_shelf);
  const double gutter_uv = gutter_texels / texture_size;
  const double shelf = shelf_scale(sord, n, charts, area, gutter_uv, spos);
  for (size_t i = 0; i < n; i++) key[i] = (pack_key){charts[i].w * charts[i].h, i};
  qsort(key, n, sizeof *key, cmp_pack);
  for (size_t i = 0; i < n; i++) ord[i] = key[i].i;
  /* no scale beyond the one that fills the grid with the charts' own area;
     from 0.7 of it down by halves until it fits, then bisection; the
     placements of the last that fitted are kept in best */
  double hi = area > 0 ? (double)G / sqrt(area) : 1, lo = 0.7 * hi;
  while (lo > 1e-6 * hi && !pack_at(charts, ord, n, lo, &g, pl)) hi = lo, lo *= 0.5;
  if (!(lo > 1e-6 * hi)) lo = pack_at(charts, ord, n, 0, &g, pl) ? 0 : -1;
  if (lo < 0 && !(shelf > 0)) {
    s = hearth_err_set(err, HEARTH_E_LIMIT,
                       "atlas: %zu charts do not fit %d x %d texels with %g-texel gutters", n,
                       texture_size, texture_size, gutter_texels);
    goto done;
  }
  if (lo >= 0) memcpy(best, pl, n * sizeof *pl);
  for (int it = 0; it < RA_PACK_BISECTIONS && lo > 0; it++) {
    double mid = sqrt(lo * hi);
    if (pack_at(charts, ord, n, mid, &g, pl)) {
      lo = mid;
      memcpy(best, pl, n * sizeof *pl);
    } else hi = mid;
  }
  if (shelf > 0 && shelf >= lo / (double)G) {
    for (size_t i = 0; i < n; i++) {
      atlas_chart *c = &charts[i];
      for (size_t v = 0; v < c->n_vertices; v++) {
        c->uv[2 * v] = spos[2 * i] + shelf * c->uv[2 * v];
        c->uv[2 * v + 1] = spos[2 * i + 1] + shelf * c->uv[2 * v + 1];
      }
    }
    goto done;
  }
  for (size_t i = 0; i < n; i++) {
    atlas_chart *c = &charts[i];
    const placement *p = &best[i];
    double *uv = malloc(2 * c->n_vertices * sizeof *uv);
    if (!uv) {
      s = hearth_err_set(err, HEARTH_E_NOMEM, "atlas: packing");
      goto done;
    }
    for (size_t v = 0; v < c->n_vertices; v++) {
      double x, y;
      grid_xy(c, v, lo, p->rot, &x, &y);
      uv[2 * v] = (p->X + x - p->cmin) / (double)G;
      uv[2 * v + 1] = (p->Y + y - p->rmin) / (double)G;
    }
    free(c->uv);
    c->uv = uv;
  }
done:
  free(g.last), free(g.max_run), free(g.stale), free(g.bits), free(g.wide), free(g.count);
  for (int k = 0; k < 2; k++) {
    chart_runs *cr = &g.runs[k];
    free(cr->own), free(cr->grown), free(cr->own_at), free(cr->grown_at), free(cr->grown_len);
  }
  free(key), free(ord), free(pl), free(best), free(sord), free(spos);
  return s;
}
