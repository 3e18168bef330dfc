/* recon_mc.c - the zero level set of a TSDF volume by marching
 * tetrahedra. Each cube of eight samples is split into the six tetrahedra
 * (0,0,0) -> +e_a -> +e_b -> (1,1,1) for the six orders (a, b, c) of the
 * axes. Neighbouring cubes then split their shared faces along the same
 * diagonal, so every lattice edge a tetrahedron uses runs from a sample p
 * to p + d with d one of the seven non-zero 0/1 offsets, and the surface
 * vertex on it is shared through a hash of (p, d). A tetrahedron with one
 * sample on its own side gives one triangle, with two on each side a quad
 * (two triangles); each triangle is turned to face the positive side. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/recon_geom.h"

typedef struct edge_map {
  uint64_t *keys; /* key + 1; 0 = empty */
  uint32_t *vals;
  size_t cap; /* power of two */
  size_t n;
} edge_map;

static uint64_t mix64(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

static int edge_map_grow(edge_map *m) {
  size_t nc = m->cap ? 2 * m->cap : 1 << 16;
  uint64_t *k = calloc(nc, sizeof *k);
  uint32_t *v = malloc(nc * sizeof *v);
  if (!k || !v) {
    free(k);
    free(v);
    return -1;
  }
  for (size_t i = 0; i < m->cap; i++) {
    if (!m->keys[i]) continue;
    size_t h = mix64(m->keys[i]) & (nc - 1);
    while (k[h]) h = (h + 1) & (nc - 1);
    k[h] = m->keys[i];
    v[h] = m->vals[i];
  }
  free(m->keys);
  free(m->vals);
  m->keys = k;
  m->vals = v;
  m->cap = nc;
  return 0;
}

/* Slot of key (found or empty). */
static size_t edge_map_slot(const edge_map *m, uint64_t key) {
  size_t h = mix64(key + 1) & (m->cap - 1);
  while (m->keys[h] && m->keys[h] != key + 1) h = (h + 1) & (m->cap - 1);
  return h;
}

typedef struct mc_out {
  float *pos;
  size_t nv, cap_v;
  uint32_t *idx;
  size_t nt, cap_t;
  edge_map em;
} mc_out;

/* Corner offsets of a cube, bit 0 = x, bit 1 = y, bit 2 = z. */
static const int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                  {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};

static long vertex_on_edge(mc_out *o, const hearth_tsdf *t, const int pa[3], float da,
                           const int pb[3], float db) {
  /* canonical direction: from the lower to the higher sample */
  const int *p0 = pa, *p1 = pb;
  float d0 = da, d1 = db;
  if (pb[0] + pb[1] + pb[2] < pa[0] + pa[1] + pa[2]) {
    p0 = pb;
    p1 = pa;
    d0 = db;
    d1 = da;
  }
  int dir = (p1[0] - p0[0]) | (p1[1] - p0[1]) << 1 | (p1[2] - p0[2]) << 2;
  uint64_t key = (((uint64_t)p0[2] * t->ny + p0[1]) * t->nx + p0[0]) * 8 + dir;
  if (o->em.n * 2 >= o->em.cap && edge_map_grow(&o->em)) return -1;
  size_t sl = edge_map_slot(&o->em, key);
  if (o->em.keys[sl]) return o->em.vals[sl];
  if (o->nv == o->cap_v) {
    size_t nc = o->cap_v ? 2 * o->cap_v : 4096;
    float *np = realloc(o->pos, nc * 3 * sizeof *np);
    if (!np) return -1;
    o->pos = np;
    o->cap_v = nc;
  }
  double s = d0 / (double)(d0 - d1);
  for (int a = 0; a < 3; a++)
    o->pos[3 * o->nv + a] = (float)(t->origin[a] + t->voxel * (p0[a] + s * (p1[a] - p0[a])));
  o->em.keys[sl] = key + 1;
  o->em.vals[sl] = (uint32_t)o->nv;
  o->em.n++;
  return (long)o->nv++;
}

/* Append triangle (a, b, c), turned so its normal points along dir. */
static int emit(mc_out *o, long a, long b, long c, const double dir[3]) {
  if (a < 0 || b < 0 || c < 0) return -1;
  if (a == b || b == c || a == c) return 0;
  const float *A = o->pos + 3 * a, *B = o->pos + 3 * b, *C = o->pos + 3 * c;
  double e1[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
  double e2[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
  double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                 e1[0] * e2[1] - e1[1] * e2[0]};
  if (n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2] < 0) {
    long tmp = b;
    b = c;
    c = tmp;
  }
  if (o->nt == o->cap_t) {
    size_t nc = o->cap_t ? 2 * o->cap_t : 8192;
    uint32_t *ni = realloc(o->idx, nc * 3 * sizeof *ni);
    if (!ni) return -1;
    o->idx = ni;
    o->cap_t = nc;
  }
  o->idx[3 * o->nt] = (uint32_t)a;
  o->idx[3 * o->nt + 1] = (uint32_t)b;
  o->idx[3 * o->nt + 2] = (uint32_t)c;
  o->nt++;
  return 0;
}

static int march_tet(mc_out *o, const hearth_tsdf *t, const int p[4][3], const float d[4]) {
  int in[4], out_[4], ni = 0, no = 0;
  for (int q = 0; q < 4; q++) {
    if (d[q] < 0) in[ni++] = q;
    else out_[no++] = q;
  }
  if (ni == 0 || no == 0) return 0;
  /* direction from the negative to the positive samples */
  double ci[3] = {0, 0, 0}, co[3] = {0, 0, 0}, dir[3];
  for (int q = 0; q < ni; q++)
    for (int a = 0; a < 3; a++) ci[a] += p[in[q]][a] / (double)ni;
  for (int q = 0; q < no; q++)
    for (int a = 0; a < 3; a++) co[a] += p[out_[q]][a] / (double)no;
  for (int a = 0; a < 3; a++) dir[a] = co[a] - ci[a];
  if (ni == 1 || no == 1) {
    int lone = ni == 1 ? in[0] : out_[0];
    const int *others = ni == 1 ? out_ : in;
    long v[3];
    for (int q = 0; q < 3; q++)
      v[q] = vertex_on_edge(o, t, p[lone], d[lone], p[others[q]], d[others[q]]);
    return emit(o, v[0], v[1], v[2], dir);
  }
  long a = vertex_on_edge(o, t, p[in[0]], d[in[0]], p[out_[0]], d[out_[0]]);
  long b = vertex_on_edge(o, t, p[in[0]], d[in[0]], p[out_[1]], d[out_[1]]);
  long c = vertex_on_edge(o, t, p[in[1]], d[in[1]], p[out_[1]], d[out_[1]]);
  long e = vertex_on_edge(o, t, p[in[1]], d[in[1]], p[out_[0]], d[out_[0]]);
  if (emit(o, a, b, c, dir)) return -1;
  return emit(o, a, c, e, dir);
}

hearth_status hearth_tsdf_extract(const hearth_tsdf *t, hearth_mesh *out, hearth_err *err) {
  memset(out, 0, sizeof *out);
  if (!t || !t->dist) return hearth_err_set(err, HEARTH_E_ARG, "tsdf extract: no volume");
  /* the six monotone paths through the cube: corner bit orders */
  static const int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  mc_out o = {0};
  int fail = 0;
  for (int k = 0; k + 1 < t->nz && !fail; k++) {
    for (int j = 0; j + 1 < t->ny && !fail; j++) {
      for (int i = 0; i + 1 < t->nx && !fail; i++) {
        float cd[8];
        int obs = 1, neg = 0, pos = 0;
        for (int c = 0; c < 8; c++) {
          size_t s = ((size_t)(k + kCorner[c][2]) * t->ny + (j + kCorner[c][1])) * t->nx +
                     (i + kCorner[c][0]);
          cd[c] = t->dist[s];
          if (t->weight[s] <= 0) obs = 0;
          /* keep the level set off the samples: a zero counts as positive */
          if (cd[c] == 0.0f) cd[c] = 1e-6f;
          if (cd[c] < 0) neg = 1;
          else pos = 1;
        }
        if (!neg || !pos) continue;
        for (int q = 0; q < 6 && !fail; q++) {
          int corner[4] = {0, 1 << kPerm[q][0], (1 << kPerm[q][0]) | (1 << kPerm[q][1]), 7};
          int p[4][3];
          float d[4];
          int ok = 1;
          for (int r = 0; r < 4; r++) {
            int c = corner[r];
            p[r][0] = i + kCorner[c][0];
            p[r][1] = j + kCorner[c][1];
            p[r][2] = k + kCorner[c][2];
            d[r] = cd[c];
            if (!obs) {
              size_t s = ((size_t)p[r][2] * t->ny + p[r][1]) * t->nx + p[r][0];
              if (t->weight[s] <= 0) ok = 0;
            }
          }
          if (ok && march_tet(&o, t, p, d)) fail = 1;
        }
      }
    }
  }
  free(o.em.keys);
  free(o.em.vals);
  if (fail || o.nv > UINT32_MAX) {
    free(o.pos);
    free(o.idx);
    return hearth_err_set(err, HEARTH_E_NOMEM, "tsdf extract: %zu vertices", o.nv);
  }
  out->n_vertices = o.nv;
  out->positions = o.pos;
  out->n_triangles = o.nt;
  out->indices = o.idx;
  return HEARTH_OK;
}
