/* Procedural objects of the virtual rig: UV-mapped closed meshes for the
 * paper's categories, with per-triangle part labels and a procedural albedo
 * texture drawn in UV space.
 *
 * Every shape is a union of closed components of two kinds:
 *  - sweeps: a closed profile (from the axis, round the outside, back to the
 *    axis) swept round a planar outline (a circle for revolved bodies, a
 *    rounded rectangle for slabs). Profile segments become UV islands: a
 *    strip (with one seam) or, where a segment touches the axis, a disk with
 *    a planar projection.
 *  - tubes: an elliptic cross-section swept along a planar path (handles,
 *    spouts, head bands), one strip island and two end-cap disks.
 * Islands are packed into [0,1]^2 by a shelf packer with gutters. The
 * tessellation edge length is found by bisection on a count-only pass so the
 * triangle count follows target_triangles.
 *
 * What an instance is comes from its category's entry (synth_category.h):
 * the draws of its dimensions and colours, which of the shape builders below
 * makes it, the part and material of each of the builder's slots, and the
 * materials the shader paints them with. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "synth/synth_category.h"
#include "synth/synth_noise.h"
#include "synth/synth_object.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- mesh builder -------------------------------------------------------- */

enum { K_STRIP, K_DISK };

/* a part id and an albedo style (synth_slot once numbered) */
typedef struct slot_use {
  int part, style;
} slot_use;

typedef struct patch {
  int part, style, kind;
  size_t v0, v1;       /* vertex range of the island */
  double ox, oy, w, h; /* native coordinates: origin and extent (metres) */
  double pu, pv, ps;   /* packed placement: uv = p + (native - o) * ps */
  int swap;            /* native x runs along v */
} patch;

#define MAX_PATCHES 64

typedef struct builder {
  int count_only;
  size_t nv, nt;
  float *pos, *uv; /* uv holds native coordinates until packing */
  uint32_t *idx;
  uint8_t *part;
  patch patches[MAX_PATCHES];
  int np;
  const char *part_names[SYNTH_MAX_PARTS];
  int n_parts;
  int overflow; /* too many patches/parts: a bug in a builder */
} builder;

static int b_part(builder *b, const char *name) {
  for (int i = 0; i < b->n_parts; i++)
    if (strcmp(b->part_names[i], name) == 0) return i;
  if (b->n_parts >= SYNTH_MAX_PARTS) {
    b->overflow = 1;
    return 0;
  }
  b->part_names[b->n_parts] = name;
  return b->n_parts++;
}

static patch *b_patch(builder *b, int part, int style, int kind) {
  if (b->np >= MAX_PATCHES) {
    b->overflow = 1;
    return &b->patches[MAX_PATCHES - 1];
  }
  patch *p = &b->patches[b->np++];
  memset(p, 0, sizeof *p);
  p->part = part;
  p->style = style;
  p->kind = kind;
  p->v0 = b->nv;
  return p;
}

static uint32_t b_vert(builder *b, const double p[3], double nx, double ny) {
  size_t i = b->nv++;
  if (!b->count_only) {
    b->pos[3 * i] = (float)p[0];
    b->pos[3 * i + 1] = (float)p[1];
    b->pos[3 * i + 2] = (float)p[2];
    b->uv[2 * i] = (float)nx;
    b->uv[2 * i + 1] = (float)ny;
  }
  return (uint32_t)i;
}

static void b_tri(builder *b, uint32_t a, uint32_t c, uint32_t d, int part) {
  size_t t = b->nt++;
  if (!b->count_only) {
    b->idx[3 * t] = a;
    b->idx[3 * t + 1] = c;
    b->idx[3 * t + 2] = d;
    b->part[t] = (uint8_t)part;
  }
}

/* extent of an island in native coordinates */
static void patch_close(builder *b, patch *p) {
  p->v1 = b->nv;
  if (b->count_only) return;
  double lo[2] = {1e30, 1e30}, hi[2] = {-1e30, -1e30};
  for (size_t v = p->v0; v < p->v1; v++)
    for (int k = 0; k < 2; k++) {
      double x = b->uv[2 * v + k];
      if (x < lo[k]) lo[k] = x;
      if (x > hi[k]) hi[k] = x;
    }
  p->ox = lo[0];
  p->oy = lo[1];
  p->w = hi[0] - lo[0] > 1e-6 ? hi[0] - lo[0] : 1e-6;
  p->h = hi[1] - lo[1] > 1e-6 ? hi[1] - lo[1] : 1e-6;
}

/* make a closed component's triangles [t0, nt) face outwards */
static void b_orient(builder *b, size_t t0) {
  if (b->count_only) return;
  double vol = 0;
  for (size_t t = t0; t < b->nt; t++) {
    const float *a = b->pos + 3 * b->idx[3 * t], *c = b->pos + 3 * b->idx[3 * t + 1];
    const float *d = b->pos + 3 * b->idx[3 * t + 2];
    vol += (double)a[0] * ((double)c[1] * d[2] - (double)c[2] * d[1]) -
           (double)a[1] * ((double)c[0] * d[2] - (double)c[2] * d[0]) +
           (double)a[2] * ((double)c[0] * d[1] - (double)c[1] * d[0]);
  }
  if (vol >= 0) return;
  for (size_t t = t0; t < b->nt; t++) {
    uint32_t s = b->idx[3 * t + 1];
    b->idx[3 * t + 1] = b->idx[3 * t + 2];
    b->idx[3 * t + 2] = s;
  }
}

/* ---- outlines and profiles ---------------------------------------------- */

typedef struct outline {
  size_t n;
  double *c, *nr; /* 2n each: curve points and outward normals, counter-clockwise */
  double rref;    /* a typical radius, for sample counts */
} outline;

static void outline_free(outline *o) {
  free(o->c);
  free(o->nr);
  memset(o, 0, sizeof *o);
}

static size_t nseg(double len, double h, size_t nmin) {
  double n = ceil(len / h - 1e-9);
  if (n < (double)nmin) n = (double)nmin;
  if (n > 1e7) n = 1e7;
  return (size_t)n;
}

/* circle outline: c = 0, profile d is the radius */
static int outline_circle(outline *o, double rmax, double h) {
  o->n = nseg(2 * M_PI * rmax, h, 12);
  o->c = calloc(2 * o->n, sizeof(double));
  o->nr = calloc(2 * o->n, sizeof(double));
  if (!o->c || !o->nr) return -1;
  for (size_t j = 0; j < o->n; j++) {
    double a = 2 * M_PI * (double)j / (double)o->n;
    o->nr[2 * j] = cos(a);
    o->nr[2 * j + 1] = sin(a);
  }
  o->rref = 0;
  return 0;
}

/* rounded rectangle with half extents A, B and corner radius rc */
static int outline_rrect(outline *o, double A, double B, double rc, double h) {
  double sx = 2 * (A - rc), sy = 2 * (B - rc), arc = 0.5 * M_PI * rc;
  size_t nx = sx > 1e-9 ? nseg(sx, h, 1) : 0, ny = sy > 1e-9 ? nseg(sy, h, 1) : 0;
  size_t nc = nseg(arc, h, 3);
  o->n = 2 * nx + 2 * ny + 4 * nc;
  o->c = calloc(2 * o->n, sizeof(double));
  o->nr = calloc(2 * o->n, sizeof(double));
  if (!o->c || !o->nr) return -1;
  o->rref = 0.5 * (A + B);
  size_t j = 0;
  double cx[4] = {A - rc, -(A - rc), -(A - rc), A - rc};
  double cy[4] = {B - rc, B - rc, -(B - rc), -(B - rc)};
  for (int side = 0; side < 4; side++) {
    /* straight piece (right, top, left, bottom), then the corner after it */
    size_t ns = (side % 2 == 0) ? ny : nx;
    double a0 = side * 0.5 * M_PI;
    double nxv = cos(a0), nyv = sin(a0);
    int prev = (side + 3) % 4;
    double x0 = cx[prev] + rc * nxv, y0 = cy[prev] + rc * nyv;
    double x1 = cx[side] + rc * nxv, y1 = cy[side] + rc * nyv;
    for (size_t k = 0; k < ns; k++) {
      double t = (double)k / (double)ns;
      o->c[2 * j] = x0 + (x1 - x0) * t;
      o->c[2 * j + 1] = y0 + (y1 - y0) * t;
      o->nr[2 * j] = nxv;
      o->nr[2 * j + 1] = nyv;
      j++;
    }
    for (size_t k = 0; k < nc; k++) {
      double a = a0 + 0.5 * M_PI * (double)k / (double)nc;
      o->c[2 * j] = cx[side] + rc * cos(a);
      o->c[2 * j + 1] = cy[side] + rc * sin(a);
      o->nr[2 * j] = cos(a);
      o->nr[2 * j + 1] = sin(a);
      j++;
    }
  }
  return 0;
}

typedef struct prow {
  double s, d, z;
} prow;
typedef struct pseg {
  size_t i0, i1;
  int part, style;
} pseg;

#define MAX_SEGS 24
typedef struct profile {
  prow *r;
  size_t n, cap;
  pseg seg[MAX_SEGS];
  int nseg;
  size_t mark;
  double rref, h;
  int oom;
} profile;

static void prof_init(profile *pf, double rref, double h) {
  memset(pf, 0, sizeof *pf);
  pf->rref = rref;
  pf->h = h;
}

static void prof_push(profile *pf, double s, double d, double z) {
  if (pf->n == pf->cap) {
    size_t nc = pf->cap ? 2 * pf->cap : 64;
    prow *nr = realloc(pf->r, nc * sizeof *nr);
    if (!nr) {
      pf->oom = 1;
      return;
    }
    pf->r = nr;
    pf->cap = nc;
  }
  pf->r[pf->n++] = (prow){s, d, z};
}

/* an equivalent radius for lengths along the profile */
static double prof_req(const profile *pf, double s, double d) { return s * (pf->rref + d); }

static void prof_line(profile *pf, double s, double d, double z) {
  if (pf->n == 0) {
    prof_push(pf, s, d, z);
    return;
  }
  prow a = pf->r[pf->n - 1];
  double len = hypot(prof_req(pf, s, d) - prof_req(pf, a.s, a.d), z - a.z);
  size_t n = nseg(len, pf->h, 1);
  for (size_t k = 1; k <= n; k++) {
    double t = (double)k / (double)n;
    prof_push(pf, a.s + (s - a.s) * t, a.d + (d - a.d) * t, a.z + (z - a.z) * t);
  }
}

/* arc in (d, z) at s = 1 around (cd, cz) from angle a0 to a1; the current
 * last row is taken as the arc's start */
static void prof_arc(profile *pf, double cd, double cz, double rad, double a0, double a1,
                     size_t nmin) {
  size_t n = nseg(fabs(a1 - a0) * rad, pf->h, nmin);
  for (size_t k = 1; k <= n; k++) {
    double a = a0 + (a1 - a0) * (double)k / (double)n;
    prof_push(pf, 1.0, cd + rad * cos(a), cz + rad * sin(a));
  }
}

/* the rows since the last segment end become a segment of part/style u */
static void prof_seg(profile *pf, slot_use u) {
  if (pf->nseg >= MAX_SEGS || pf->n == 0) {
    pf->oom = 1;
    return;
  }
  pf->seg[pf->nseg++] = (pseg){pf->mark, pf->n - 1, u.part, u.style};
  pf->mark = pf->n - 1;
}

static void prof_free(profile *pf) { free(pf->r); }

typedef void (*disp_fn)(const void *ctx, double p[3]);

/* sweep a closed profile (first and last rows on the axis) round an outline;
 * M (3x4 row-major, optional) places the component */
static int sweep_build(builder *b, const outline *ol, const profile *pf, const double *M,
                       disp_fn disp, const void *dctx) {
  if (pf->oom || pf->n < 3) return -1;
  size_t N = ol->n, R = pf->n;
  size_t t0 = b->nt;
  double *G = NULL, *L = NULL;
  if (!b->count_only) {
    G = hearth_alloc_array(R * N * 3, sizeof(double));
    L = hearth_alloc_array(R * N * 2, sizeof(double));
    if (!G || !L) {
      free(G);
      free(L);
      return -1;
    }
    for (size_t i = 0; i < R; i++) {
      prow r = pf->r[i];
      for (size_t j = 0; j < N; j++) {
        double x = r.s * (ol->c[2 * j] + r.d * ol->nr[2 * j]);
        double y = r.s * (ol->c[2 * j + 1] + r.d * ol->nr[2 * j + 1]);
        double p[3] = {x, y, r.z};
        if (disp) disp(dctx, p);
        L[2 * (i * N + j)] = p[0];
        L[2 * (i * N + j) + 1] = p[1];
        double *g = G + 3 * (i * N + j);
        if (M) {
          for (int k = 0; k < 3; k++)
            g[k] = M[4 * k] * p[0] + M[4 * k + 1] * p[1] + M[4 * k + 2] * p[2] + M[4 * k + 3];
        } else {
          g[0] = p[0];
          g[1] = p[1];
          g[2] = p[2];
        }
      }
    }
  }
  for (int si = 0; si < pf->nseg; si++) {
    pseg sg = pf->seg[si];
    int start_pole = sg.i0 == 0, end_pole = sg.i1 == R - 1;
    if (start_pole || end_pole) {
      /* a disk: pole vertex + rings, planar native coordinates */
      patch *pp = b_patch(b, sg.part, sg.style, K_DISK);
      size_t pole_row = start_pole ? 0 : R - 1;
      size_t r0 = start_pole ? 1 : sg.i0, r1 = start_pole ? sg.i1 : R - 2;
      double zero[3] = {0, 0, 0};
      const double *pg = G ? G + 3 * (pole_row * N) : zero;
      uint32_t pole = b_vert(b, pg, L ? L[2 * pole_row * N] : 0, L ? L[2 * pole_row * N + 1] : 0);
      uint32_t base = (uint32_t)b->nv;
      for (size_t i = r0; i <= r1; i++)
        for (size_t j = 0; j < N; j++)
          b_vert(b, G ? G + 3 * (i * N + j) : zero, L ? L[2 * (i * N + j)] : 0,
                 L ? L[2 * (i * N + j) + 1] : 0);
      size_t nr = r1 - r0 + 1;
      for (size_t i = 0; i + 1 < nr; i++)
        for (size_t j = 0; j < N; j++) {
          size_t jn = (j + 1) % N;
          uint32_t a = base + (uint32_t)(i * N + j), c = base + (uint32_t)(i * N + jn);
          uint32_t d = base + (uint32_t)((i + 1) * N + jn), e = base + (uint32_t)((i + 1) * N + j);
          b_tri(b, a, c, d, sg.part);
          b_tri(b, a, d, e, sg.part);
        }
      for (size_t j = 0; j < N; j++) {
        size_t jn = (j + 1) % N;
        if (start_pole) {
          b_tri(b, pole, base + (uint32_t)jn, base + (uint32_t)j, sg.part);
        } else {
          size_t i = nr - 1;
          b_tri(b, base + (uint32_t)(i * N + j), base + (uint32_t)(i * N + jn), pole, sg.part);
        }
      }
      patch_close(b, pp);
    } else {
      /* a strip with a seam column duplicated; native x along the outline,
       * y along the profile (both from the undisplaced profile, so the count
       * pass and the fill pass agree). A long thin band is cut into a few
       * chunks so the packer can use the texture. */
      double lt = 0, ltot = 0;
      for (size_t i = sg.i0; i <= sg.i1; i++) {
        prow rw = pf->r[i];
        double per = 0, px = rw.s * (ol->c[0] + rw.d * ol->nr[0]);
        double py = rw.s * (ol->c[1] + rw.d * ol->nr[1]);
        for (size_t j = 1; j <= N; j++) {
          size_t jj = j % N;
          double qx = rw.s * (ol->c[2 * jj] + rw.d * ol->nr[2 * jj]);
          double qy = rw.s * (ol->c[2 * jj + 1] + rw.d * ol->nr[2 * jj + 1]);
          per += hypot(qx - px, qy - py);
          px = qx;
          py = qy;
        }
        if (per > lt) lt = per;
        if (i > sg.i0) {
          prow q = pf->r[i - 1];
          ltot +=
              hypot(rw.s * (ol->c[0] + rw.d * ol->nr[0]) - q.s * (ol->c[0] + q.d * ol->nr[0]),
                    hypot(rw.s * (ol->c[1] + rw.d * ol->nr[1]) - q.s * (ol->c[1] + q.d * ol->nr[1]),
                          rw.z - q.z));
        }
      }
      size_t nch = 1;
      if (ltot > 0) {
        double asp = lt / ltot;
        nch = asp > 24 ? 4 : asp > 10 ? 3 : asp > 5 ? 2 : 1;
      }
      if (nch > N / 4) nch = 1;
      size_t nr = sg.i1 - sg.i0 + 1;
      for (size_t ch = 0; ch < nch; ch++) {
        size_t j0 = N * ch / nch, j1 = N * (ch + 1) / nch, nc = j1 - j0;
        patch *pp = b_patch(b, sg.part, sg.style, K_STRIP);
        uint32_t base = (uint32_t)b->nv;
        double acc = 0;
        for (size_t i = sg.i0; i <= sg.i1; i++) {
          if (i > sg.i0) {
            prow rw = pf->r[i], q = pf->r[i - 1];
            acc += hypot(rw.s * (ol->c[0] + rw.d * ol->nr[0]) - q.s * (ol->c[0] + q.d * ol->nr[0]),
                         hypot(rw.s * (ol->c[1] + rw.d * ol->nr[1]) -
                                   q.s * (ol->c[1] + q.d * ol->nr[1]),
                               rw.z - q.z));
          }
          for (size_t j = j0; j <= j1; j++) {
            double zero[3] = {0, 0, 0};
            b_vert(b, G ? G + 3 * (i * N + j % N) : zero, lt * (double)j / (double)N, acc);
          }
        }
        for (size_t i = 0; i + 1 < nr; i++)
          for (size_t j = 0; j < nc; j++) {
            uint32_t a = base + (uint32_t)(i * (nc + 1) + j), c = a + 1;
            uint32_t e = base + (uint32_t)((i + 1) * (nc + 1) + j), d = e + 1;
            b_tri(b, a, c, d, sg.part);
            b_tri(b, a, d, e, sg.part);
          }
        patch_close(b, pp);
      }
    }
  }
  free(G);
  free(L);
  b_orient(b, t0);
  return 0;
}

/* a tube along a planar path: path(t) for t in [0,1], half-axes a (along
 * the plane normal bn) and c (in the plane) */
typedef struct tube_def {
  double p[4][3];        /* cubic Bezier control points */
  double bn[3];          /* unit normal of the path's plane */
  double a0, a1, c0, c1; /* half-axes at the start and end */
} tube_def;

static void bez(const tube_def *td, double t, double out[3]) {
  double u = 1 - t, w0 = u * u * u, w1 = 3 * u * u * t, w2 = 3 * u * t * t, w3 = t * t * t;
  for (int k = 0; k < 3; k++)
    out[k] = w0 * td->p[0][k] + w1 * td->p[1][k] + w2 * td->p[2][k] + w3 * td->p[3][k];
}

static int tube_build(builder *b, const tube_def *td, slot_use u, double h) {
  int part = u.part;
  double len = 0, prev[3], cur[3];
  bez(td, 0, prev);
  for (int k = 1; k <= 64; k++) {
    bez(td, k / 64.0, cur);
    len += sqrt((cur[0] - prev[0]) * (cur[0] - prev[0]) + (cur[1] - prev[1]) * (cur[1] - prev[1]) +
                (cur[2] - prev[2]) * (cur[2] - prev[2]));
    memcpy(prev, cur, sizeof cur);
  }
  double amax = fmax(td->a0, td->a1), cmax = fmax(td->c0, td->c1);
  double per = 2 * M_PI * sqrt(0.5 * (amax * amax + cmax * cmax));
  size_t M = nseg(len, h, 6), K = nseg(per, h, 8);
  size_t t0 = b->nt;
  double *G = NULL, *X = NULL;
  if (!b->count_only) {
    G = hearth_alloc_array((M + 1) * K * 3, sizeof(double));
    X = hearth_alloc_array(2 * K * 2, sizeof(double));
    if (!G || !X) {
      free(G);
      free(X);
      return -1;
    }
    for (size_t i = 0; i <= M; i++) {
      double t = (double)i / (double)M, p[3], q0[3], q1[3], tg[3], nrm[3];
      bez(td, t, p);
      bez(td, fmax(0, t - 1e-4), q0);
      bez(td, fmin(1, t + 1e-4), q1);
      double tl = 0;
      for (int k = 0; k < 3; k++) {
        tg[k] = q1[k] - q0[k];
        tl += tg[k] * tg[k];
      }
      tl = sqrt(tl);
      for (int k = 0; k < 3; k++) tg[k] /= tl;
      nrm[0] = td->bn[1] * tg[2] - td->bn[2] * tg[1];
      nrm[1] = td->bn[2] * tg[0] - td->bn[0] * tg[2];
      nrm[2] = td->bn[0] * tg[1] - td->bn[1] * tg[0];
      double a = td->a0 + (td->a1 - td->a0) * t, c = td->c0 + (td->c1 - td->c0) * t;
      for (size_t k = 0; k < K; k++) {
        double ph = 2 * M_PI * (double)k / (double)K, ca = a * cos(ph), sc = c * sin(ph);
        for (int m = 0; m < 3; m++) G[3 * (i * K + k) + m] = p[m] + ca * td->bn[m] + sc * nrm[m];
        if (i == 0 || i == M) {
          size_t e = (i == 0) ? 0 : 1;
          X[2 * (e * K + k)] = ca;
          X[2 * (e * K + k) + 1] = sc;
        }
      }
    }
  }
  double zero[3] = {0, 0, 0};
  /* side strip */
  patch *pp = b_patch(b, part, u.style, K_STRIP);
  uint32_t base = (uint32_t)b->nv;
  for (size_t i = 0; i <= M; i++)
    for (size_t k = 0; k <= K; k++)
      b_vert(b, G ? G + 3 * (i * K + k % K) : zero, per * (double)k / (double)K,
             len * (double)i / (double)M);
  for (size_t i = 0; i < M; i++)
    for (size_t k = 0; k < K; k++) {
      uint32_t a = base + (uint32_t)(i * (K + 1) + k), c = a + 1;
      uint32_t e = base + (uint32_t)((i + 1) * (K + 1) + k), d = e + 1;
      b_tri(b, a, c, d, part);
      b_tri(b, a, d, e, part);
    }
  patch_close(b, pp);
  /* end caps: fans round the path's end points */
  for (int e = 0; e < 2; e++) {
    patch *cp = b_patch(b, part, u.style, K_DISK);
    double pc[3];
    bez(td, (double)e, pc);
    uint32_t c = b_vert(b, pc, 0, 0);
    uint32_t rb = (uint32_t)b->nv;
    size_t i = e ? M : 0;
    for (size_t k = 0; k < K; k++)
      b_vert(b, G ? G + 3 * (i * K + k) : zero, X ? X[2 * (e * K + k)] : 0,
             X ? X[2 * (e * K + k) + 1] : 0);
    for (size_t k = 0; k < K; k++) {
      uint32_t j0 = rb + (uint32_t)k, j1 = rb + (uint32_t)((k + 1) % K);
      if (e == 0) b_tri(b, c, j1, j0, part);
      else b_tri(b, c, j0, j1, part);
    }
    patch_close(b, cp);
  }
  free(G);
  free(X);
  b_orient(b, t0);
  return 0;
}

/* a handle-like tube in the vertical plane at azimuth phi: from radius r0 at
 * height z0 out by `reach` and back to radius r1 at z1, leaving and meeting
 * the body horizontally */
static void tube_handle(tube_def *td, double phi, double r0, double z0, double r1, double z1,
                        double reach, double a, double c) {
  double cx = cos(phi), cy = sin(phi);
  double rr[4] = {r0, r0 + reach, r1 + reach, r1}, zz[4] = {z0, z0, z1, z1};
  for (int k = 0; k < 4; k++) {
    td->p[k][0] = rr[k] * cx;
    td->p[k][1] = rr[k] * cy;
    td->p[k][2] = zz[k];
  }
  td->bn[0] = -cy;
  td->bn[1] = cx;
  td->bn[2] = 0;
  td->a0 = td->a1 = a;
  td->c0 = td->c1 = c;
}

/* ---- shapes ------------------------------------------------------------- */

typedef struct shape {
  const synth_category *cat;
  double d[D_COUNT]; /* dimensions (synth_dim) */
  double col[4][3];  /* colour slots */
  uint64_t tseed;    /* texture detail */
} shape;

static void pick_col(hearth_rng *r, double out[3], const double (*choices)[3], int n) {
  int k = (int)(hearth_rng_uniform(r) * n);
  if (k >= n) k = n - 1;
  for (int m = 0; m < 3; m++) out[m] = choices[k][m];
}

/* an instance's texture seed, colours and dimensions (synth_draw) */
static void shape_draw(shape *s, const synth_category *cat, hearth_rng *r) {
  memset(s, 0, sizeof *s);
  s->cat = cat;
  s->tseed = hearth_rng_u64(r);
  const synth_palette *vivid = &synth_palettes[PAL_VIVID];
  for (int k = 0; k < 4; k++) pick_col(r, s->col[k], vivid->rgb, vivid->n);
  double *d = s->d;
  for (const synth_draw *st = cat->draw; st < cat->draw + SYNTH_MAX_DRAWS && st->op; st++) {
    switch (st->op) {
      case DRAW_RANGE: d[st->dst] = hearth_rng_range(r, st->lo, st->hi); break;
      case DRAW_SCALED:
        d[st->dst] = st->k * d[st->src] * hearth_rng_range(r, st->lo, st->hi);
        break;
      case DRAW_OFFSET: d[st->dst] = d[st->src] + hearth_rng_range(r, st->lo, st->hi); break;
      case DRAW_CONST: d[st->dst] = st->k; break;
      case DRAW_TIMES: d[st->dst] = d[st->src] * st->k; break;
      case DRAW_MINUS: d[st->dst] = d[st->src] - st->k; break;
      case DRAW_FLAG: d[st->dst] = hearth_rng_uniform(r) < st->k; break;
      case DRAW_COLOUR:
        pick_col(r, s->col[st->dst], synth_palettes[st->src].rgb, (int)st->k);
        break;
      case DRAW_END: break;
    }
  }
}

/* the part and style of slot k of the instance's category (the part is
 * numbered on first use) */
static slot_use b_slot(builder *b, const shape *s, int k) {
  const synth_slot *sl = &s->cat->slots[k];
  return (slot_use){b_part(b, sl->part), sl->style[s->d[D_VARIANT] != 0]};
}

/* slots first..last-1, numbered in that order */
static void b_slots(builder *b, const shape *s, int first, int last, slot_use *out) {
  for (int k = first; k < last; k++) out[k] = b_slot(b, s, k);
}

/* a domed lid from radius r0 at height z0 in to a knob of radius rk: the
 * dome rises by hd, the knob hk above it */
static void prof_dome(profile *pf, double r0, double z0, double rk, double hd, double hk,
                      slot_use dome, slot_use knob) {
  size_t n = nseg(r0, pf->h, 4);
  for (size_t k = 1; k <= n; k++) {
    double t = (double)k / (double)n, r = r0 + (rk - r0) * t;
    prof_push(pf, 1, r, z0 + hd * sin(0.5 * M_PI * t));
  }
  prof_seg(pf, dome);
  prof_line(pf, 1, rk, z0 + hd + hk);
  prof_seg(pf, knob);
  prof_line(pf, 1, 0, z0 + hd + hk);
  prof_seg(pf, knob);
}

/* a profile of edge length h starting on the axis at height z */
static void prof_start(profile *pf, double h, double z) {
  prof_init(pf, 0, h);
  prof_push(pf, 1, 0, z);
}

/* sweep profile pf round a circle sampled for radius rmax, placed by M
 * (3x4, optional) and displaced by disp (optional); frees pf */
static int revolve(builder *b, profile *pf, double rmax, const double *M, disp_fn disp,
                   const void *dctx) {
  outline ol = {0};
  int rc = outline_circle(&ol, rmax, pf->h) ? -1 : sweep_build(b, &ol, pf, M, disp, dctx);
  outline_free(&ol);
  prof_free(pf);
  return rc;
}

/* SHAPE_VESSEL (synth_vessel) */
static int build_vessel(builder *b, const shape *s, double h) {
  const synth_vessel *v = &s->cat->vessel;
  slot_use sl[VESSEL_SLOTS];
  b_slots(b, s, VESSEL_BODY, VESSEL_LID, sl);
  const double *d = s->d;
  double R = d[D_R], Rb = d[D_R2], H = d[D_H], tw = d[D_T], tb = d[D_T2], f = v->foot;
  double fi = v->inner_round;
  profile pf;
  prof_start(&pf, h, 0);
  prof_line(&pf, 1, Rb - f, 0);
  prof_seg(&pf, sl[VESSEL_BOTTOM]);
  prof_arc(&pf, Rb - f, f, f, -0.5 * M_PI, 0, (size_t)v->foot_steps);
  prof_line(&pf, 1, R, H - 0.5 * tw);
  prof_seg(&pf, sl[VESSEL_BODY]);
  prof_arc(&pf, R - 0.5 * tw, H - 0.5 * tw, 0.5 * tw, 0, M_PI, 3);
  prof_seg(&pf, sl[VESSEL_RIM]);
  /* the inner wall parallel to the outer one */
  double rib = Rb - tw + (R - Rb) * tb / H;
  prof_line(&pf, 1, rib, tb + fi);
  prof_arc(&pf, rib - fi, tb + fi, fi, 0, -0.5 * M_PI, 2);
  prof_seg(&pf, sl[VESSEL_INNER]);
  prof_line(&pf, 1, 0, tb);
  prof_seg(&pf, sl[VESSEL_INNER]);
  int rc = revolve(b, &pf, R + v->margin, NULL, NULL, NULL);
  tube_def td;
  if (!rc && !v->lugs) {
    /* ends buried half-way into the wall */
    double z0 = H * v->mug[0], z1 = H * v->mug[1];
    double r0 = Rb + (R - Rb) * z0 / H - 0.5 * tw, r1 = Rb + (R - Rb) * z1 / H - 0.5 * tw;
    tube_handle(&td, 0, r0, z0, r1, z1, d[D_REACH] * v->mug[2], d[D_A], d[D_C]);
    rc = tube_build(b, &td, sl[VESSEL_HANDLE], h);
  }
  for (int k = 0; !rc && v->lugs && k < 2; k++) {
    double zh = H - v->lug[0];
    tube_handle(&td, k * M_PI, R - 0.5 * tw, zh + v->lug[1], R - 0.5 * tw, zh - v->lug[1],
                d[D_REACH], d[D_A], d[D_C]);
    rc = tube_build(b, &td, sl[VESSEL_HANDLE], h);
  }
  if (!rc && v->lid && d[D_VARIANT]) {
    /* resting on the rim */
    b_slots(b, s, VESSEL_LID, VESSEL_SLOTS, sl);
    double Rl = R + 0.002, zl = H + 0.0002;
    prof_start(&pf, h, zl);
    prof_line(&pf, 1, Rl, zl);
    prof_seg(&pf, sl[VESSEL_LID]);
    prof_line(&pf, 1, Rl, zl + 0.004);
    prof_dome(&pf, Rl, zl + 0.004, 0.016, 0.015, 0.02, sl[VESSEL_LID], sl[VESSEL_KNOB]);
    rc = revolve(b, &pf, R + v->margin, NULL, NULL, NULL);
  }
  return rc;
}

/* SHAPE_CAN */
static int build_can(builder *b, const shape *s, double h) {
  slot_use sl[CAN_SLOTS];
  b_slots(b, s, 0, CAN_SLOTS, sl);
  double R = s->d[D_R], H = s->d[D_H];
  profile pf;
  prof_start(&pf, h, 0.004);
  prof_line(&pf, 1, R - 0.008, 0.0);
  prof_seg(&pf, sl[CAN_DOME]);
  prof_line(&pf, 1, R - 0.0065, 0.0);
  prof_line(&pf, 1, R, 0.010);
  prof_seg(&pf, sl[CAN_FOOT]);
  prof_line(&pf, 1, R, H - 0.013);
  prof_seg(&pf, sl[CAN_BODY]);
  prof_line(&pf, 1, R - 0.0045, H - 0.002);
  prof_line(&pf, 1, R - 0.0045, H);
  prof_line(&pf, 1, R - 0.0065, H);
  prof_line(&pf, 1, R - 0.0065, H - 0.003);
  prof_seg(&pf, sl[CAN_RIM]);
  prof_line(&pf, 1, 0, H - 0.003);
  prof_seg(&pf, sl[CAN_LID]);
  return revolve(b, &pf, R, NULL, NULL, NULL);
}

/* SHAPE_BOTTLE: body D_R x D_H, neck radius D_R2 */
static int build_bottle(builder *b, const shape *s, double h) {
  slot_use sl[BOTTLE_SLOTS];
  b_slots(b, s, 0, BOTTLE_SLOTS, sl);
  double R = s->d[D_R], H = s->d[D_H], rn = s->d[D_R2], rcap = rn + 0.0015, hc = 0.02;
  double zs = H * 0.62, zn = H * 0.84, zl0 = H * 0.25, zl1 = H * 0.50;
  profile pf;
  prof_start(&pf, h, 0.003);
  prof_line(&pf, 1, R - 0.006, 0);
  prof_seg(&pf, sl[BOTTLE_BOTTOM]);
  prof_arc(&pf, R - 0.006, 0.006, 0.006, -0.5 * M_PI, 0, 3);
  prof_line(&pf, 1, R, zl0);
  prof_seg(&pf, sl[BOTTLE_BODY]);
  prof_line(&pf, 1, R, zl1);
  prof_seg(&pf, sl[BOTTLE_LABEL]);
  prof_line(&pf, 1, R, zs);
  /* the shoulder: a half cosine from the body in to the neck */
  size_t n = nseg(hypot(R - rn, zn - zs) * 1.2, h, 6);
  for (size_t k = 1; k <= n; k++) {
    double t = (double)k / (double)n;
    prof_push(&pf, 1, rn + (R - rn) * 0.5 * (1 + cos(M_PI * t)), zs + (zn - zs) * t);
  }
  prof_seg(&pf, sl[BOTTLE_BODY]);
  prof_line(&pf, 1, rn, H - hc);
  prof_seg(&pf, sl[BOTTLE_NECK]);
  prof_line(&pf, 1, rcap, H - hc);
  prof_line(&pf, 1, rcap, H - 0.0015);
  prof_arc(&pf, rcap - 0.0015, H - 0.0015, 0.0015, 0, 0.5 * M_PI, 2);
  prof_seg(&pf, sl[BOTTLE_CAP]);
  prof_line(&pf, 1, 0, H);
  prof_seg(&pf, sl[BOTTLE_CAP]);
  return revolve(b, &pf, R, NULL, NULL, NULL);
}

/* peel bumps: a small radial displacement from smooth 3D noise */
typedef struct peel_disp {
  double zc, amp;
  uint64_t seed;
} peel_disp;
static void peel_displace(const void *ctx, double p[3]) {
  const peel_disp *od = ctx;
  double q[3] = {p[0], p[1], p[2] - od->zc};
  double r = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  if (r < 1e-9) return;
  double n = synth_noise3(od->seed, q[0] / 0.006, q[1] / 0.006, q[2] / 0.006) * 0.6 +
             synth_noise3(od->seed + 1, q[0] / 0.0025, q[1] / 0.0025, q[2] / 0.0025) * 0.4;
  double k = 1 + od->amp * n / r;
  p[0] = q[0] * k;
  p[1] = q[1] * k;
  p[2] = q[2] * k + od->zc;
}

/* SHAPE_SPHEROID: radius D_R, height D_H; the stem end is a cap at the top */
static int build_spheroid(builder *b, const shape *s, double h) {
  slot_use sl[SPHEROID_SLOTS];
  b_slots(b, s, 0, SPHEROID_SLOTS, sl);
  double R = s->d[D_R], Hz = 0.5 * s->d[D_H], cap = 0.35;
  size_t n1 = nseg(cap * R, h, 2), n2 = nseg((M_PI - 2 * cap) * R, h, 6);
  profile pf;
  prof_start(&pf, h, 0);
  for (size_t k = 1; k <= n1; k++) {
    double a = -0.5 * M_PI + cap * (double)k / (double)n1;
    prof_push(&pf, 1, R * cos(a), Hz * (1 + sin(a)));
  }
  prof_seg(&pf, sl[SPHEROID_PEEL]);
  for (size_t k = 1; k <= n2; k++) {
    double a = -0.5 * M_PI + cap + (M_PI - 2 * cap) * (double)k / (double)n2;
    prof_push(&pf, 1, R * cos(a), Hz * (1 + sin(a)));
  }
  prof_seg(&pf, sl[SPHEROID_PEEL]);
  for (size_t k = 1; k <= n1; k++) {
    double a = 0.5 * M_PI - cap + cap * (double)k / (double)n1;
    prof_push(&pf, 1, k == n1 ? 0 : R * cos(a), Hz * (1 + sin(a)));
  }
  prof_seg(&pf, sl[SPHEROID_STEM]);
  peel_disp od = {Hz, 0.0004, s->tseed};
  return revolve(b, &pf, R, NULL, peel_displace, &od);
}

/* SHAPE_KETTLE: body radius D_R and height D_H on a base D_T high */
static int build_kettle(builder *b, const shape *s, double h) {
  slot_use sl[KETTLE_SLOTS];
  b_slots(b, s, 0, KETTLE_SLOTS, sl);
  double R = s->d[D_R], zb = s->d[D_T], Hb = s->d[D_H], Rt = R * 0.82;
  /* base plate */
  profile pf;
  prof_start(&pf, h, 0);
  prof_line(&pf, 1, R + 0.004, 0);
  prof_seg(&pf, sl[KETTLE_BASE]);
  prof_arc(&pf, R + 0.004, 0.004, 0.004, -0.5 * M_PI, 0, 2);
  prof_line(&pf, 1, R + 0.008, zb - 0.004);
  prof_arc(&pf, R + 0.004, zb - 0.004, 0.004, 0, 0.5 * M_PI, 2);
  prof_seg(&pf, sl[KETTLE_BASE]);
  prof_line(&pf, 1, 0, zb);
  prof_seg(&pf, sl[KETTLE_BASE]);
  int rc = revolve(b, &pf, R + 0.01, NULL, NULL, NULL);
  if (rc) return rc;
  /* body with a domed lid and knob; it floats 0.3 mm above the base so the
   * two never share a vertex */
  zb += 0.0003;
  prof_start(&pf, h, zb);
  prof_line(&pf, 1, R - 0.01, zb);
  prof_seg(&pf, sl[KETTLE_BODY]);
  prof_arc(&pf, R - 0.01, zb + 0.01, 0.01, -0.5 * M_PI, 0, 3);
  prof_line(&pf, 1, Rt + 0.012, zb + Hb - 0.012);
  prof_arc(&pf, Rt, zb + Hb - 0.012, 0.012, 0, 0.5 * M_PI, 3);
  prof_seg(&pf, sl[KETTLE_BODY]);
  prof_dome(&pf, Rt, zb + Hb, 0.014, 0.012, 0.012, sl[KETTLE_LID], sl[KETTLE_KNOB]);
  rc = revolve(b, &pf, R, NULL, NULL, NULL);
  if (rc) return rc;
  /* handle at the back, ends inside the body */
  double z0 = zb + Hb * 0.85, z1 = zb + Hb * 0.25;
  double rz0 = R - (R - Rt) * 0.85 - 0.015, rz1 = R - (R - Rt) * 0.25 - 0.015;
  tube_def td;
  tube_handle(&td, M_PI, rz0, z0, rz1, z1, s->d[D_REACH] * 1.33, 0.012, 0.010);
  rc = tube_build(b, &td, sl[KETTLE_HANDLE], h);
  if (rc) return rc;
  /* spout at the front: up and out, tapering */
  double zs = zb + Hb * 0.78, rs = R - (R - Rt) * 0.78 - 0.012;
  tube_def sp = {{{rs, 0, zs},
                  {rs + 0.03, 0, zs + 0.004},
                  {rs + 0.04, 0, zs + 0.025},
                  {rs + 0.045, 0, zs + 0.04}},
                 {0, 1, 0},
                 0.014,
                 0.008,
                 0.012,
                 0.006};
  return tube_build(b, &sp, sl[KETTLE_SPOUT], h);
}

/* SHAPE_SLAB: a rounded rectangle D_W x D_L (corner radius D_RC) swept by a
 * profile D_H high with edge rounds D_E: bottom face, side, top face. The
 * side is split at D_ZSPLIT (0: none) into SLAB_SIDE and SLAB_UPPER; the top
 * face domes up by D_BULGE. */
static int build_slab(builder *b, const shape *s, double h) {
  slot_use sl[SLAB_SLOTS];
  b_slots(b, s, 0, SLAB_SLOTS, sl);
  const double *d = s->d;
  double A = 0.5 * d[D_W], B = 0.5 * d[D_L], e = d[D_E], bulge = d[D_BULGE];
  double H = d[D_H] - bulge, zsplit = d[D_ZSPLIT];
  outline ol = {0};
  profile pf;
  if (outline_rrect(&ol, A, B, d[D_RC], h)) return -1;
  prof_init(&pf, 0.5 * (A + B), h);
  size_t nf = nseg(pf.rref, pf.h, 2);
  /* bottom face from the centre out */
  for (size_t k = 0; k <= nf; k++) {
    double t = (double)k / (double)nf;
    prof_push(&pf, t, -e, 0.0);
  }
  prof_seg(&pf, sl[SLAB_BOTTOM]);
  prof_arc(&pf, -e, e, e, -0.5 * M_PI, 0, 2);
  if (zsplit > e && zsplit < H - e) {
    prof_line(&pf, 1, 0, zsplit);
    prof_seg(&pf, sl[SLAB_SIDE]);
    prof_line(&pf, 1, 0, H - e);
    prof_arc(&pf, -e, H - e, e, 0, 0.5 * M_PI, 2);
    prof_seg(&pf, sl[SLAB_UPPER]);
  } else {
    prof_line(&pf, 1, 0, H - e);
    prof_arc(&pf, -e, H - e, e, 0, 0.5 * M_PI, 2);
    prof_seg(&pf, sl[SLAB_SIDE]);
  }
  /* top face from the rim in to the centre */
  for (size_t k = 1; k <= nf; k++) {
    double t = 1 - (double)k / (double)nf;
    prof_push(&pf, t, -e, H + bulge * (1 - t * t));
  }
  prof_seg(&pf, sl[SLAB_TOP]);
  int rc = sweep_build(b, &ol, &pf, NULL, NULL, NULL);
  prof_free(&pf);
  outline_free(&ol);
  return rc;
}

/* SHAPE_HEADSET: ear cups of radius D_R, D_T thick, D_W apart, on a band of
 * half-axes D_A x D_C */
static int build_headset(builder *b, const shape *s, double h) {
  slot_use sl[HEADSET_SLOTS];
  b_slots(b, s, 0, HEADSET_SLOTS, sl);
  double R = s->d[D_R], T = s->d[D_T], W = s->d[D_W], e = 0.006;
  profile pf;
  prof_start(&pf, h, 0);
  prof_line(&pf, 1, R - e, 0);
  prof_seg(&pf, sl[HEADSET_CUP]);
  prof_arc(&pf, R - e, e, e, -0.5 * M_PI, 0, 2);
  prof_line(&pf, 1, R, T - e);
  prof_seg(&pf, sl[HEADSET_CUP]);
  prof_arc(&pf, R - e, T - e, e, 0, 0.5 * M_PI, 2);
  prof_line(&pf, 1, 0, T);
  prof_seg(&pf, sl[HEADSET_CUSHION]);
  outline ol = {0};
  int rc = outline_circle(&ol, R, h);
  for (int k = 0; k < 2 && !rc; k++) {
    /* cups stand on edge with their axes along x, cushions facing in */
    double sx = k ? -1.0 : 1.0, x0 = k ? 0.5 * W + 0.5 * T : -0.5 * W - 0.5 * T;
    double M[12] = {0, 0, sx, x0, 0, 1, 0, 0, -sx, 0, 0, R};
    rc = sweep_build(b, &ol, &pf, M, NULL, NULL);
  }
  prof_free(&pf);
  outline_free(&ol);
  if (rc) return rc;
  /* band over the top, its ends inside the cups */
  double hw = 0.5 * W, zc = R, k4 = 0.5523 * 2;
  tube_def td =
      {{{-hw, 0, zc}, {-hw, 0, zc + hw * k4 * 1.3}, {hw, 0, zc + hw * k4 * 1.3}, {hw, 0, zc}},
       {0, 1, 0},
       s->d[D_A],
       s->d[D_A],
       s->d[D_C],
       s->d[D_C]};
  return tube_build(b, &td, sl[HEADSET_BAND], h);
}

typedef int (*shape_fn)(builder *b, const shape *s, double h);
static const shape_fn k_shapes[SHAPE_COUNT] = {
    [SHAPE_VESSEL] = build_vessel,     [SHAPE_CAN] = build_can,       [SHAPE_BOTTLE] = build_bottle,
    [SHAPE_SPHEROID] = build_spheroid, [SHAPE_KETTLE] = build_kettle, [SHAPE_SLAB] = build_slab,
    [SHAPE_HEADSET] = build_headset};

/* build a shape at edge length h; returns -1 on allocation failure */
static int shape_build(builder *b, const shape *s, double h) {
  return k_shapes[s->cat->shape](b, s, h);
}

/* ---- UV packing ---------------------------------------------------------- */

#define UV_GAP (12.0 / 1024.0)
#define UV_MARGIN (6.0 / 1024.0)

static int cmp_patch_h(const void *a, const void *b, const patch *P) {
  const int ia = *(const int *)a, ib = *(const int *)b;
  double ha = P[ia].swap ? P[ia].w : P[ia].h, hb = P[ib].swap ? P[ib].w : P[ib].h;
  if (ha > hb) return -1;
  if (ha < hb) return 1;
  return ia - ib;
}

/* shelf packing at scale sc; returns 1 if everything fits */
static int pack_try(patch *P, const int *order, int n, double sc, int commit) {
  double x = UV_MARGIN, y = UV_MARGIN, shelf = 0;
  for (int k = 0; k < n; k++) {
    patch *p = &P[order[k]];
    double w = (p->swap ? p->h : p->w) * sc, hh = (p->swap ? p->w : p->h) * sc;
    if (x + w > 1 - UV_MARGIN && x > UV_MARGIN) {
      y += shelf + UV_GAP;
      x = UV_MARGIN;
      shelf = 0;
    }
    if (x + w > 1 - UV_MARGIN || y + hh > 1 - UV_MARGIN) return 0;
    if (commit) {
      p->pu = x;
      p->pv = y;
      p->ps = sc;
    }
    x += w + UV_GAP;
    if (hh > shelf) shelf = hh;
  }
  return 1;
}

static void pack_islands(builder *b) {
  int n = b->np, order[MAX_PATCHES];
  for (int i = 0; i < n; i++) {
    b->patches[i].swap = b->patches[i].h > b->patches[i].w;
    order[i] = i;
  }
  /* insertion sort by packed height (n is small) */
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && cmp_patch_h(&order[j], &order[j - 1], b->patches) < 0; j--) {
      int t = order[j];
      order[j] = order[j - 1];
      order[j - 1] = t;
    }
  double lo = 0, hi = 1e4;
  for (int it = 0; it < 60; it++) {
    double mid = 0.5 * (lo + hi);
    if (pack_try(b->patches, order, n, mid, 0)) lo = mid;
    else hi = mid;
  }
  pack_try(b->patches, order, n, lo, 1);
  for (int i = 0; i < n; i++) {
    patch *p = &b->patches[i];
    for (size_t v = p->v0; v < p->v1; v++) {
      double x = (b->uv[2 * v] - p->ox) * p->ps, y = (b->uv[2 * v + 1] - p->oy) * p->ps;
      b->uv[2 * v] = (float)(p->pu + (p->swap ? y : x));
      b->uv[2 * v + 1] = (float)(p->pv + (p->swap ? x : y));
    }
  }
}

/* ---- albedo -------------------------------------------------------------- */

static void mixc(double out[3], const double a[3], const double c[3], double t) {
  for (int k = 0; k < 3; k++) out[k] = a[k] + (c[k] - a[k]) * t;
}
static void setc(double out[3], double r, double g, double b) {
  out[0] = r;
  out[1] = g;
  out[2] = b;
}
static void copyc(double out[3], const double a[3]) { memcpy(out, a, 3 * sizeof(double)); }

static const double k_white[3] = {1, 1, 1};

/* a text-like block pattern: rows of short dark bars */
static double textish(uint64_t seed, double x, double y, double lh) {
  double row = floor(y / lh), fy = y / lh - row;
  if (fy < 0.25 || fy > 0.8) return 0;
  double word =
      floor(x / (lh * 0.9) + synth_lattice(seed, SYNTH_NOISE_SALT, (int64_t)row, 3, 0) * 7);
  if (synth_lattice(seed, SYNTH_NOISE_SALT, (int64_t)row, (int64_t)word, 1) < 0.25) return 0;
  double fx = x / (lh * 0.9) - floor(x / (lh * 0.9));
  return (fx > 0.1 && fx < 0.92) ? 1 : 0;
}

/* the grain most metal and peel patterns mix in */
static double coarse_grain(uint64_t ts, double x, double y) {
  return synth_fbm2(ts, x / 0.01, y / 0.01, 3);
}

/* pattern m->pattern at native point (x, y), (lx, ly) from the island's
 * corner, over the base colour in out */
static void draw_pattern(const shape *s, const patch *p, const synth_material *m, uint64_t ts,
                         double x, double y, double out[3]) {
  const double *d = s->d;
  double lx = x - p->ox, ly = y - p->oy;
  switch (m->pattern) {
    case PAT_NONE: break;
    case PAT_CAN_LABEL: {
      double t = ly / p->h, u = lx / p->w;
      if (t < 0.08 || t > 0.92) setc(out, 0.75, 0.76, 0.78);
      else if (fabs(t - 0.3) < 0.04) copyc(out, s->col[1]);
      else if (t > 0.42 && t < 0.75 && u > 0.1 && u < 0.45) {
        /* a logo block with white lettering */
        double q = textish(ts, lx, ly, 0.012);
        mixc(out, s->col[0], k_white, q);
      } else if (t > 0.45 && t < 0.65 && u > 0.6 && u < 0.9) {
        double q = textish(ts + 5, lx, ly, 0.004);
        mixc(out, out, (const double[3]){0.05, 0.05, 0.05}, q * 0.8);
      }
      break;
    }
    case PAT_ALU: {
      double r = hypot(x, y);
      double v =
          m->param + 0.05 * synth_noise2(ts, r / 0.0006, 0.5) + 0.02 * coarse_grain(ts, x, y);
      setc(out, v, v + 0.005, v + 0.015);
      if (m->alt && p->kind == K_DISK && x > 0.004 && x < 0.02 && fabs(y) < 0.006)
        setc(out, 0.55, 0.56, 0.58);
      break;
    }
    case PAT_BOTTLE_LABEL: {
      double t = ly / p->h;
      if (t < 0.12 || t > 0.88) setc(out, 0.95, 0.95, 0.95);
      double q = textish(ts, lx, ly, 0.008);
      if (t > 0.3 && t < 0.7) mixc(out, out, k_white, q);
      break;
    }
    case PAT_RIBS:
      if (p->kind == K_STRIP) {
        double rib = 0.5 + 0.5 * sin(lx / 0.0008 * 2 * M_PI);
        for (int k = 0; k < 3; k++) out[k] *= 0.85 + 0.15 * rib;
      }
      break;
    case PAT_PEEL: {
      double pores = synth_noise2(ts, x / 0.0009, y / 0.0009);
      double k = 0.06 * coarse_grain(ts, x, y) - (pores > 0.55 ? 0.12 * (pores - 0.55) / 0.45 : 0);
      for (int c = 0; c < 3; c++) out[c] += k * out[c] * 2;
      double r = hypot(x, y);
      if (m->alt && r < 0.004) mixc(out, out, (const double[3]){0.35, 0.40, 0.12}, 1 - r / 0.004);
      break;
    }
    case PAT_SCREEN: {
      double A = 0.5 * d[D_W] - d[D_E] - 0.0025, B = 0.5 * d[D_L] - d[D_E] - 0.004;
      if (fabs(x) < A && fabs(y) < B) {
        double g = 0.04 + 0.03 * (x / A + y / B + 2) / 4;
        setc(out, g, g, g + 0.01);
      } else {
        setc(out, 0.02, 0.02, 0.02);
      }
      if (hypot(x, y - (0.5 * d[D_L] - 0.009)) < 0.0018) setc(out, 0.10, 0.10, 0.14);
      break;
    }
    case PAT_FRAME: {
      double v = 0.55 + 0.04 * coarse_grain(ts, x, y);
      mixc(out, s->col[0], (const double[3]){v, v, v}, 0.6);
      break;
    }
    case PAT_CAMERA: {
      double cx = -(0.5 * d[D_W] - 0.02), cy = 0.5 * d[D_L] - 0.02;
      if (fabs(x - cx) < 0.015 && fabs(y - cy) < 0.015) {
        mixc(out, out, (const double[3]){0.15, 0.15, 0.16}, 0.7);
        for (int l = 0; l < 2; l++)
          if (hypot(x - cx + 0.005, y - cy - 0.006 + 0.012 * l) < 0.0045)
            setc(out, 0.03, 0.03, 0.05);
      }
      break;
    }
    case PAT_PORES: {
      double pores = synth_noise2(ts, x / 0.0007, y / 0.0007);
      if (pores > 0.5) mixc(out, out, (const double[3]){0.75, 0.58, 0.10}, (pores - 0.5) * 1.6);
      break;
    }
    case PAT_FIBRES: {
      double f = synth_noise2(ts, x / 0.0004, y / 0.003) * 0.5 +
                 synth_noise2(ts + 9, x / 0.003, y / 0.0004) * 0.5;
      for (int k = 0; k < 3; k++) out[k] *= 0.8 + 0.35 * f;
      break;
    }
    case PAT_BRUSHED: {
      double v = m->param + 0.06 * synth_noise2(ts, lx / 0.03, ly / 0.0004) +
                 0.03 * coarse_grain(ts, x, y);
      if (p->kind == K_STRIP) v += 0.08 * sin(2 * M_PI * lx / p->w * 2);
      setc(out, v, v + 0.005, v + 0.012);
      break;
    }
    case PAT_MOUSE:
      if (p->kind == K_DISK && fabs(x) < 0.0006 && y > d[D_L] * 0.1) setc(out, 0.02, 0.02, 0.02);
      if (p->kind == K_DISK && hypot(x, y - d[D_L] * 0.3) < 0.004) setc(out, 0.2, 0.2, 0.22);
      break;
    case PAT_PRINT: mixc(out, out, k_white, textish(ts, lx, ly, m->param)); break;
    case PAT_LOGO:
      if (hypot(x, y) < 0.012) setc(out, 0.82, 0.83, 0.85);
      break;
    case PAT_FEET:
      if (p->kind == K_DISK && fabs(fabs(x) - 0.5 * d[D_W] + 0.03) < 0.008 &&
          fabs(fabs(y) - 0.5 * d[D_L] + 0.03) < 0.008)
        setc(out, 0.1, 0.1, 0.1);
      break;
    case PAT_STITCHES:
      if (p->kind == K_DISK) {
        double dx = 0.5 * d[D_W] - d[D_E] - fabs(x), dy = 0.5 * d[D_L] - d[D_E] - fabs(y);
        double dm = fmin(dx, dy);
        if (dm > 0.003 && dm < 0.0038 && fmod(fabs(x + y) / 0.003, 1.0) < 0.6)
          setc(out, 0.85, 0.78, 0.60);
      }
      break;
    case PAT_FLOWERS:
      if (synth_noise2(ts, lx / 0.02, ly / 0.02) > 0.45) mixc(out, out, s->col[1], 0.7);
      break;
    case PAT_OPENING: {
      double ex = x / (0.5 * d[D_W] * 0.6), ey = y / (0.5 * d[D_L] * 0.35);
      if (ex * ex + ey * ey < 1) setc(out, 0.97, 0.97, 0.97);
      break;
    }
    case PAT_WEAVE: {
      double weave = 0.5 + 0.5 * sin(lx / 0.0012 * M_PI) * sin(ly / 0.0012 * M_PI);
      for (int k = 0; k < 3; k++) out[k] *= 0.92 + 0.08 * weave;
      if (m->alt && ((int)floor(lx / 0.04) + (int)floor(ly / 0.04)) % 2)
        for (int k = 0; k < 3; k++) out[k] *= 0.75;
      break;
    }
    case PAT_ZIP:
      if (fabs(ly - 0.5 * p->h) < 0.002) copyc(out, s->col[0]);
      break;
  }
}

/* colour of native point (x, y) of an island: its material (synth_material)
 * with texture detail from s->tseed */
static void shade(const shape *s, const patch *p, double x, double y, double out[3]) {
  const synth_material *m = &synth_materials[p->style];
  uint64_t ts = s->tseed + (uint64_t)m->stream * 977;
  switch (m->base) {
    case BASE_NONE: break;
    case BASE_RGB: copyc(out, m->rgb); break;
    case BASE_SLOT: copyc(out, s->col[m->slot]); break;
    case BASE_MIX: mixc(out, s->col[m->slot], m->rgb, m->mix); break;
  }
  if (m->band[2] > 0 && p->kind == K_STRIP) {
    double t = (y - p->oy) / p->h;
    if (t > m->band[0] && t < m->band[1]) mixc(out, out, s->col[0], m->band[2]);
  }
  if (m->grain != 0) {
    double g = synth_fbm2(ts, x / m->grain_size, y / m->grain_size, m->grain_octaves);
    for (int k = 0; k < 3; k++) out[k] += m->grain * g;
  }
  draw_pattern(s, p, m, ts, x, y, out);
}

typedef struct tex_job {
  const shape *s;
  const builder *b;
  hearth_image *img;
} tex_job;

static void tex_rows(void *ctx, size_t r0, size_t r1, int thread_index) {
  const tex_job *j = ctx;
  size_t R = j->img->width;
  uint8_t *px = j->img->data;
  double g = 0.5 * UV_GAP;
  for (size_t row = r0; row < r1; row++)
    for (size_t col = 0; col < R; col++) {
      double u = ((double)col + 0.5) / (double)R, v = ((double)row + 0.5) / (double)R;
      double c[3] = {0.5, 0.5, 0.5};
      for (int k = 0; k < j->b->np; k++) {
        const patch *p = &j->b->patches[k];
        double pw = (p->swap ? p->h : p->w) * p->ps, ph = (p->swap ? p->w : p->h) * p->ps;
        if (u < p->pu - g || u > p->pu + pw + g || v < p->pv - g || v > p->pv + ph + g) continue;
        double a = (u - p->pu) / p->ps, bb = (v - p->pv) / p->ps;
        double x = p->swap ? bb : a, y = p->swap ? a : bb;
        x = fmin(fmax(x, 0), p->w) + p->ox;
        y = fmin(fmax(y, 0), p->h) + p->oy;
        shade(j->s, p, x, y, c);
        break;
      }
      for (int m = 0; m < 3; m++) {
        double q = c[m] < 0 ? 0 : c[m] > 1 ? 1 : c[m];
        px[3 * (row * R + col) + m] = (uint8_t)lround(q * 255.0);
      }
    }
}

/* ---- public entry points ------------------------------------------------- */

void synth_object_free(synth_object *obj) {
  if (!obj) return;
  hearth_mesh_free(&obj->mesh);
  free(obj->part_of_tri);
  free(obj->style_of_tri);
  hearth_image_free(&obj->albedo);
  memset(obj, 0, sizeof *obj);
}

static size_t count_at(const shape *s, double h, int *fail) {
  builder cb;
  memset(&cb, 0, sizeof cb);
  cb.count_only = 1;
  if (shape_build(&cb, s, h)) *fail = 1;
  return cb.nt;
}

static void obj_extent(synth_object *obj) {
  double hz = 0, rr = 0;
  for (size_t v = 0; v < obj->mesh.n_vertices; v++) {
    const float *p = obj->mesh.positions + 3 * v;
    double r = hypot(p[0], p[1]);
    if (p[2] > hz) hz = p[2];
    if (r > rr) rr = r;
  }
  obj->height = hz;
  obj->radius = rr;
}

hearth_status synth_object_make(const char *category, uint64_t seed, size_t target_triangles,
                                size_t texture_size, synth_object *obj, hearth_err *err) {
  if (!obj) return hearth_err_set(err, HEARTH_E_ARG, "synth_object_make: obj is NULL");
  memset(obj, 0, sizeof *obj);
  int cat = synth_category_index(category);
  if (cat < 0) {
    char known[512];
    size_t n = 0;
    for (int c = 0; c < SYNTH_N_CATEGORIES && n < sizeof known; c++)
      n += (size_t)snprintf(known + n, sizeof known - n, "%s%s", c ? ", " : "",
                            synth_categories[c].name);
    return hearth_err_set(err, HEARTH_E_ARG,
                          "synth_object_make: unknown category '%s': expected one of %s",
                          category ? category : "(null)", known);
  }
  const synth_category *sc = &synth_categories[cat];
  if (target_triangles < 200 || target_triangles > 5000000)
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "synth_object_make(%s): target_triangles %zu: expected 200..5000000",
                          category, target_triangles);
  if (texture_size < 16 || texture_size > 8192)
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "synth_object_make(%s): texture_size %zu: expected 16..8192", category,
                          texture_size);
  hearth_rng root, r;
  hearth_rng_seed(&root, seed);
  hearth_rng_fork(&root, 0x6f626a00u + (uint64_t)cat, &r);
  shape s;
  shape_draw(&s, sc, &r);

  /* edge length by bisection on log(h) against the counted triangles */
  int fail = 0;
  double lo = log(2e-4), hi = log(0.2), best_h = 0.01;
  size_t best_n = 0;
  double best_err = 1e300;
  for (int it = 0; it < 48 && !fail; it++) {
    double mid = 0.5 * (lo + hi), h = exp(mid);
    size_t n = count_at(&s, h, &fail);
    double e = fabs((double)n - (double)target_triangles);
    if (e < best_err) {
      best_err = e;
      best_h = h;
      best_n = n;
    }
    if (n > target_triangles) lo = mid;
    else hi = mid;
    if (e < 0.02 * (double)target_triangles) break;
  }
  if (fail)
    return hearth_err_set(err, HEARTH_E_NOMEM, "synth_object_make(%s): out of memory", category);
  (void)best_n;

  builder cb;
  memset(&cb, 0, sizeof cb);
  cb.count_only = 1;
  shape_build(&cb, &s, best_h);
  hearth_status st = hearth_mesh_alloc(&obj->mesh, cb.nv, cb.nt, 1, err);
  if (st) return st;
  obj->part_of_tri = malloc(cb.nt ? cb.nt : 1);
  if (!obj->part_of_tri) {
    synth_object_free(obj);
    return hearth_err_set(err, HEARTH_E_NOMEM, "synth_object_make(%s): out of memory", category);
  }
  builder *b = calloc(1, sizeof *b);
  if (!b) {
    synth_object_free(obj);
    return hearth_err_set(err, HEARTH_E_NOMEM, "synth_object_make(%s): out of memory", category);
  }
  b->pos = obj->mesh.positions;
  b->uv = obj->mesh.uvs;
  b->idx = obj->mesh.indices;
  b->part = obj->part_of_tri;
  if (shape_build(b, &s, best_h) || b->overflow || b->nv != cb.nv || b->nt != cb.nt) {
    free(b);
    synth_object_free(obj);
    return hearth_err_set(err, HEARTH_E_NOMEM, "synth_object_make(%s): building the mesh failed",
                          category);
  }
  pack_islands(b);
  /* each triangle's material: the style of the island its first vertex is in */
  obj->style_of_tri = malloc(cb.nt ? cb.nt : 1);
  uint8_t *vstyle = malloc(cb.nv ? cb.nv : 1);
  if (!obj->style_of_tri || !vstyle) {
    free(vstyle);
    free(b);
    synth_object_free(obj);
    return hearth_err_set(err, HEARTH_E_NOMEM, "synth_object_make(%s): out of memory", category);
  }
  memset(vstyle, 0, cb.nv ? cb.nv : 1);
  for (int k = 0; k < b->np; k++)
    for (size_t v = b->patches[k].v0; v < b->patches[k].v1 && v < cb.nv; v++)
      vstyle[v] = (uint8_t)b->patches[k].style;
  for (size_t t = 0; t < cb.nt; t++) obj->style_of_tri[t] = vstyle[obj->mesh.indices[3 * t]];
  free(vstyle);
  /* rest on z = 0 exactly (bumps may dip below the nominal bottom) */
  {
    float zmin = 1e30f;
    for (size_t v = 0; v < cb.nv; v++) zmin = fminf(zmin, obj->mesh.positions[3 * v + 2]);
    if (zmin != 0.0f)
      for (size_t v = 0; v < cb.nv; v++) obj->mesh.positions[3 * v + 2] -= zmin;
  }

  snprintf(obj->category, sizeof obj->category, "%s", sc->name);
  obj->n_parts = b->n_parts;
  for (int k = 0; k < b->n_parts; k++) obj->part_names[k] = b->part_names[k];
  obj_extent(obj);
  switch (sc->fill) {
    case FILL_DRAWN: obj->fill_level = s.d[D_FILL]; break;
    case FILL_DEPTH: obj->fill_level = s.d[D_H] * s.d[D_FILL] / obj->height; break;
    case FILL_ABOVE_BASE:
      obj->fill_level = (s.d[D_T] + s.d[D_H] * s.d[D_FILL]) / obj->height;
      break;
  }

  st = hearth_image_alloc(&obj->albedo, texture_size, texture_size, 3, HEARTH_PIX_U8, err);
  if (st) {
    free(b);
    synth_object_free(obj);
    return st;
  }
  tex_job job = {&s, b, &obj->albedo};
  hearth_parallel_for(texture_size, 0, tex_rows, &job);
  free(b);
  return HEARTH_OK;
}

/* bilinear sample of a U8 image (any channel count) as RGB in [0,1] */
static void sample_rgb(const hearth_image *im, double u, double v, double out[3]) {
  double x = u * (double)im->width - 0.5, y = v * (double)im->height - 0.5;
  double fx = floor(x), fy = floor(y), tx = x - fx, ty = y - fy;
  const uint8_t *d = im->data;
  int ch = im->channels;
  double acc[3] = {0, 0, 0};
  for (int k = 0; k < 4; k++) {
    long xi = (long)fx + (k & 1), yi = (long)fy + (k >> 1);
    if (xi < 0) xi = 0;
    if (yi < 0) yi = 0;
    if (xi >= (long)im->width) xi = (long)im->width - 1;
    if (yi >= (long)im->height) yi = (long)im->height - 1;
    double w = ((k & 1) ? tx : 1 - tx) * ((k >> 1) ? ty : 1 - ty);
    const uint8_t *p = d + ((size_t)yi * im->width + (size_t)xi) * (size_t)ch;
    for (int m = 0; m < 3; m++) acc[m] += w * p[ch >= 3 ? m : 0] / 255.0;
  }
  memcpy(out, acc, sizeof acc);
}

hearth_status synth_object_from_mesh(const hearth_mesh *m, double size_m, const char *category,
                                     size_t texture_size, synth_object *obj, hearth_err *err) {
  if (!obj) return hearth_err_set(err, HEARTH_E_ARG, "synth_object_from_mesh: obj is NULL");
  memset(obj, 0, sizeof *obj);
  if (!m || !m->positions || !m->indices || m->n_triangles == 0)
    return hearth_err_set(err, HEARTH_E_ARG, "synth_object_from_mesh: empty mesh");
  if (!m->uvs)
    return hearth_err_set(err, HEARTH_E_NOT_FOUND,
                          "synth_object_from_mesh: the mesh has no UV coordinates");
  if (!(size_m > 0) || size_m > 100)
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "synth_object_from_mesh: size %g m: expected (0, 100]", size_m);
  if (texture_size < 16 || texture_size > 8192)
    return hearth_err_set(err, HEARTH_E_RANGE,
                          "synth_object_from_mesh: texture_size %zu: expected 16..8192",
                          texture_size);
  hearth_status st = hearth_mesh_validate(m, "synth_object_from_mesh", err);
  if (st) return st;
  const hearth_image *tx = &m->texture;
  if (tx->data && (tx->type != HEARTH_PIX_U8 || tx->channels < 1 || tx->channels > 4 ||
                   !tx->width || !tx->height))
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                          "synth_object_from_mesh: texture must be 8-bit with 1-4 channels");
  st = hearth_mesh_copy(m, &obj->mesh, err);
  if (st) return st;
  hearth_image_free(&obj->mesh.texture);
  double lo[3], hi[3];
  hearth_mesh_bounds(&obj->mesh, lo, hi);
  double ext = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  if (!(ext > 0)) {
    synth_object_free(obj);
    return hearth_err_set(err, HEARTH_E_RANGE, "synth_object_from_mesh: the mesh has no extent");
  }
  double sc = size_m / ext;
  double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double t[3] = {-0.5 * (lo[0] + hi[0]) * sc, -0.5 * (lo[1] + hi[1]) * sc, -lo[2] * sc};
  hearth_mesh_transform(&obj->mesh, sc, I, t);
  obj->part_of_tri = calloc(m->n_triangles, 1);
  if (!obj->part_of_tri) {
    synth_object_free(obj);
    return hearth_err_set(err, HEARTH_E_NOMEM, "synth_object_from_mesh: out of memory");
  }
  obj->n_parts = 1;
  obj->part_names[0] = "body";
  snprintf(obj->category, sizeof obj->category, "%s", category ? category : "object");
  obj_extent(obj);
  const synth_category *kind = synth_category_find(category);
  obj->fill_level = kind ? kind->wrapped_fill : 0;
  st = hearth_image_alloc(&obj->albedo, texture_size, texture_size, 3, HEARTH_PIX_U8, err);
  if (st) {
    synth_object_free(obj);
    return st;
  }
  uint8_t *px = obj->albedo.data;
  for (size_t row = 0; row < texture_size; row++)
    for (size_t col = 0; col < texture_size; col++) {
      double c[3] = {0.8, 0.8, 0.8};
      if (tx->data)
        sample_rgb(tx, ((double)col + 0.5) / (double)texture_size,
                   ((double)row + 0.5) / (double)texture_size, c);
      for (int k = 0; k < 3; k++)
        px[3 * (row * texture_size + col) + k] = (uint8_t)lround(fmin(fmax(c[k], 0), 1) * 255);
    }
  return HEARTH_OK;
}
