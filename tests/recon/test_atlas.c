/* The UV atlas (hearth_mesh_atlas) on closed-form meshes and on the TSDF
 * mesh of a small virtual-rig release. What is asserted is measured here,
 * independently of the atlas code: each chart's Euler characteristic and
 * boundary from the output's own indices, UV triangle overlaps by
 * rasterising all UV triangles at 512 x 512 (texel centres strictly inside
 * two triangles), the gutter from the border and between charts (the least
 * distance between two charts' boundary edges), orientation, the L2
 * stretch (Sander et al. 2001) recomputed from the UVs, one UV island per
 * chart, the GLB through the Khronos validator and hearth's reader.
 * Packing bounds in closed form: 64 equal squares fill an 8 x 8 grid, (1 -
 * 9 g)^2 of the square at gutter g, at three texture sizes and gutters;
 * 64 parallelograms beat 2/3, the most any packing of their boxes holds;
 * 5 nested rings beat the most that one run of cells per row can hold.
 *
 * With arguments GLB_IN [GLB_OUT] it only runs the atlas on that mesh and
 * prints its figures (bench use). */
#include <float.h>
#include <sys/wait.h>
#include "hearth/recon_geom.h"
#include "../test_util.h"

/* ---- closed meshes, welded by exact positions ---------------------------- */
typedef struct soup {
  float *p; /* 9 per triangle */
  size_t n, cap;
} soup;

static void soup_tri(soup *s, const double a[3], const double b[3], const double c[3]) {
  if (s->n == s->cap) {
    s->cap = s->cap ? 2 * s->cap : 256;
    s->p = realloc(s->p, s->cap * 9 * sizeof *s->p);
  }
  const double *v[3] = {a, b, c};
  for (int j = 0; j < 3; j++)
    for (int k = 0; k < 3; k++) s->p[9 * s->n + 3 * j + k] = (float)v[j][k];
  s->n++;
}

static const float *g_sort_p;
static int cmp_corner(const void *pa, const void *pb) {
  const float *a = g_sort_p + 3 * *(const uint32_t *)pa, *b = g_sort_p + 3 * *(const uint32_t *)pb;
  for (int k = 0; k < 3; k++)
    if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
  return 0;
}

/* the soup as an indexed mesh, corners at equal positions joined */
static void soup_weld(soup *s, hearth_mesh *m) {
  hearth_err e = {0};
  size_t nc = 3 * s->n;
  uint32_t *ord = malloc(nc * sizeof *ord), *id = malloc(nc * sizeof *id);
  for (size_t i = 0; i < nc; i++) ord[i] = (uint32_t)i;
  g_sort_p = s->p;
  qsort(ord, nc, sizeof *ord, cmp_corner);
  size_t nv = 0;
  for (size_t i = 0; i < nc; i++) {
    if (i == 0 || cmp_corner(&ord[i - 1], &ord[i]) != 0) nv++;
    id[ord[i]] = (uint32_t)(nv - 1);
  }
  CHECK_OK(hearth_mesh_alloc(m, nv, s->n, 0, &e), &e);
  for (size_t i = 0; i < nc; i++) {
    m->indices[i] = id[i];
    memcpy(m->positions + 3 * (size_t)id[i], s->p + 3 * i, 3 * sizeof(float));
  }
  free(ord), free(id), free(s->p);
  memset(s, 0, sizeof *s);
}

/* the cube [-h, h]^3, each face a k x k grid of squares, outward faces */
static void make_cube(hearth_mesh *m, int k, double h) {
  soup s = {0};
  for (int ax = 0; ax < 3; ax++)
    for (int sg = -1; sg <= 1; sg += 2) {
      int a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
      for (int i = 0; i < k; i++)
        for (int j = 0; j < k; j++) {
          double q[4][3];
          const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; c++) {
            q[c][ax] = sg * h;
            q[c][a1] = -h + 2 * h * (i + di[c]) / k;
            q[c][a2] = -h + 2 * h * (j + dj[c]) / k;
          }
          /* a1 x a2 = ax: counter-clockwise seen from +ax */
          if (sg > 0) {
            soup_tri(&s, q[0], q[1], q[2]);
            soup_tri(&s, q[0], q[2], q[3]);
          } else {
            soup_tri(&s, q[0], q[2], q[1]);
            soup_tri(&s, q[0], q[3], q[2]);
          }
        }
    }
  soup_weld(&s, m);
}

/* a surface of revolution point: torus (R, r) or sphere (R = 0) */
static void rev_point(double R, double r, double th, double ph, double o[3]) {
  double rho = R + r * sin(th);
  o[0] = rho * cos(ph);
  o[1] = rho * sin(ph);
  o[2] = -r * cos(th);
}

/* sphere (R = 0, th in [0, pi]) or torus (th in [0, 2 pi]) on a grid of
 * nu x nv quads, tilted about x by tilt radians */
static void make_rev(hearth_mesh *m, double R, double r, int nu, int nv, double tilt) {
  soup s = {0};
  double thmax = R > 0 ? 2 * M_PI : M_PI;
  for (int i = 0; i < nv; i++)
    for (int j = 0; j < nu; j++) {
      double q[4][3];
      const int di[4] = {0, 0, 1, 1}, dj[4] = {0, 1, 1, 0};
      for (int c = 0; c < 4; c++) {
        int ii = i + di[c], jj = (j + dj[c]) % nu;
        if (R == 0 && (ii == 0 || ii == nv)) jj = 0; /* one pole vertex */
        if (R > 0) ii %= nv;
        rev_point(R, r, thmax * ii / nv, 2 * M_PI * jj / nu, q[c]);
        double y = q[c][1], z = q[c][2];
        q[c][1] = cos(tilt) * y - sin(tilt) * z;
        q[c][2] = sin(tilt) * y + cos(tilt) * z;
      }
      if (!(R == 0 && i == 0)) soup_tri(&s, q[0], q[1], q[2]);
      if (!(R == 0 && i == nv - 1)) soup_tri(&s, q[0], q[2], q[3]);
    }
  soup_weld(&s, m);
}

/* closed cylinder of radius r, height h, n segments, rings bands; caps are
 * fans around a centre vertex */
static void make_cylinder(hearth_mesh *m, double r, double h, int n, int rings) {
  soup s = {0};
  for (int j = 0; j < n; j++) {
    double a0 = 2 * M_PI * j / n, a1 = 2 * M_PI * ((j + 1) % n) / n;
    for (int i = 0; i < rings; i++) {
      double z0 = h * i / rings, z1 = h * (i + 1) / rings;
      double p00[3] = {r * cos(a0), r * sin(a0), z0}, p10[3] = {r * cos(a1), r * sin(a1), z0};
      double p01[3] = {r * cos(a0), r * sin(a0), z1}, p11[3] = {r * cos(a1), r * sin(a1), z1};
      soup_tri(&s, p00, p10, p11);
      soup_tri(&s, p00, p11, p01);
    }
    double c0[3] = {0, 0, 0}, c1[3] = {0, 0, h};
    double b0[3] = {r * cos(a0), r * sin(a0), 0}, b1[3] = {r * cos(a1), r * sin(a1), 0};
    double t0[3] = {r * cos(a0), r * sin(a0), h}, t1[3] = {r * cos(a1), r * sin(a1), h};
    soup_tri(&s, c0, b1, b0);
    soup_tri(&s, c1, t0, t1);
  }
  soup_weld(&s, m);
}

/* ---- the independent checks ---------------------------------------------- */
typedef struct edge_key {
  uint32_t a, b, chart;
} edge_key;
static int cmp_edge(const void *pa, const void *pb) {
  const edge_key *x = pa, *y = pb;
  if (x->chart != y->chart) return x->chart < y->chart ? -1 : 1;
  if (x->a != y->a) return x->a < y->a ? -1 : 1;
  return x->b < y->b ? -1 : x->b > y->b;
}

typedef struct atlas_check {
  size_t n_charts, non_discs, overlaps, outside, folded;
  double stretch, stretch_max, efficiency;
  double gap; /* least UV distance between two charts' triangles */
} atlas_check;

/* distance from p to segment ab */
static double point_seg(const double p[2], const double a[2], const double b[2]) {
  double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  double ex = a[0] + t * dx - p[0], ey = a[1] + t * dy - p[1];
  return sqrt(ex * ex + ey * ey);
}

static double cross2(const double o[2], const double a[2], const double b[2]) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/* distance between segments ab and cd (0 when they meet) */
static double seg_seg(const double a[2], const double b[2], const double c[2], const double d[2]) {
  double o1 = cross2(a, b, c), o2 = cross2(a, b, d), o3 = cross2(c, d, a), o4 = cross2(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
    return 0;
  return fmin(fmin(point_seg(a, c, d), point_seg(b, c, d)),
              fmin(point_seg(c, a, b), point_seg(d, a, b)));
}

/* The least distance between boundary edges of different charts (seg: 3
 * per edge, vertex, vertex, chart), over pairs closer than reach: edges
 * are binned on a grid by their boxes grown by reach. Charts that do not
 * overlap (checked apart) are that far apart. Returns reach when no pair
 * is closer. */
static double chart_gap(const hearth_mesh *out, const uint32_t *seg, size_t ns, double reach) {
  const int B = 64;
  size_t *cnt = calloc((size_t)B * B + 1, sizeof *cnt);
  double gap = reach;
  for (int pass = 0; pass < 2; pass++) {
    size_t *fill = pass ? calloc((size_t)B * B, sizeof *fill) : NULL;
    uint32_t *bin = pass ? malloc((cnt[(size_t)B * B] + 1) * sizeof *bin) : NULL;
    for (size_t i = 0; i < ns; i++) {
      const float *a = out->uvs + 2 * (size_t)seg[3 * i],
                  *b = out->uvs + 2 * (size_t)seg[3 * i + 1];
      int x0 = (int)floor((fmin(a[0], b[0]) - reach) * B),
          x1 = (int)floor((fmax(a[0], b[0]) + reach) * B);
      int y0 = (int)floor((fmin(a[1], b[1]) - reach) * B),
          y1 = (int)floor((fmax(a[1], b[1]) + reach) * B);
      for (int y = y0 < 0 ? 0 : y0; y <= y1 && y < B; y++)
        for (int x = x0 < 0 ? 0 : x0; x <= x1 && x < B; x++) {
          size_t c = (size_t)y * B + x;
          if (pass) bin[cnt[c] + fill[c]++] = (uint32_t)i;
          else cnt[c + 1]++;
        }
    }
    if (!pass) {
      for (size_t c = 0; c < (size_t)B * B; c++) cnt[c + 1] += cnt[c];
      continue;
    }
    for (size_t c = 0; c < (size_t)B * B; c++)
      for (size_t i = cnt[c]; i < cnt[c + 1]; i++)
        for (size_t j = i + 1; j < cnt[c + 1]; j++) {
          const uint32_t *p = seg + 3 * (size_t)bin[i], *q = seg + 3 * (size_t)bin[j];
          if (p[2] == q[2]) continue;
          double A[2], Bq[2], C[2], D[2];
          for (int k = 0; k < 2; k++) {
            A[k] = out->uvs[2 * (size_t)p[0] + k], Bq[k] = out->uvs[2 * (size_t)p[1] + k];
            C[k] = out->uvs[2 * (size_t)q[0] + k], D[k] = out->uvs[2 * (size_t)q[1] + k];
          }
          gap = fmin(gap, seg_seg(A, Bq, C, D));
        }
    free(fill), free(bin);
  }
  free(cnt);
  return gap;
}

/* every check on out (from in, with chart_of_tri); gutter and unit (one
 * texel) in UV units */
static void check_atlas(const char *name, const hearth_mesh *in, const hearth_mesh *out,
                        const uint32_t *chart, size_t n_charts, double gutter, double unit,
                        atlas_check *r) {
  memset(r, 0, sizeof *r);
  r->n_charts = n_charts;
  CHECK_MSG(out->n_triangles == in->n_triangles, "%s: %zu of %zu triangles", name, out->n_triangles,
            in->n_triangles);
  CHECK(out->uvs != NULL);
  if (out->n_triangles != in->n_triangles || !out->uvs) return;
  const size_t nt = in->n_triangles;
  /* same surface: each corner at the input's position */
  size_t moved = 0;
  for (size_t c = 0; c < 3 * nt; c++)
    moved += memcmp(out->positions + 3 * (size_t)out->indices[c],
                    in->positions + 3 * (size_t)in->indices[c], 3 * sizeof(float)) != 0;
  CHECK_MSG(moved == 0, "%s: %zu corners moved", name, moved);
  /* every chart a disc: V - E + F = 1 and a boundary, from out's indices */
  size_t *nf = calloc(n_charts, sizeof *nf), *ne = calloc(n_charts, sizeof *ne),
         *nb = calloc(n_charts, sizeof *nb), *nvc = calloc(n_charts, sizeof *nvc);
  uint32_t *vchart = malloc(out->n_vertices * sizeof *vchart);
  for (size_t v = 0; v < out->n_vertices; v++) vchart[v] = UINT32_MAX;
  edge_key *ek = malloc(3 * nt * sizeof *ek);
  size_t shared_vertices = 0;
  for (size_t t = 0; t < nt; t++) {
    CHECK(chart[t] < n_charts);
    nf[chart[t]]++;
    for (int j = 0; j < 3; j++) {
      uint32_t a = out->indices[3 * t + j], b = out->indices[3 * t + (j + 1) % 3];
      ek[3 * t + j] = (edge_key){a < b ? a : b, a < b ? b : a, chart[t]};
      if (vchart[a] == UINT32_MAX) vchart[a] = chart[t], nvc[chart[t]]++;
      else if (vchart[a] != chart[t]) shared_vertices++;
    }
  }
  CHECK_MSG(shared_vertices == 0, "%s: %zu corners use a vertex of another chart", name,
            shared_vertices);
  qsort(ek, 3 * nt, sizeof *ek, cmp_edge);
  uint32_t *seg = malloc(3 * 3 * nt * sizeof *seg);
  size_t ns = 0;
  for (size_t i = 0; i < 3 * nt;) {
    size_t j = i + 1;
    while (j < 3 * nt && cmp_edge(&ek[i], &ek[j]) == 0) j++;
    ne[ek[i].chart]++;
    if (j - i == 1) {
      nb[ek[i].chart]++;
      seg[3 * ns] = ek[i].a, seg[3 * ns + 1] = ek[i].b, seg[3 * ns + 2] = ek[i].chart;
      ns++;
    }
    i = j;
  }
  /* the gutter between charts: boundary edges of two charts no closer than
     it (with no overlap, checked below, the triangles are as far apart) */
  r->gap = chart_gap(out, seg, ns, 2 * gutter + 1e-3);
  free(seg);
  for (size_t k = 0; k < n_charts; k++) {
    long chi = (long)nvc[k] - (long)ne[k] + (long)nf[k];
    if (chi != 1 || nb[k] == 0) r->non_discs++;
  }
  free(nf), free(ne), free(nb), free(nvc), free(vchart), free(ek);
  /* UVs inside the gutter; orientation; L2 stretch over the common scale */
  double a3 = 0, auv = 0;
  for (size_t v = 0; v < out->n_vertices; v++)
    for (int k = 0; k < 2; k++) {
      float u = out->uvs[2 * v + k];
      if (!(u >= gutter - 1e-6 && u <= 1 - gutter + 1e-6)) r->outside++;
    }
  double *jac = malloc(nt * 4 * sizeof *jac); /* a, c, b, area3 per triangle */
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *ix = out->indices + 3 * t;
    double q[3][3], s[3], w[3];
    for (int j = 0; j < 3; j++) {
      for (int k = 0; k < 3; k++) q[j][k] = out->positions[3 * (size_t)ix[j] + k];
      s[j] = out->uvs[2 * (size_t)ix[j]], w[j] = out->uvs[2 * (size_t)ix[j] + 1];
    }
    double e1[3], e2[3], n[3];
    for (int k = 0; k < 3; k++) e1[k] = q[1][k] - q[0][k], e2[k] = q[2][k] - q[0][k];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2],
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double A3 = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double Au = 0.5 * ((s[1] - s[0]) * (w[2] - w[0]) - (s[2] - s[0]) * (w[1] - w[0]));
    jac[4 * t + 3] = 0;
    if (!(A3 > 1e-14)) continue;
    if (!(Au > 0)) {
      r->folded++;
      continue;
    }
    double Ss[3], St[3];
    for (int k = 0; k < 3; k++) {
      Ss[k] =
          (q[0][k] * (w[1] - w[2]) + q[1][k] * (w[2] - w[0]) + q[2][k] * (w[0] - w[1])) / (2 * Au);
      St[k] =
          (q[0][k] * (s[2] - s[1]) + q[1][k] * (s[0] - s[2]) + q[2][k] * (s[1] - s[0])) / (2 * Au);
    }
    jac[4 * t] = Ss[0] * Ss[0] + Ss[1] * Ss[1] + Ss[2] * Ss[2];
    jac[4 * t + 1] = St[0] * St[0] + St[1] * St[1] + St[2] * St[2];
    jac[4 * t + 3] = A3;
    a3 += A3, auv += Au;
  }
  double sum = 0;
  for (size_t t = 0; t < nt; t++) {
    double A3 = jac[4 * t + 3];
    if (!(A3 > 0)) continue;
    /* scaled so the whole map has UV area = surface area */
    double l2sq = 0.5 * (jac[4 * t] + jac[4 * t + 1]) * auv / a3;
    sum += A3 * l2sq;
    if (sqrt(l2sq) > r->stretch_max) r->stretch_max = sqrt(l2sq);
  }
  free(jac);
  r->stretch = a3 > 0 ? sqrt(sum / a3) : 0;
  r->efficiency = auv;
  /* overlaps at 512 x 512: texel centres strictly inside two UV triangles */
  const int R = 512;
  uint8_t *cov = calloc((size_t)R * R, 1);
  uint32_t *who = getenv("ATLAS_DEBUG") ? calloc((size_t)R * R, sizeof *who) : NULL;
  for (size_t t = 0; t < nt; t++) {
    double P[3][2];
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 2; k++) P[j][k] = out->uvs[2 * (size_t)out->indices[3 * t + j] + k] * R;
    double area =
        (P[1][0] - P[0][0]) * (P[2][1] - P[0][1]) - (P[2][0] - P[0][0]) * (P[1][1] - P[0][1]);
    double sg = area > 0 ? 1 : -1;
    int x0 = (int)floor(fmin(P[0][0], fmin(P[1][0], P[2][0]))),
        x1 = (int)ceil(fmax(P[0][0], fmax(P[1][0], P[2][0])));
    int y0 = (int)floor(fmin(P[0][1], fmin(P[1][1], P[2][1]))),
        y1 = (int)ceil(fmax(P[0][1], fmax(P[1][1], P[2][1])));
    for (int y = y0 < 0 ? 0 : y0; y <= y1 && y < R; y++)
      for (int x = x0 < 0 ? 0 : x0; x <= x1 && x < R; x++) {
        double px = x + 0.5, py = y + 0.5;
        int inside = 1;
        for (int j = 0; j < 3 && inside; j++) {
          const double *a = P[j], *b = P[(j + 1) % 3];
          inside = sg * ((b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])) > 0;
        }
        if (inside && who && cov[(size_t)y * R + x])
          fprintf(stderr, "overlap at %d %d: triangles %u (chart %u) and %zu (chart %u)\n", x, y,
                  who[(size_t)y * R + x], chart[who[(size_t)y * R + x]], t, chart[t]);
        if (inside && who) who[(size_t)y * R + x] = (uint32_t)t;
        if (inside && cov[(size_t)y * R + x]++ == 1) r->overlaps++;
      }
  }
  free(cov), free(who);
  /* one UV island per chart */
  uint32_t *isl = malloc(nt * sizeof *isl), n_isl = 0;
  hearth_err e = {0};
  CHECK_OK(hearth_uv_islands(out, isl, &n_isl, &e), &e);
  CHECK_MSG(n_isl == n_charts, "%s: %u UV islands, %zu charts", name, n_isl, n_charts);
  free(isl);
  printf(
      "%s: %zu triangles, %zu charts, L2 stretch %.4f (max %.4f), packing %.3f; "
      "%zu non-disc charts, %zu overlapping texels, %zu UVs outside, %zu folded; "
      "least gap %.2f texels of %.0f\n",
      name, nt, n_charts, r->stretch, r->stretch_max, r->efficiency, r->non_discs, r->overlaps,
      r->outside, r->folded, r->gap / unit, gutter / unit);
  CHECK_MSG(r->non_discs == 0, "%s: %zu charts are no disc", name, r->non_discs);
  CHECK_MSG(r->overlaps == 0, "%s: %zu texels under two UV triangles", name, r->overlaps);
  CHECK_MSG(r->outside == 0, "%s: %zu UV coordinates in the gutter or outside", name, r->outside);
  CHECK_MSG(r->folded == 0, "%s: %zu folded UV triangles", name, r->folded);
  CHECK_MSG(r->gap >= gutter * (1 - 1e-3), "%s: two charts %.3f texels apart, gutter %.3f", name,
            r->gap / unit, gutter / unit);
}

/* the atlas of m with the defaults, or texture_size and gutter_texels
 * when tex > 0 */
static void run_case_at(const char *name, const hearth_mesh *m, int tex, double gutter,
                        atlas_check *r, hearth_atlas_stats *st, hearth_mesh *keep) {
  hearth_err e = {0};
  hearth_atlas_opts o;
  hearth_atlas_opts_default(&o);
  if (tex > 0) o.texture_size = tex, o.gutter_texels = gutter;
  hearth_mesh out, again;
  uint32_t *chart = malloc(m->n_triangles * sizeof *chart);
  CHECK_OK(hearth_mesh_atlas(m, &o, &out, chart, st, &e), &e);
  if (!out.uvs) {
    free(chart);
    return;
  }
  check_atlas(name, m, &out, chart, st->n_charts, o.gutter_texels / o.texture_size,
              1.0 / o.texture_size, r);
  /* the worst chart lies between the mesh's stretch and the worst triangle's */
  CHECK_MSG(st->stretch_l2_chart_max >= st->stretch_l2 * (1 - 1e-9) &&
                st->stretch_l2_chart_max <= st->stretch_l2_max * (1 + 1e-9),
            "%s: chart stretch %g outside [%g, %g]", name, st->stretch_l2_chart_max, st->stretch_l2,
            st->stretch_l2_max);
  /* the library's own figures agree with the ones measured here */
  CHECK_NEAR(st->stretch_l2, r->stretch, 1e-3 * r->stretch);
  CHECK_NEAR(st->packing_efficiency, r->efficiency, 1e-4);
  printf("  (library: stretch %.4f max %.4f, area %.4f, angle %.4f, %zu splits, CG <= %d)\n",
         st->stretch_l2, st->stretch_l2_max, st->area_distortion, st->angle_distortion,
         st->n_splits, st->cg_iterations_max);
  /* deterministic */
  hearth_atlas_stats st2;
  CHECK_OK(hearth_mesh_atlas(m, &o, &again, NULL, &st2, &e), &e);
  CHECK(again.n_vertices == out.n_vertices &&
        memcmp(again.uvs, out.uvs, 2 * out.n_vertices * sizeof(float)) == 0 &&
        memcmp(again.indices, out.indices, 3 * out.n_triangles * sizeof(uint32_t)) == 0);
  hearth_mesh_free(&again);
  free(chart);
  if (keep) *keep = out;
  else hearth_mesh_free(&out);
}

static void run_case(const char *name, const hearth_mesh *m, atlas_check *r, hearth_atlas_stats *st,
                     hearth_mesh *keep) {
  run_case_at(name, m, 0, 0, r, st, keep);
}

static void test_closed_forms(void) {
  hearth_mesh m;
  atlas_check r;
  hearth_atlas_stats st;
  make_cube(&m, 4, 0.05);
  run_case("cube", &m, &r, &st, NULL);
  CHECK_MSG(st.n_charts == 6, "cube: %zu charts", st.n_charts);
  CHECK_NEAR(r.stretch, 1, 1e-5);
  CHECK_NEAR(r.stretch_max, 1, 1e-5);
  CHECK_NEAR(st.stretch_l2_chart_max, 1, 1e-5);
  CHECK_NEAR(st.area_distortion, 0, 1e-5);
  CHECK_NEAR(st.angle_distortion, 0, 1e-5);
  /* six equal squares in shelves of the unit square: at least 6/9 of it
     less the gutters */
  CHECK_MSG(r.efficiency > 0.6, "cube: packing %g", r.efficiency);
  hearth_mesh_free(&m);

  make_rev(&m, 0, 0.05, 32, 16, 0.3);
  run_case("sphere", &m, &r, &st, NULL);
  CHECK_MSG(r.stretch < 1.15 && r.stretch_max < 2, "sphere: stretch %g max %g", r.stretch,
            r.stretch_max);
  CHECK_MSG(r.efficiency > 0.4, "sphere: packing %g", r.efficiency);
  hearth_mesh_free(&m);

  make_cylinder(&m, 0.03, 0.1, 32, 8);
  run_case("cylinder", &m, &r, &st, NULL);
  CHECK_MSG(r.stretch < 1.15, "cylinder: stretch %g", r.stretch);
  hearth_mesh_free(&m);

  /* a torus: the normal clusters include bands around the hole, which are
     no discs and must be cut */
  make_rev(&m, 0.05, 0.02, 48, 24, 0.2);
  run_case("torus", &m, &r, &st, NULL);
  CHECK_MSG(st.n_splits > 0, "torus: no chart was cut");
  CHECK_MSG(r.stretch < 1.25, "torus: stretch %g", r.stretch);
  hearth_mesh_free(&m);

  /* errors */
  hearth_err e = {0};
  hearth_mesh empty = {0}, out;
  CHECK(hearth_mesh_atlas(&empty, NULL, &out, NULL, NULL, &e) == HEARTH_E_ARG);
}

static int run_validator(const char *path) {
  const char *src = getenv("HEARTH_SOURCE_DIR");
  char cmd[4096];
  snprintf(cmd, sizeof cmd, "node '%s/tests/mesh/validate_glb.js' '%s'", src ? src : ".", path);
  int rc = system(cmd);
  return rc == -1 || !WIFEXITED(rc) ? -1 : WEXITSTATUS(rc);
}

/* n x n disjoint tiles in the plane z = 0, each a square of side a or,
 * with slant, a parallelogram (0,0) (a,0) (2a,a) (a,a); two triangles */
static void make_tiles(hearth_mesh *m, int n, double a, int slant) {
  soup s = {0};
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      double x = 3 * a * i, y = 3 * a * j;
      double sh = slant ? a : 0;
      double p0[3] = {x, y, 0}, p1[3] = {x + a, y, 0}, p2[3] = {x + a + sh, y + a, 0},
             p3[3] = {x + sh, y + a, 0};
      soup_tri(&s, p0, p1, p2);
      soup_tri(&s, p0, p2, p3);
    }
  soup_weld(&s, m);
}

/* the least bounding box, over turns of 0.005 degree, of the n points p
 * (2 each) */
static double least_box(const double *p, int n) {
  double best = INFINITY;
  for (int t = 0; t < 18000; t++) {
    double th = M_PI * t / 36000, c = cos(th), sn = sin(th);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < n; k++) {
      double u = c * p[2 * k] - sn * p[2 * k + 1], v = sn * p[2 * k] + c * p[2 * k + 1];
      lo[0] = fmin(lo[0], u), hi[0] = fmax(hi[0], u), lo[1] = fmin(lo[1], v),
      hi[1] = fmax(hi[1], v);
    }
    best = fmin(best, (hi[0] - lo[0]) * (hi[1] - lo[1]));
  }
  return best;
}

/* packing bounds on tiles: 64 equal squares fill an 8 x 8 grid with 9
 * gutters a side, (1 - 9 g)^2 of the square */
static void test_tiles(void) {
  hearth_mesh m;
  atlas_check r;
  hearth_atlas_stats st;
  const struct {
    int tex;
    double gutter;
  } at[] = {{1024, 4}, {256, 2}, {512, 6.5}};
  for (size_t i = 0; i < sizeof at / sizeof at[0]; i++) {
    char name[64];
    snprintf(name, sizeof name, "64 squares at %d, gutter %g", at[i].tex, at[i].gutter);
    make_tiles(&m, 8, 0.01, 0);
    run_case_at(name, &m, at[i].tex, at[i].gutter, &r, &st, NULL);
    double g = at[i].gutter / at[i].tex, bound = (1 - 9 * g) * (1 - 9 * g);
    CHECK_MSG(st.n_charts == 64, "%s: %zu charts", name, st.n_charts);
    CHECK_MSG(r.efficiency >= bound - 1e-4, "%s: packing %g, 8 x 8 gives %g", name, r.efficiency,
              bound);
    hearth_mesh_free(&m);
  }
  /* parallelograms (sides a and a sqrt 2 at 45 degrees): their least box
     holds 2/3 of them (1.5 a^2, along the long sides; measured here too),
     so boxes alone pack at most that; packed by shape they interlock */
  const double P[8] = {0, 0, 1, 0, 2, 1, 1, 1};
  double box_eff = 1 / least_box(P, 4);
  make_tiles(&m, 8, 0.01, 1);
  run_case("64 parallelograms", &m, &r, &st, NULL);
  CHECK_NEAR(box_eff, 2.0 / 3, 1e-6);
  CHECK_MSG(st.n_charts == 64, "parallelograms: %zu charts", st.n_charts);
  CHECK_MSG(r.efficiency > box_eff, "parallelograms: packing %g, boxes alone <= %g", r.efficiency,
            box_eff);
  hearth_mesh_free(&m);
}

/* Nested rings in the plane z = 0: ring k the annulus sector of radii
 * [rad[2k], rad[2k+1]] over 350 degrees (a disc, cut by a 10-degree
 * slit), nu segments along, two across; rings 3 units apart */
static void make_rings(soup *s, const double *rad, int n, int nu, double unit) {
  for (int k = 0; k < n; k++) {
    double ox = 3 * unit * k, r0 = unit * rad[2 * k], r1 = unit * rad[2 * k + 1];
    for (int i = 0; i < nu; i++)
      for (int j = 0; j < 2; j++) {
        double q[4][3];
        for (int c = 0; c < 4; c++) {
          double th = (M_PI / 180) * (95 + 350.0 * (i + (c == 1 || c == 2)) / nu);
          double r = r0 + (r1 - r0) * (j + (c >= 2)) / 2;
          q[c][0] = ox + r * cos(th), q[c][1] = r * sin(th), q[c][2] = 0;
        }
        soup_tri(s, q[0], q[1], q[2]);
        soup_tri(s, q[0], q[2], q[3]);
      }
  }
}

/* The area of the triangles p (9 each, z ignored) turned by th and filled
 * row by row: the integral over lines of constant y of the span from the
 * first to the last point the triangles hold on that line, by the
 * midpoint rule over n_lines. */
static double row_hull_area(const float *p, size_t nt, double th, int n_lines) {
  const double c = cos(th), sn = sin(th);
  double lo = INFINITY, hi = -INFINITY;
  for (size_t i = 0; i < 3 * nt; i++) {
    double y = sn * p[3 * i] + c * p[3 * i + 1];
    lo = fmin(lo, y), hi = fmax(hi, y);
  }
  const double dy = (hi - lo) / n_lines;
  double *x0 = malloc(n_lines * sizeof *x0), *x1 = malloc(n_lines * sizeof *x1);
  for (int l = 0; l < n_lines; l++) x0[l] = INFINITY, x1[l] = -INFINITY;
  for (size_t t = 0; t < nt; t++) {
    double v[3][2], ya = INFINITY, yb = -INFINITY;
    for (int j = 0; j < 3; j++) {
      const float *q = p + 9 * t + 3 * j;
      v[j][0] = c * q[0] - sn * q[1], v[j][1] = sn * q[0] + c * q[1];
      ya = fmin(ya, v[j][1]), yb = fmax(yb, v[j][1]);
    }
    int la = (int)ceil((ya - lo) / dy - 0.5), lb = (int)floor((yb - lo) / dy - 0.5);
    for (int l = la < 0 ? 0 : la; l <= lb && l < n_lines; l++) {
      double y = lo + (l + 0.5) * dy;
      for (int e = 0; e < 3; e++) {
        const double *P = v[e], *Q = v[(e + 1) % 3];
        if ((P[1] - y) * (Q[1] - y) > 0 || P[1] == Q[1]) continue;
        double x = P[0] + (y - P[1]) * (Q[0] - P[0]) / (Q[1] - P[1]);
        x0[l] = fmin(x0[l], x), x1[l] = fmax(x1[l], x);
      }
    }
  }
  double sum = 0;
  for (int l = 0; l < n_lines; l++)
    if (x0[l] <= x1[l]) sum += (x1[l] - x0[l]) * dy;
  free(x0), free(x1);
  return sum;
}

/* Packing bound on nested rings: a packing that keeps one run of cells
 * per row fills at least each chart's row hull in the turn it is packed
 * at, so it holds at most the rings' area over the sum of their least row
 * hulls (over turns at every degree; 0.267 here). Each ring fits the
 * hole of the one before with a radial slack of about 12 gutters, so the
 * nest packed alone gives the rings' area over (2 R)^2 (0.420) less the
 * gutters;
 * packing that uses the holes must beat the first and reach 0.9 of the
 * second. */
static void test_rings(void) {
  const double rad[] = {0.90, 1.00, 0.70, 0.80, 0.50, 0.60, 0.30, 0.40, 0.10, 0.20};
  const int n = 5, nu = 96;
  double area = 0, hull = 0;
  for (int k = 0; k < n; k++) {
    soup s = {0};
    make_rings(&s, rad + 2 * k, 1, nu, 1.0);
    for (size_t t = 0; t < s.n; t++) {
      const float *v = s.p + 9 * t;
      area += 0.5 * fabs((v[3] - v[0]) * (v[7] - v[1]) - (v[6] - v[0]) * (v[4] - v[1]));
    }
    double least = INFINITY;
    for (int deg = 0; deg < 180; deg++)
      least = fmin(least, row_hull_area(s.p, s.n, M_PI * deg / 180, 2000));
    hull += least;
    free(s.p);
  }
  const double run_bound = area / hull, nest = area / 4;
  soup s = {0};
  make_rings(&s, rad, n, nu, 0.05);
  hearth_mesh m;
  soup_weld(&s, &m);
  atlas_check r;
  hearth_atlas_stats st;
  run_case_at("5 nested rings", &m, 1024, 4, &r, &st, NULL);
  printf("  rings: packing %.3f, one run per row holds <= %.3f, the nest alone %.3f\n",
         r.efficiency, run_bound, nest);
  CHECK_MSG(st.n_charts == (size_t)n, "rings: %zu charts", st.n_charts);
  CHECK_MSG(r.efficiency > run_bound, "rings: packing %g, one run per row holds <= %g",
            r.efficiency, run_bound);
  CHECK_MSG(r.efficiency >= 0.9 * nest, "rings: packing %g, the nest gives %g", r.efficiency, nest);
  hearth_mesh_free(&m);
}

/* the atlas of a fused mesh, written as GLB, validated and read back */
static void atlas_glb(const char *name, const hearth_mesh *m, const char *path) {
  hearth_err e = {0};
  atlas_check r;
  hearth_atlas_stats st;
  hearth_mesh out = {0};
  run_case(name, m, &r, &st, &out);
  if (!out.uvs) return;
  CHECK_OK(hearth_glb_write(path, &out, &e), &e);
  int rc = run_validator(path);
  CHECK_MSG(rc == 0, "%s: validator exit status %d", path, rc);
  hearth_glb_read_opts ro;
  hearth_glb_read_opts_default(&ro);
  ro.require_uvs = 1;
  hearth_mesh back;
  CHECK_OK(hearth_glb_read(path, &ro, &back, &e), &e);
  CHECK(back.n_triangles == out.n_triangles && back.uvs != NULL);
  if (back.uvs && back.n_vertices == out.n_vertices)
    CHECK(memcmp(back.uvs, out.uvs, 2 * out.n_vertices * sizeof(float)) == 0);
  hearth_mesh_free(&back);
  hearth_mesh_free(&out);
}

static void test_release(void) {
  const char *dir = test_tmpdir("recon_atlas");
  char root[1100], cmd[1400], path[1200];
  snprintf(root, sizeof root, "%s/rel", dir);
  snprintf(cmd, sizeof cmd,
           "%s synth --out '%s' --categories cup --states neutral --views 10 --no-calibration "
           "--draft-rgb --texture 256 --map-res 64 --quiet",
           HEARTH_EXE, root);
  CHECK(system(cmd) == 0);
  hearth_err e = {0};
  hearth_recon_tsdf_opts o;
  hearth_recon_tsdf_opts_default(&o);
  o.voxel_m = 0.003;
  o.target_triangles = 8000;
  hearth_mesh m;
  CHECK_OK(hearth_recon_tsdf(root, "cup_01", NULL, 0, &o, &m, &e), &e);
  if (!m.n_triangles) return;
  snprintf(path, sizeof path, "%s/cup_atlas.glb", dir);
  atlas_glb("cup (TSDF)", &m, path);
  hearth_mesh_free(&m);
}

int main(int argc, char **argv) {
  if (argc >= 2) {
    hearth_err e = {0};
    hearth_mesh m;
    CHECK_OK(hearth_glb_read(argv[1], NULL, &m, &e), &e);
    if (g_test_failures) return 1;
    hearth_atlas_stats st;
    hearth_mesh out;
    CHECK_OK(hearth_mesh_atlas(&m, NULL, &out, NULL, &st, &e), &e);
    if (g_test_failures) return 1;
    printf(
        "%s: %zu triangles, %zu charts, L2 stretch %.4f (max %.4f), area %.4f, angle %.4f, "
        "packing %.3f; worst chart %.4f, %zu merged\n",
        argv[1], m.n_triangles, st.n_charts, st.stretch_l2, st.stretch_l2_max, st.area_distortion,
        st.angle_distortion, st.packing_efficiency, st.stretch_l2_chart_max, st.n_merges);
    if (argc >= 3) CHECK_OK(hearth_glb_write(argv[2], &out, &e), &e);
    hearth_mesh_free(&m), hearth_mesh_free(&out);
    return g_test_failures;
  }
  test_closed_forms();
  test_tiles();
  test_rings();
  test_release();
  return g_test_failures;
}
