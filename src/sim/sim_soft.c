/* hearth's software renderer of a MuJoCo scene: geoms tessellated once in
 * their own frames, then per view: vertices to the camera frame, lit at
 * the vertices as MuJoCo's fixed-function OpenGL path lights them,
 * clipped at the near plane, rasterised with exact edge functions (a
 * top-left rule, so shared edges are drawn once), perspective-correct
 * interpolation, a z-buffer and bilinear texture lookups. See sim_soft.h.
 * Compiled with -ffp-contract=off (CMakeLists.txt). */
#include "sim/sim_soft.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* x^e for x in [0, 1] tabulated at 1/SOFT_POWN steps, interpolated */
#define SOFT_POWN 1024
#define SOFT_NPOW 16
typedef struct soft_pow {
  float e, t[SOFT_POWN + 2];
} soft_pow;

/* ---- arithmetic of its own: libm picks per-CPU variants (FMA or not) at
 * run time, so the renderer computes its powers and angles itself ---- */

/* sine and cosine of a (|a| up to a few turns): quadrant reduction, then
 * Taylor series on [-pi/4, pi/4] (error below 1e-16) */
static void soft_sincos(double a, double *sn, double *cs) {
  double k = floor(a / (0.5 * M_PI) + 0.5), r = a - k * (0.5 * M_PI), r2 = r * r;
  double s = r, c = 1.0, ts = r, tc = 1.0;
  for (int i = 1; i <= 10; i++) {
    ts *= -r2 / ((2.0 * i) * (2.0 * i + 1.0));
    tc *= -r2 / ((2.0 * i - 1.0) * (2.0 * i));
    s += ts, c += tc;
  }
  long q = (long)k % 4;
  if (q < 0) q += 4;
  *sn = q == 0 ? s : q == 1 ? c : q == 2 ? -s : -c;
  *cs = q == 0 ? c : q == 1 ? -s : q == 2 ? -c : s;
}

/* x^e for x in [0, 1], e >= 0, to about 1e-7: integer exponents by
 * squaring, others as 2^(e log2 x) with series of their own */
static float soft_powf(float x, float e) {
  if (x <= 0.0f) return e == 0.0f ? 1.0f : 0.0f;
  if (x >= 1.0f || e == 0.0f) return 1.0f;
  if (e == floorf(e) && e <= 256.0f) {
    float r = 1.0f, b = x;
    for (unsigned n = (unsigned)e; n; n >>= 1, b *= b)
      if (n & 1) r *= b;
    return r;
  }
  /* log2 x = ex + log2 m, m in [sqrt(1/2), sqrt(2)): 2 atanh((m-1)/(m+1)) / ln 2 */
  int ex;
  double m = frexp((double)x, &ex);
  if (m < M_SQRT1_2) m *= 2.0, ex--;
  double z = (m - 1.0) / (m + 1.0), z2 = z * z, t = z, sum = 0.0;
  for (int i = 0; i < 8; i++, t *= z2) sum += t / (2 * i + 1);
  double y = (double)e * ((double)ex + 2.0 * sum / M_LN2);
  if (y < -126.0) return 0.0f;
  /* 2^y = 2^n 2^f, f in [-0.5, 0.5] */
  double n = floor(y + 0.5), f = (y - n) * M_LN2, term = 1.0, ef = 1.0;
  for (int i = 1; i <= 10; i++) term *= f / i, ef += term;
  return (float)ldexp(ef, (int)n);
}

#define SOFT_MIN3(p, q, r) ((p) < (q) ? ((p) < (r) ? (p) : (r)) : ((q) < (r) ? (q) : (r)))
#define SOFT_MAX3(p, q, r) ((p) > (q) ? ((p) > (r) ? (p) : (r)) : ((q) > (r) ? (q) : (r)))

/* floor and ceiling of values well inside the int range, exact, without
 * a libm call (x86-64's baseline has no rounding instruction) */
static inline int soft_floor(double x) {
  int k = (int)x;
  return (double)k > x ? k - 1 : k;
}
static inline int soft_ceil(double x) {
  int k = (int)x;
  return (double)k < x ? k + 1 : k;
}

/* one geom's triangles in its own frame, sizes applied */
typedef struct soft_shape {
  int nv, nt;
  float *pos, *nrm, *uv; /* nv x 3, nv x 3, nv x 2 (uv NULL: no texture coordinates) */
  int *tri;              /* nt x 3, counter-clockwise seen from outside */
  float *plane;          /* nt x 4: face normal n (unnormalised), n . corner 0 */
  int np, *pid;          /* distinct positions; each vertex's position index */
} soft_shape;

/* a 2D texture and its mip levels, RGB U8, row 0 at t = 0 (as GL uploads it) */
#define SOFT_MAXLEVEL 14
typedef struct soft_tex {
  int levels, w[SOFT_MAXLEVEL], h[SOFT_MAXLEVEL];
  size_t off[SOFT_MAXLEVEL];
  uint8_t *rgb;
} soft_tex;

/* a vertex in the camera frame: position, lit colour, texture coordinates */
typedef struct soft_vtx {
  float x, y, z, r, g, b, u, v;
} soft_vtx;

/* a vertex on screen: pixel position (y up), 1/w and attributes times 1/w */
typedef struct soft_svtx {
  double sx, sy;
  float iw, a[5];
} soft_svtx;

/* a light in the camera frame */
typedef struct soft_light {
  const soft_pow *spot_pow;
  int directional;
  float pos[3], dir[3]; /* dir: unit, the way the light shines */
  float amb[3], dif[3], spc[3], att[3], cos_cut, expo;
} soft_light;

/* a triangle that won pixels in raster(): what resolve() shades them with */
typedef struct soft_rec {
  double A[3], B[3], C[3], inv; /* edge functions, 1 / twice the area */
  float iw[3], a[3][5];         /* the corners' 1/w and attributes over w */
  int level[2], mat;            /* mip levels; material in sim_soft.mats */
} soft_rec;

/* what one geom draws with: material, texture, level chooser */
typedef struct soft_mat {
  float rgba[4], spec, shin, emis;
  const soft_pow *shin_pow;
  const soft_tex *tex;
  int unlit;
  float flat[3];
  uint8_t *twin;        /* LIT with a twin image: its buffer, */
  const soft_tex *tex2; /* the texture it shows (NULL: flat2) */
  uint8_t flat2[3];
  int id;
} soft_mat;

struct sim_soft {
  soft_pow pw[SOFT_NPOW];
  int npw;
  int w, h, ngeom, ntex;
  soft_shape *shape;
  soft_tex *tex;
  float *depth;  /* 1/w of the nearest surface; 0: nothing */
  int *tri;      /* per pixel: record of the nearest triangle, -1: none */
  soft_rec *rec; /* the view's winning triangles, in drawing order */
  int *remap;    /* rcap: record renumbering of rec_compact */
  int nrec, rcap;
  soft_mat *mats;     /* ngeom: the materials of a view's geoms */
  int *order;         /* ngeom: drawing order of a view */
  double *key;        /* ngeom: its sort keys */
  soft_vtx *vtx;      /* per vertex of the geom at hand: camera frame, */
  soft_svtx *sv;      /* on screen (in front of the near plane only), */
  unsigned char *lit; /* 1 once placed, 2 once lit */
  float *pcam;        /* per distinct position: camera frame x y z, then */
  double *pscr;       /* screen x y and 1/w (in front of the near plane) */
  unsigned char *pdone;
  int vcap;
};

/* the table of exponent e, NULL when there is none (then soft_powf) */
static const soft_pow *pow_table(const sim_soft *s, float e) {
  for (int i = 0; i < s->npw; i++)
    if (s->pw[i].e == e) return &s->pw[i];
  return NULL;
}

/* a table for exponent e, made when the context is (so which exponents
 * have one depends on the model alone, never on what was rendered) */
static void pow_add(sim_soft *s, float e) {
  if (pow_table(s, e) || s->npw == SOFT_NPOW) return;
  soft_pow *p = &s->pw[s->npw++];
  p->e = e;
  for (int i = 0; i <= SOFT_POWN; i++) p->t[i] = soft_powf((float)i / SOFT_POWN, e);
  p->t[SOFT_POWN + 1] = 1.0f;
}

static float pow_lookup(const soft_pow *p, float e, float x) {
  if (!p) return soft_powf(x, e);
  if (x <= 0.0f) return p->t[0];
  if (x >= 1.0f) return 1.0f;
  float f = x * SOFT_POWN;
  int i = (int)f;
  float t = f - (float)i;
  return p->t[i] + t * (p->t[i + 1] - p->t[i]);
}

/* ---- tessellation ---------------------------------------------------------- */
static int shape_alloc(soft_shape *s, int nv, int nt, int with_uv) {
  s->nv = nv, s->nt = nt;
  s->plane = NULL, s->pid = NULL, s->np = 0;
  s->pos = malloc(sizeof(float) * 3 * (size_t)nv);
  s->nrm = malloc(sizeof(float) * 3 * (size_t)nv);
  s->uv = with_uv ? malloc(sizeof(float) * 2 * (size_t)nv) : NULL;
  s->tri = malloc(sizeof(int) * 3 * (size_t)(nt > 0 ? nt : 1));
  return s->pos && s->nrm && s->tri && (!with_uv || s->uv);
}

/* the triangles' planes, for culling back faces before any vertex work */
static int shape_planes(soft_shape *s) {
  s->plane = malloc(sizeof(float) * 4 * (size_t)(s->nt > 0 ? s->nt : 1));
  if (!s->plane) return 0;
  for (int t = 0; t < s->nt; t++) {
    const float *a = s->pos + 3 * s->tri[3 * t], *b = s->pos + 3 * s->tri[3 * t + 1],
                *c = s->pos + 3 * s->tri[3 * t + 2];
    float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
          v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    float *p = s->plane + 4 * t;
    p[0] = u[1] * v[2] - u[2] * v[1], p[1] = u[2] * v[0] - u[0] * v[2],
    p[2] = u[0] * v[1] - u[1] * v[0];
    p[3] = p[0] * a[0] + p[1] * a[1] + p[2] * a[2];
  }
  return 1;
}

/* the distinct positions of a shape (vertices repeat them where normals
 * or texture coordinates differ): each is moved to the camera once */
static int shape_positions(soft_shape *s) {
  size_t cap = 16;
  while (cap < 2 * (size_t)s->nv) cap *= 2;
  int *slot = malloc(sizeof(int) * cap);
  s->pid = malloc(sizeof(int) * (size_t)(s->nv > 0 ? s->nv : 1));
  if (!slot || !s->pid) return free(slot), 0;
  for (size_t i = 0; i < cap; i++) slot[i] = -1;
  s->np = 0;
  for (int i = 0; i < s->nv; i++) {
    const float *p = s->pos + 3 * i;
    uint64_t h = 1469598103934665603ull;
    const unsigned char *kb = (const unsigned char *)p;
    for (size_t b = 0; b < 3 * sizeof(float); b++) h = (h ^ kb[b]) * 1099511628211ull;
    size_t at = (size_t)h & (cap - 1);
    for (;;) {
      int j = slot[at];
      if (j < 0) {
        slot[at] = i;
        s->pid[i] = s->np++;
        break;
      }
      if (memcmp(s->pos + 3 * j, p, 3 * sizeof(float)) == 0) {
        s->pid[i] = s->pid[j];
        break;
      }
      at = (at + 1) & (cap - 1);
    }
  }
  free(slot);
  return 1;
}

static void shape_free(soft_shape *s) {
  free(s->pos), free(s->nrm), free(s->uv), free(s->tri), free(s->plane), free(s->pid);
  memset(s, 0, sizeof *s);
}

/* a box of half sizes sz: each face a q x q grid of quads; texture
 * coordinates as MuJoCo's object-linear generation on the unit box
 * (s = 0.5 scl0 x - 0.5, t = -0.5 scl1 y - 0.5) */
static int make_box(soft_shape *s, const double sz[3], int q, const float scl[2]) {
  int per = (q + 1) * (q + 1);
  if (!shape_alloc(s, 6 * per, 6 * 2 * q * q, 1)) return 0;
  int nv = 0, nt = 0;
  for (int f = 0; f < 6; f++) {
    int a = f / 2, sg = f % 2 ? -1 : 1;
    int b = (a + 1) % 3, c = (a + 2) % 3;
    if (sg < 0) b ^= c, c ^= b, b ^= c; /* b x c points outwards */
    int base = nv;
    for (int i = 0; i <= q; i++)
      for (int j = 0; j <= q; j++) {
        double unit[3];
        unit[a] = sg;
        unit[b] = -1.0 + 2.0 * i / q;
        unit[c] = -1.0 + 2.0 * j / q;
        for (int k = 0; k < 3; k++) {
          s->pos[3 * nv + k] = (float)(unit[k] * sz[k]);
          s->nrm[3 * nv + k] = k == a ? (float)sg : 0.0f;
        }
        s->uv[2 * nv] = (float)(0.5 * scl[0] * unit[0] - 0.5);
        s->uv[2 * nv + 1] = (float)(-0.5 * scl[1] * unit[1] - 0.5);
        nv++;
      }
    for (int i = 0; i < q; i++)
      for (int j = 0; j < q; j++) {
        int v00 = base + i * (q + 1) + j, v10 = v00 + q + 1, v11 = v10 + 1, v01 = v00 + 1;
        int *t = s->tri + 3 * nt;
        t[0] = v00, t[1] = v10, t[2] = v11, t[3] = v00, t[4] = v11, t[5] = v01;
        nt += 2;
      }
  }
  return 1;
}

/* rings of a surface of revolution about z, top to bottom: ring k at
 * height z[k], radius r[k], normal (nr[k] radial, nz[k] axial); quads
 * between consecutive rings, `sl` slices */
static int make_rings(soft_shape *s, int nring, const double *z, const double *r, const double *nr,
                      const double *nz, int sl) {
  if (!shape_alloc(s, nring * (sl + 1), 2 * (nring - 1) * sl, 0)) return 0;
  int nv = 0, nt = 0;
  for (int k = 0; k < nring; k++)
    for (int j = 0; j <= sl; j++) {
      double az = 2.0 * M_PI * j / sl, ca, sa;
      soft_sincos(az, &sa, &ca);
      s->pos[3 * nv] = (float)(r[k] * ca), s->pos[3 * nv + 1] = (float)(r[k] * sa);
      s->pos[3 * nv + 2] = (float)z[k];
      s->nrm[3 * nv] = (float)(nr[k] * ca), s->nrm[3 * nv + 1] = (float)(nr[k] * sa);
      s->nrm[3 * nv + 2] = (float)nz[k];
      nv++;
    }
  for (int k = 0; k + 1 < nring; k++)
    for (int j = 0; j < sl; j++) {
      int a = k * (sl + 1) + j, b = a + sl + 1, c = b + 1, d = a + 1;
      int *t = s->tri + 3 * nt;
      t[0] = a, t[1] = b, t[2] = c, t[3] = a, t[4] = c, t[5] = d;
      nt += 2;
    }
  return 1;
}

/* sphere (h = 0) or capsule (cylinder of half length h between two
 * hemispheres) of radius rad */
static int make_round(soft_shape *s, double rad, double h, int sl, int st) {
  int half = st / 2 > 1 ? st / 2 : 2, n = 2 * (half + 1);
  double z[64], r[64], nr[64], nz[64];
  if (n > 64) half = 31, n = 64;
  for (int k = 0; k < n; k++) {
    int top = k <= half;
    double el = top ? 0.5 * M_PI * k / half : 0.5 * M_PI * (1.0 + (double)(k - half - 1) / half);
    soft_sincos(el, &nr[k], &nz[k]);
    r[k] = rad * nr[k];
    z[k] = rad * nz[k] + (top ? h : -h);
  }
  return make_rings(s, n, z, r, nr, nz, sl);
}

/* closed cylinder: side rings, then the two caps as fans */
static int make_cylinder(soft_shape *s, double rad, double h, int sl) {
  double z[2] = {h, -h}, r[2] = {rad, rad}, nr[2] = {1, 1}, nz[2] = {0, 0};
  soft_shape side;
  if (!make_rings(&side, 2, z, r, nr, nz, sl)) return shape_free(&side), 0;
  int nv = side.nv + 2 * (sl + 2), nt = side.nt + 2 * sl;
  if (!shape_alloc(s, nv, nt, 0)) return shape_free(&side), 0;
  memcpy(s->pos, side.pos, sizeof(float) * 3 * side.nv);
  memcpy(s->nrm, side.nrm, sizeof(float) * 3 * side.nv);
  memcpy(s->tri, side.tri, sizeof(int) * 3 * side.nt);
  int v = side.nv, t = side.nt;
  shape_free(&side);
  for (int cap = 0; cap < 2; cap++) {
    double zc = cap ? -h : h;
    float n = cap ? -1.0f : 1.0f;
    int centre = v;
    for (int j = -1; j <= sl; j++) {
      double az = 2.0 * M_PI * (j < 0 ? 0 : j) / sl;
      double rr = j < 0 ? 0.0 : rad;
      double sa, ca;
      soft_sincos(az, &sa, &ca);
      s->pos[3 * v] = (float)(rr * ca), s->pos[3 * v + 1] = (float)(rr * sa);
      s->pos[3 * v + 2] = (float)zc;
      s->nrm[3 * v] = 0, s->nrm[3 * v + 1] = 0, s->nrm[3 * v + 2] = n;
      v++;
    }
    for (int j = 0; j < sl; j++) {
      int a = centre + 1 + j, b = a + 1;
      int *tt = s->tri + 3 * t++;
      tt[0] = centre, tt[1] = cap ? b : a, tt[2] = cap ? a : b;
    }
  }
  return 1;
}

/* the model's mesh: vertices, normals, texture coordinates as stored,
 * with vertices that agree in all three merged (MuJoCo keeps one per
 * face corner; merging changes no pixel and lights each corner once) */
static int make_mesh(soft_shape *s, const mjModel *m, int id) {
  int va = m->mesh_vertadr[id], nv = m->mesh_vertnum[id], fa = m->mesh_faceadr[id],
      nf = m->mesh_facenum[id], ta = m->mesh_texcoordadr[id];
  if (!shape_alloc(s, nv, nf, ta >= 0)) return 0;
  size_t cap = 16;
  while (cap < 2 * (size_t)nv) cap *= 2;
  int *slot = malloc(sizeof(int) * cap), *remap = malloc(sizeof(int) * (size_t)(nv > 0 ? nv : 1));
  if (!slot || !remap) return free(slot), free(remap), 0;
  for (size_t i = 0; i < cap; i++) slot[i] = -1;
  int n = 0;
  for (int i = 0; i < nv; i++) {
    float key[8];
    memcpy(key, m->mesh_vert + 3 * (size_t)(va + i), sizeof(float) * 3);
    memcpy(key + 3, m->mesh_normal + 3 * (size_t)(va + i), sizeof(float) * 3);
    key[6] = key[7] = 0;
    if (ta >= 0) memcpy(key + 6, m->mesh_texcoord + 2 * (size_t)(ta + i), sizeof(float) * 2);
    uint64_t h = 1469598103934665603ull;
    const unsigned char *kb = (const unsigned char *)key;
    for (size_t b = 0; b < sizeof key; b++) h = (h ^ kb[b]) * 1099511628211ull;
    size_t at = (size_t)h & (cap - 1);
    for (;;) {
      int j = slot[at];
      if (j < 0) {
        slot[at] = n;
        memcpy(s->pos + 3 * n, key, sizeof(float) * 3);
        memcpy(s->nrm + 3 * n, key + 3, sizeof(float) * 3);
        if (s->uv) memcpy(s->uv + 2 * n, key + 6, sizeof(float) * 2);
        remap[i] = n++;
        break;
      }
      if (memcmp(s->pos + 3 * j, key, sizeof(float) * 3) == 0 &&
          memcmp(s->nrm + 3 * j, key + 3, sizeof(float) * 3) == 0 &&
          (!s->uv || memcmp(s->uv + 2 * j, key + 6, sizeof(float) * 2) == 0)) {
        remap[i] = j;
        break;
      }
      at = (at + 1) & (cap - 1);
    }
  }
  s->nv = n;
  for (int t = 0; t < 3 * nf; t++) {
    int k = m->mesh_face[3 * (size_t)fa + t];
    s->tri[t] = k >= 0 && k < nv ? remap[k] : 0;
  }
  free(slot), free(remap);
  return 1;
}

static void geom_scl(const mjModel *m, int g, float scl[2]) {
  int mat = m->geom_matid[g];
  scl[0] = scl[1] = 1;
  if (mat < 0) return;
  for (int k = 0; k < 2; k++) {
    scl[k] = m->mat_texrepeat[2 * mat + k];
    if (m->mat_texuniform[mat] && m->geom_size[3 * g + k] > 0)
      scl[k] *= (float)m->geom_size[3 * g + k];
  }
}

static int make_shape(soft_shape *s, const mjModel *m, int g) {
  const double *sz = m->geom_size + 3 * g;
  int sl = m->vis.quality.numslices > 4 ? m->vis.quality.numslices : 4,
      st = m->vis.quality.numstacks > 2 ? m->vis.quality.numstacks : 2,
      q = m->vis.quality.numquads > 1 ? m->vis.quality.numquads : 1;
  float scl[2];
  geom_scl(m, g, scl);
  switch (m->geom_type[g]) {
    case mjGEOM_BOX: return make_box(s, sz, q, scl);
    case mjGEOM_SPHERE: return make_round(s, sz[0], 0.0, sl, st);
    case mjGEOM_CAPSULE: return make_round(s, sz[0], sz[1], sl, st);
    case mjGEOM_CYLINDER: return make_cylinder(s, sz[0], sz[1], sl);
    case mjGEOM_MESH: return m->geom_dataid[g] >= 0 ? make_mesh(s, m, m->geom_dataid[g]) : 1;
    default: return 1; /* planes, height fields, ellipsoids: not drawn */
  }
}

/* ---- textures ---------------------------------------------------------------- */
static void tex_fill(soft_tex *t, const mjModel *m, int id);
static int make_tex(soft_tex *t, const mjModel *m, int id) {
  if (m->tex_type[id] != mjTEXTURE_2D) return 1;
  int w = m->tex_width[id], h = m->tex_height[id];
  size_t total = 0;
  t->levels = 0;
  for (int lw = w, lh = h;
       t->levels<SOFT_MAXLEVEL; lw = lw> 1 ? lw / 2 : 1, lh = lh > 1 ? lh / 2 : 1) {
    t->w[t->levels] = lw, t->h[t->levels] = lh, t->off[t->levels] = total;
    total += (size_t)lw * (size_t)lh * 3;
    t->levels++;
    if (lw == 1 && lh == 1) break;
  }
  t->rgb = malloc(total);
  if (!t->rgb) return 0;
  tex_fill(t, m, id);
  return 1;
}

/* the texture's level 0 from the model and the mip levels below it */
static void tex_fill(soft_tex *t, const mjModel *m, int id) {
  memcpy(t->rgb, m->tex_rgb + m->tex_adr[id], (size_t)t->w[0] * t->h[0] * 3);
  /* each level the rounded mean of (up to) 2 x 2 texels of the one above */
  for (int l = 1; l < t->levels; l++) {
    const uint8_t *src = t->rgb + t->off[l - 1];
    uint8_t *dst = t->rgb + t->off[l];
    int sw = t->w[l - 1], sh = t->h[l - 1];
    for (int y = 0; y < t->h[l]; y++)
      for (int x = 0; x < t->w[l]; x++) {
        int x0 = 2 * x < sw ? 2 * x : sw - 1, x1 = 2 * x + 1 < sw ? 2 * x + 1 : x0;
        int y0 = 2 * y < sh ? 2 * y : sh - 1, y1 = 2 * y + 1 < sh ? 2 * y + 1 : y0;
        for (int c = 0; c < 3; c++) {
          int sum = src[3 * (y0 * sw + x0) + c] + src[3 * (y0 * sw + x1) + c] +
                    src[3 * (y1 * sw + x0) + c] + src[3 * (y1 * sw + x1) + c];
          dst[3 * (y * t->w[l] + x) + c] = (uint8_t)((sum + 2) / 4);
        }
      }
  }
}

void sim_soft_update_tex(sim_soft *s, const mjModel *m, int id) {
  if (!s || id < 0 || id >= s->ntex || !s->tex[id].rgb) return;
  if (s->tex[id].w[0] != m->tex_width[id] || s->tex[id].h[0] != m->tex_height[id]) return;
  tex_fill(&s->tex[id], m, id);
}

/* bilinear lookup with wrap-around in level l, into c[3] (0..1) */
static inline void tex_sample(const soft_tex *t, int l, float u, float v, float c[3]) {
  int w = t->w[l], h = t->h[l];
  const uint8_t *p = t->rgb + t->off[l];
  float fu = u * (float)w - 0.5f, fv = v * (float)h - 0.5f;
  /* coordinates far outside the texture's repeats (or not numbers): its
   * first texel rather than an overflowing conversion */
  if (!(fabsf(fu) < 1e7f)) fu = 0.0f;
  if (!(fabsf(fv) < 1e7f)) fv = 0.0f;
  float x0f = (float)soft_floor(fu), y0f = (float)soft_floor(fv), ax = fu - x0f, ay = fv - y0f;
  /* wrap: the coordinates stay within a few repeats of the texture */
  long x0, y0;
  if (((w & (w - 1)) | (h & (h - 1))) == 0) {
    x0 = (long)x0f & (w - 1), y0 = (long)y0f & (h - 1);
  } else {
    x0 = (long)x0f % w, y0 = (long)y0f % h;
    if (x0 < 0) x0 += w;
    if (y0 < 0) y0 += h;
  }
  long x1 = x0 + 1 < w ? x0 + 1 : 0, y1 = y0 + 1 < h ? y0 + 1 : 0;
  const uint8_t *a = p + 3 * (y0 * w + x0), *b = p + 3 * (y0 * w + x1), *cc = p + 3 * (y1 * w + x0),
                *d = p + 3 * (y1 * w + x1);
  for (int k = 0; k < 3; k++) {
    float top = (float)a[k] + ax * ((float)b[k] - (float)a[k]);
    float bot = (float)cc[k] + ax * ((float)d[k] - (float)cc[k]);
    c[k] = (top + ay * (bot - top)) * (1.0f / 255.0f);
  }
}

/* ---- context ------------------------------------------------------------------- */
void sim_soft_free(sim_soft *s) {
  if (!s) return;
  for (int g = 0; g < s->ngeom && s->shape; g++) shape_free(&s->shape[g]);
  for (int t = 0; t < s->ntex && s->tex; t++) free(s->tex[t].rgb);
  free(s->order), free(s->key);
  free(s->shape), free(s->tex), free(s->depth), free(s->vtx), free(s->sv), free(s->lit);
  free(s->pcam), free(s->pscr), free(s->pdone);
  free(s->tri), free(s->rec), free(s->remap), free(s->mats);
  free(s);
}

sim_soft *sim_soft_new(const mjModel *m, int w, int h) {
  sim_soft *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  s->w = w, s->h = h, s->ngeom = m->ngeom, s->ntex = m->ntex;
  s->shape = calloc((size_t)(m->ngeom > 0 ? m->ngeom : 1), sizeof *s->shape);
  s->tex = calloc((size_t)(m->ntex > 0 ? m->ntex : 1), sizeof *s->tex);
  s->depth = malloc(sizeof(float) * (size_t)w * (size_t)h);
  s->order = malloc(sizeof(int) * (size_t)(m->ngeom > 0 ? m->ngeom : 1));
  s->key = malloc(sizeof(double) * (size_t)(m->ngeom > 0 ? m->ngeom : 1));
  int ok = s->shape && s->tex && s->depth && s->order && s->key;
  for (int g = 0; g < m->ngeom && ok; g++) {
    ok = make_shape(&s->shape[g], m, g) && shape_planes(&s->shape[g]) &&
         shape_positions(&s->shape[g]);
    if (s->shape[g].nv > s->vcap) s->vcap = s->shape[g].nv;
  }
  for (int t = 0; t < m->ntex && ok; t++) ok = make_tex(&s->tex[t], m, t);
  /* the exponents: specular (shininess x 128; 0.5 without a material)
   * and spot lights */
  pow_add(s, 0.5f * 128.0f);
  for (int i = 0; i < m->nmat; i++) pow_add(s, m->mat_shininess[i] * 128.0f);
  for (int i = 0; i < m->nlight; i++)
    pow_add(s, m->light_directional[i] ? 0.0f : m->light_exponent[i]);
  size_t nv = (size_t)(s->vcap > 0 ? s->vcap : 1);
  /* records: at most two per triangle (near-plane clipping), and never
   * more than one per pixel after rec_compact */
  size_t ntri = 0;
  for (int g = 0; g < m->ngeom && ok; g++) ntri += (size_t)s->shape[g].nt;
  size_t npx = (size_t)w * (size_t)h, rcap = 2 * ntri + 1;
  if (rcap > npx + 1) rcap = npx + 1;
  s->rcap = (int)rcap;
  if (ok) {
    s->tri = malloc(sizeof(int) * npx), s->rec = malloc(sizeof(soft_rec) * rcap);
    s->remap = malloc(sizeof(int) * rcap);
    s->mats = malloc(sizeof(soft_mat) * (size_t)(m->ngeom > 0 ? m->ngeom : 1));
    ok = s->tri && s->rec && s->remap && s->mats;
  }
  if (ok) {
    s->vtx = malloc(sizeof(soft_vtx) * nv), s->sv = malloc(sizeof(soft_svtx) * nv);
    s->lit = malloc(nv);
    s->pcam = malloc(sizeof(float) * 3 * nv), s->pscr = malloc(sizeof(double) * 3 * nv);
    s->pdone = malloc(nv);
    ok = s->vtx && s->sv && s->lit && s->pcam && s->pscr && s->pdone;
  }
  if (!ok) {
    sim_soft_free(s);
    return NULL;
  }
  return s;
}

/* ---- per view ------------------------------------------------------------------ */
typedef struct soft_cam {
  double R[9], p[3]; /* world from camera: columns of R are the camera axes */
  double znear, f;   /* near distance, focal length in pixels */
  double tanx, tany; /* half field of view tangents */
} soft_cam;

/* the fixed-function lighting sum at one camera-frame vertex, clamped */
static void light_vertex(const soft_light *L, int nl, const soft_mat *mt, const float p[3],
                         const float n[3], float out[3]) {
  float c[3];
  /* OpenGL's global ambient: 0.3 when there is no light at all (as
   * MuJoCo sets it), else none */
  float amb = nl == 0 ? 0.3f : 0.0f;
  for (int k = 0; k < 3; k++) c[k] = mt->emis * mt->rgba[k] + amb * mt->rgba[k];
  float vl = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  float V[3] = {0, 0, 1};
  if (vl > 0) {
    float iv = 1.0f / vl;
    V[0] = -p[0] * iv, V[1] = -p[1] * iv, V[2] = -p[2] * iv;
  }
  for (int i = 0; i < nl; i++) {
    const soft_light *l = &L[i];
    float Ld[3], att = 1.0f, spot = 1.0f;
    if (l->directional) {
      Ld[0] = -l->dir[0], Ld[1] = -l->dir[1], Ld[2] = -l->dir[2];
    } else {
      float dx = l->pos[0] - p[0], dy = l->pos[1] - p[1], dz = l->pos[2] - p[2];
      float dist = sqrtf(dx * dx + dy * dy + dz * dz);
      if (dist <= 0) continue;
      float id = 1.0f / dist;
      Ld[0] = dx * id, Ld[1] = dy * id, Ld[2] = dz * id;
      if (l->att[0] != 1.0f || l->att[1] != 0.0f || l->att[2] != 0.0f)
        att = 1.0f / (l->att[0] + l->att[1] * dist + l->att[2] * dist * dist);
      float cs = -(Ld[0] * l->dir[0] + Ld[1] * l->dir[1] + Ld[2] * l->dir[2]);
      if (cs < l->cos_cut) continue;
      spot = pow_lookup(l->spot_pow, l->expo, cs);
    }
    float ndl = n[0] * Ld[0] + n[1] * Ld[1] + n[2] * Ld[2];
    float s = 0.0f;
    if (ndl > 0) {
      float hx = Ld[0] + V[0], hy = Ld[1] + V[1], hz = Ld[2] + V[2];
      float hl = sqrtf(hx * hx + hy * hy + hz * hz);
      float ndh = hl > 0 ? (n[0] * hx + n[1] * hy + n[2] * hz) / hl : 0.0f;
      if (ndh > 0) s = pow_lookup(mt->shin_pow, mt->shin, ndh) * mt->spec;
    } else {
      ndl = 0;
    }
    float k = att * spot;
    for (int j = 0; j < 3; j++)
      c[j] += k * (l->amb[j] * mt->rgba[j] + ndl * l->dif[j] * mt->rgba[j] + s * l->spc[j]);
  }
  for (int k = 0; k < 3; k++) out[k] = c[k] < 0 ? 0 : c[k] > 1 ? 1 : c[k];
}

static int edge_owns(double A, double B) { return A > 0 || (A == 0 && B < 0); }

/* the pixels whose centres (x + 0.5, y + 0.5) may be inside a screen
 * triangle, clipped to the image: box = x0 x1 y0 y1; 0 when none */
static int tri_box(const sim_soft *s, const soft_svtx *a, const soft_svtx *b, const soft_svtx *c,
                   int box[4]) {
  double lo[2] = {SOFT_MIN3(a->sx, b->sx, c->sx) - 0.5, SOFT_MIN3(a->sy, b->sy, c->sy) - 0.5},
         hi[2] = {SOFT_MAX3(a->sx, b->sx, c->sx) - 0.5, SOFT_MAX3(a->sy, b->sy, c->sy) - 0.5};
  int n[2] = {s->w, s->h};
  for (int k = 0; k < 2; k++) {
    if (!(hi[k] >= 0 && lo[k] <= n[k] - 1)) return 0; /* off the image (or not a number) */
    int i0 = soft_ceil(lo[k] < -1 ? -1 : lo[k]), i1 = soft_floor(hi[k] > n[k] ? n[k] : hi[k]);
    if (i0 < 0) i0 = 0;
    if (i1 > n[k] - 1) i1 = n[k] - 1;
    if (i0 > i1) return 0;
    box[2 * k] = i0, box[2 * k + 1] = i1;
  }
  return 1;
}

/* records no pixel refers to any more go, the others keep their order
 * (so rcap >= pixels + 1 always leaves room) */
static void rec_compact(sim_soft *s) {
  size_t npx = (size_t)s->w * (size_t)s->h;
  for (int i = 0; i < s->nrec; i++) s->remap[i] = -1;
  for (size_t p = 0; p < npx; p++)
    if (s->tri[p] >= 0) s->remap[s->tri[p]] = 0;
  int n = 0;
  for (int i = 0; i < s->nrec; i++)
    if (s->remap[i] == 0) {
      if (n != i) s->rec[n] = s->rec[i];
      s->remap[i] = n++;
    }
  for (size_t p = 0; p < npx; p++)
    if (s->tri[p] >= 0) s->tri[p] = s->remap[s->tri[p]];
  s->nrec = n;
}

/* The loops of the depth pass and of the shading are built twice on
 * x86-64 with GCC: for AVX2 (4 doubles or 8 floats per vector) and for
 * the baseline (SSE2), chosen once at load time by the CPU. Each lane
 * does the same IEEE operations in the same order in both (no fused
 * multiply-adds: AVX2 does not imply FMA and the file is compiled with
 * -ffp-contract=off; no reassociated sums), so the bytes do not depend
 * on which one runs. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SOFT_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define SOFT_CLONES
#endif

/* box width (pixels) below which raster() tests the whole box */
#define SOFT_NARROW 8

/* the exact coverage test of pixel centre xc against the three edges */
static inline int soft_inside(const double A[3], const double row[3], const int own[3], double xc) {
  for (int i = 0; i < 3; i++) {
    double e = A[i] * xc + row[i];
    if (!(e > 0 || (e == 0 && own[i]))) return 0;
  }
  return 1;
}

/* one screen triangle (counter-clockwise, y up; positions and 1/w) of
 * twice the area `area` (> 0) over pixel box `box` (tri_box) into the
 * depth buffer: the pixels where it is the nearest surface so far take
 * the index of the next record, s->nrec. 1 when it won any: then
 * rec_commit() must fill that record (the shading waits for resolve()) */
SOFT_CLONES static int raster_in(sim_soft *s, const soft_svtx *a, const soft_svtx *b,
                                 const soft_svtx *c, double area, const int box[4]) {
  if (s->nrec == s->rcap) rec_compact(s);
  int x0 = box[0], x1 = box[1], y0 = box[2], y1 = box[3];
  /* edge i opposite vertex i: E(p) = A x + B y + C, positive inside */
  const soft_svtx *v[3] = {a, b, c};
  int t = s->nrec;
  soft_rec *r = &s->rec[t];
  double A[3], B[3], C[3];
  int own[3];
  for (int i = 0; i < 3; i++) {
    const soft_svtx *p = v[(i + 1) % 3], *q = v[(i + 2) % 3];
    A[i] = p->sy - q->sy, B[i] = q->sx - p->sx, C[i] = p->sx * q->sy - p->sy * q->sx;
    own[i] = edge_owns(A[i], B[i]);
    r->A[i] = A[i], r->B[i] = B[i], r->C[i] = C[i];
  }
  double inv = 1.0 / area, rA[3];
  r->inv = inv;
  /* the roots need not be exact: the span is a pixel wider and trimmed */
  for (int i = 0; i < 3; i++) rA[i] = A[i] != 0 ? 1.0 / A[i] : 0.0;
  float aiw = a->iw, biw = b->iw, ciw = c->iw;
  int won = 0;
  if (x1 - x0 < SOFT_NARROW) {
    /* a narrow triangle: every centre of its box takes the exact test,
     * without branches (cheaper than finding each row's span) */
    int o0 = own[0], o1 = own[1], o2 = own[2];
    for (int y = y0; y <= y1; y++) {
      double yc = y + 0.5, r0 = B[0] * yc + C[0], r1 = B[1] * yc + C[1], r2 = B[2] * yc + C[2];
      size_t line = (size_t)y * (size_t)s->w;
      float *dp = s->depth + line;
      int *tp = s->tri + line;
      for (int x = x0; x <= x1; x++) {
        double xc = x + 0.5, e0 = A[0] * xc + r0, e1 = A[1] * xc + r1, e2 = A[2] * xc + r2;
        int in = ((e0 > 0) | ((e0 == 0) & o0)) & ((e1 > 0) | ((e1 == 0) & o1)) &
                 ((e2 > 0) | ((e2 == 0) & o2));
        float l0 = (float)(e0 * inv), l1 = (float)(e1 * inv), l2 = (float)(e2 * inv);
        float iw = l0 * aiw + l1 * biw + l2 * ciw;
        int pass = in & !(iw < dp[x]);
        dp[x] = pass ? iw : dp[x];
        tp[x] = pass ? t : tp[x];
        won |= pass;
      }
    }
    return won;
  }
  for (int y = y0; y <= y1; y++) {
    double yc = y + 0.5, row[3];
    for (int i = 0; i < 3; i++) row[i] = B[i] * yc + C[i];
    size_t line = (size_t)y * (size_t)s->w;
    /* the row's span from the edges' roots, a pixel wider on each side */
    int lo = x0, hi = x1;
    for (int i = 0; i < 3 && lo <= hi; i++) {
      if (A[i] == 0) {
        if (row[i] < 0 || (row[i] == 0 && !own[i])) hi = lo - 1;
        continue;
      }
      double rt = -row[i] * rA[i] - 0.5;
      if (rt < x0 - 1) rt = x0 - 1;
      if (rt > x1 + 1) rt = x1 + 1;
      if (A[i] > 0) {
        int k = soft_floor(rt);
        if (k > lo) lo = k;
      } else {
        int k = soft_ceil(rt);
        if (k < hi) hi = k;
      }
    }
    /* each edge function is monotone in x (a product and a sum, rounded),
     * so the centres that pass the exact test form one run: trim the
     * span's ends to it and test nothing inside */
    while (lo <= hi && !soft_inside(A, row, own, lo + 0.5)) lo++;
    while (hi > lo && !soft_inside(A, row, own, hi + 0.5)) hi--;
    float *dp = s->depth + line;
    int *tp = s->tri + line;
    double A0 = A[0], A1 = A[1], A2 = A[2], r0 = row[0], r1 = row[1], r2 = row[2];
    for (int x = lo; x <= hi; x++) {
      double xc = x + 0.5;
      float l0 = (float)((A0 * xc + r0) * inv), l1 = (float)((A1 * xc + r1) * inv),
            l2 = (float)((A2 * xc + r2) * inv);
      float iw = l0 * aiw + l1 * biw + l2 * ciw;
      int pass = !(iw < dp[x]);
      dp[x] = pass ? iw : dp[x];
      tp[x] = pass ? t : tp[x];
      won |= pass;
    }
  }
  return won;
}

/* raster_in for a triangle not yet measured */
static int raster(sim_soft *s, const soft_svtx *a, const soft_svtx *b, const soft_svtx *c) {
  double area = (b->sx - a->sx) * (c->sy - a->sy) - (b->sy - a->sy) * (c->sx - a->sx);
  int box[4];
  if (!(area > 0) || !tri_box(s, a, b, c, box)) return 0;
  return raster_in(s, a, b, c, area, box);
}

/* the record of the triangle raster() just drew: its corners' 1/w and
 * attributes, mip levels and material */
static void rec_commit(sim_soft *s, const soft_svtx *a, const soft_svtx *b, const soft_svtx *c,
                       const soft_mat *mt, const int level[2]) {
  soft_rec *r = &s->rec[s->nrec++];
  r->iw[0] = a->iw, r->iw[1] = b->iw, r->iw[2] = c->iw;
  for (int k = 0; k < 5; k++) r->a[0][k] = a->a[k], r->a[1][k] = b->a[k], r->a[2][k] = c->a[k];
  r->level[0] = level[0], r->level[1] = level[1];
  r->mat = (int)(mt - s->mats);
}

/* pixels x0 .. x1 - 1 of row `row` (edge functions at the row's centre
 * line) won by triangle r: colour (o) and twin (o2) bytes; the flags say
 * what the material has, so that each kind gets a loop of its own */
static inline void shade_run(const soft_rec *r, const soft_mat *mt, const double row[3], int x0,
                             int x1, uint8_t *o, uint8_t *o2, int unlit, int tex, int twin,
                             int tex2) {
  /* only the attributes this triangle uses */
  int k0 = unlit ? 3 : 0, k1 = tex || tex2 ? 5 : 3;
  double A0 = r->A[0], A1 = r->A[1], A2 = r->A[2], inv = r->inv;
  float iw0 = r->iw[0], iw1 = r->iw[1], iw2 = r->iw[2];
  for (int x = x0; x < x1; x++) {
    double xc = x + 0.5;
    float l0 = (float)((A0 * xc + row[0]) * inv), l1 = (float)((A1 * xc + row[1]) * inv),
          l2 = (float)((A2 * xc + row[2]) * inv);
    float iw = l0 * iw0 + l1 * iw1 + l2 * iw2;
    float wgt = 1.0f / iw, at[5] = {1.0f, 1.0f, 1.0f, 0.0f, 0.0f};
    for (int k = k0; k < k1; k++)
      at[k] = (l0 * r->a[0][k] + l1 * r->a[1][k] + l2 * r->a[2][k]) * wgt;
    float col[3] = {at[0], at[1], at[2]};
    if (unlit && !tex) col[0] = mt->flat[0], col[1] = mt->flat[1], col[2] = mt->flat[2];
    if (tex) {
      float tc[3];
      tex_sample(mt->tex, r->level[0], at[3], at[4], tc);
      for (int k = 0; k < 3; k++) col[k] = unlit ? tc[k] : col[k] * tc[k];
    }
    uint8_t *p = o + 3 * x;
    for (int k = 0; k < 3; k++) {
      float cl = col[k] < 0 ? 0 : col[k] > 1 ? 1 : col[k];
      p[k] = (uint8_t)(cl * 255.0f + 0.5f);
    }
    if (twin) {
      uint8_t *p2 = o2 + 3 * x;
      if (tex2) {
        float tc[3];
        tex_sample(mt->tex2, r->level[1], at[3], at[4], tc);
        for (int k = 0; k < 3; k++) p2[k] = (uint8_t)(tc[k] * 255.0f + 0.5f);
      } else {
        p2[0] = mt->flat2[0], p2[1] = mt->flat2[1], p2[2] = mt->flat2[2];
      }
    }
  }
}

/* shade_run for a lit material without texture: the run in blocks whose
 * arithmetic the compiler vectorises (the same operations per pixel) */
#define SOFT_BLOCK 32
SOFT_CLONES static void shade_run_plain(const soft_rec *r, const soft_mat *mt, const double row[3],
                                        int x0, int x1, uint8_t *o, uint8_t *o2) {
  double A0 = r->A[0], A1 = r->A[1], A2 = r->A[2], inv = r->inv, r0 = row[0], r1 = row[1],
         r2 = row[2];
  float iw0 = r->iw[0], iw1 = r->iw[1], iw2 = r->iw[2];
  float a0[3], a1[3], a2[3];
  for (int k = 0; k < 3; k++) a0[k] = r->a[0][k], a1[k] = r->a[1][k], a2[k] = r->a[2][k];
  float c[3][SOFT_BLOCK];
  for (int xb = x0; xb < x1; xb += SOFT_BLOCK) {
    int n = x1 - xb < SOFT_BLOCK ? x1 - xb : SOFT_BLOCK;
    for (int i = 0; i < n; i++) {
      double xc = (xb + i) + 0.5;
      float l0 = (float)((A0 * xc + r0) * inv), l1 = (float)((A1 * xc + r1) * inv),
            l2 = (float)((A2 * xc + r2) * inv);
      float iw = l0 * iw0 + l1 * iw1 + l2 * iw2;
      float wgt = 1.0f / iw;
      for (int k = 0; k < 3; k++) {
        float v = (l0 * a0[k] + l1 * a1[k] + l2 * a2[k]) * wgt;
        c[k][i] = v < 0 ? 0 : v > 1 ? 1 : v;
      }
    }
    uint8_t *p = o + 3 * xb;
    for (int i = 0; i < n; i++)
      for (int k = 0; k < 3; k++) p[3 * i + k] = (uint8_t)(c[k][i] * 255.0f + 0.5f);
    if (o2) {
      uint8_t *p2 = o2 + 3 * xb;
      for (int i = 0; i < n; i++)
        p2[3 * i] = mt->flat2[0], p2[3 * i + 1] = mt->flat2[1], p2[3 * i + 2] = mt->flat2[2];
    }
  }
}

/* the colours of every covered pixel from the triangle that won it, with
 * the interpolation raster's depth test used (the same values), run by
 * run of pixels that one triangle won */
SOFT_CLONES static void resolve(sim_soft *s, uint8_t *rgb, int *ids) {
  for (int y = 0; y < s->h; y++) {
    double yc = y + 0.5, row[3];
    size_t line = (size_t)y * (size_t)s->w;
    const int *tl = s->tri + line;
    int x = 0;
    while (x < s->w) {
      int t = tl[x];
      if (t < 0) {
        x++;
        continue;
      }
      int xe = x + 1;
      while (xe < s->w && tl[xe] == t) xe++;
      const soft_rec *r = &s->rec[t];
      const soft_mat *mt = &s->mats[r->mat];
      if (ids)
        for (int i = x; i < xe; i++) ids[line + (size_t)i] = mt->id;
      if (rgb) {
        for (int i = 0; i < 3; i++) row[i] = r->B[i] * yc + r->C[i];
        uint8_t *o = rgb + 3 * line, *o2 = mt->twin ? mt->twin + 3 * line : NULL;
        int tex = mt->tex != NULL, tex2 = mt->tex2 != NULL;
        if (!mt->unlit && o2 && tex && tex2) shade_run(r, mt, row, x, xe, o, o2, 0, 1, 1, 1);
        else if (!mt->unlit && !tex && !tex2) shade_run_plain(r, mt, row, x, xe, o, o2);
        else if (!mt->unlit && !o2 && tex) shade_run(r, mt, row, x, xe, o, o2, 0, 1, 0, 0);
        else shade_run(r, mt, row, x, xe, o, o2, mt->unlit, tex, o2 != NULL, tex2);
      }
      x = xe;
    }
  }
}

static void project_pos(const sim_soft *s, const soft_cam *cam, const soft_vtx *p, soft_svtx *o) {
  double iw = 1.0 / -(double)p->z;
  o->sx = 0.5 * s->w + cam->f * (double)p->x * iw;
  o->sy = 0.5 * s->h + cam->f * (double)p->y * iw;
  o->iw = (float)iw;
}

static void project_attr(const soft_vtx *p, soft_svtx *o) {
  float fiw = o->iw;
  o->a[0] = p->r * fiw, o->a[1] = p->g * fiw, o->a[2] = p->b * fiw;
  o->a[3] = p->u * fiw, o->a[4] = p->v * fiw;
}

static void project(const sim_soft *s, const soft_cam *cam, const soft_vtx *p, soft_svtx *o) {
  project_pos(s, cam, p, o);
  project_attr(p, o);
}

static soft_vtx lerp_vtx(const soft_vtx *p, const soft_vtx *q, float t) {
  soft_vtx o;
  const float *a = &p->x, *b = &q->x;
  float *d = &o.x;
  for (int k = 0; k < 8; k++) d[k] = a[k] + t * (b[k] - a[k]);
  return o;
}

/* mip level of a triangle: texels per pixel (areas) halved per level */
static int tri_level(const soft_tex *t, const soft_vtx *p[3], const soft_svtx sv[3]) {
  if (!t) return 0;
  double du1 = p[1]->u - p[0]->u, dv1 = p[1]->v - p[0]->v, du2 = p[2]->u - p[0]->u,
         dv2 = p[2]->v - p[0]->v;
  double ta = fabs(du1 * dv2 - dv1 * du2) * t->w[0] * t->h[0];
  double sa = fabs((sv[1].sx - sv[0].sx) * (sv[2].sy - sv[0].sy) -
                   (sv[1].sy - sv[0].sy) * (sv[2].sx - sv[0].sx));
  int l = 0;
  if (!(sa > 0)) return t->levels - 1;
  double r = ta / sa;
  while (r > 2.0 && l + 1 < t->levels) r *= 0.25, l++;
  return l;
}

/* a triangle in the camera frame: near-plane clipping, projection, raster */
static void draw_tri(sim_soft *s, const soft_cam *cam, const soft_vtx *p0, const soft_vtx *p1,
                     const soft_vtx *p2, const soft_mat *mt) {
  const soft_vtx *in[3] = {p0, p1, p2};
  float zn = (float)-cam->znear;
  int inside = (p0->z <= zn) + (p1->z <= zn) + (p2->z <= zn);
  if (inside == 0) return;
  soft_vtx poly[4];
  int n = 0;
  if (inside == 3) {
    poly[0] = *p0, poly[1] = *p1, poly[2] = *p2, n = 3;
  } else {
    for (int i = 0; i < 3; i++) {
      const soft_vtx *a = in[i], *b = in[(i + 1) % 3];
      int ia = a->z <= zn, ib = b->z <= zn;
      if (ia) poly[n++] = *a;
      if (ia != ib) poly[n++] = lerp_vtx(a, b, (zn - a->z) / (b->z - a->z));
    }
  }
  soft_svtx sv[4];
  for (int i = 0; i < n; i++) project(s, cam, &poly[i], &sv[i]);
  for (int i = 1; i + 1 < n; i++) {
    const soft_vtx *tp[3] = {&poly[0], &poly[i], &poly[i + 1]};
    soft_svtx ts[3] = {sv[0], sv[i], sv[i + 1]};
    if (!raster(s, &ts[0], &ts[1], &ts[2])) continue;
    int lv[2] = {tri_level(mt->tex, tp, ts), tri_level(mt->tex2, tp, ts)};
    rec_commit(s, &ts[0], &ts[1], &ts[2], mt, lv);
  }
}

static int culled(const soft_cam *cam, const double c[3], double r) {
  if (r <= 0) return 0;
  if (c[2] - r > -cam->znear) return 1;
  double nx = 1.0 / sqrt(1.0 + cam->tanx * cam->tanx), ny = 1.0 / sqrt(1.0 + cam->tany * cam->tany);
  /* side planes through the eye: |x| <= -z tanx, |y| <= -z tany */
  if ((c[0] + c[2] * cam->tanx) * nx > r || (-c[0] + c[2] * cam->tanx) * nx > r) return 1;
  if ((c[1] + c[2] * cam->tany) * ny > r || (-c[1] + c[2] * cam->tany) * ny > r) return 1;
  return 0;
}

static void geom_material(const mjModel *m, sim_soft *s, int g, const sim_soft_view *v,
                          uint8_t *twin, soft_mat *mt) {
  memset(mt, 0, sizeof *mt);
  int mat = m->geom_matid[g];
  const float *gr = m->geom_rgba + 4 * g;
  int dflt = gr[0] == 0.5f && gr[1] == 0.5f && gr[2] == 0.5f && gr[3] == 1.0f;
  const float *rgba = mat >= 0 && dflt ? m->mat_rgba + 4 * mat : gr;
  memcpy(mt->rgba, rgba, sizeof mt->rgba);
  mt->spec = mat >= 0 ? m->mat_specular[mat] : 0.5f;
  mt->shin = (mat >= 0 ? m->mat_shininess[mat] : 0.5f) * 128.0f;
  mt->emis = mat >= 0 ? m->mat_emission[mat] : 0.0f;
  mt->shin_pow = v->mode == SIM_SOFT_LIT ? pow_table(s, mt->shin) : NULL;
  int tid = mat >= 0 ? m->mat_texid[mat] : -1;
  mt->tex = tid >= 0 && s->tex[tid].rgb ? &s->tex[tid] : NULL;
  mt->unlit = v->mode != SIM_SOFT_LIT;
  mt->id = g;
  if (v->mode == SIM_SOFT_UNLIT) {
    if (!(v->tex_geom && v->tex_geom[g])) mt->tex = NULL;
    for (int k = 0; k < 3; k++) mt->flat[k] = v->flat_rgb[k] / 255.0f;
  }
  if (v->mode == SIM_SOFT_LIT && twin) {
    int t2 = v->twin_tex ? v->twin_tex[g] : -1;
    mt->twin = twin;
    mt->tex2 = t2 >= 0 && t2 < s->ntex && s->tex[t2].rgb ? &s->tex[t2] : NULL;
    memcpy(mt->flat2, v->flat_rgb, 3);
  }
}

/* what the vertices of one geom are lit with */
typedef struct geom_pass {
  sim_soft *s;
  const soft_cam *cam;
  const soft_shape *sh;
  const soft_mat *mt;
  const soft_light *L;
  int nl;
  sim_soft_mode mode;
  const float *M; /* camera from geom rotation, row-major */
} geom_pass;

/* vertex i's colour (once per geom and view), and its attributes over w
 * when it is in front of the near plane */
static void light_at(const geom_pass *g, int i) {
  sim_soft *s = g->s;
  if (s->lit[i] == 2) return;
  s->lit[i] = 2;
  soft_vtx *o = &s->vtx[i];
  if (g->mode == SIM_SOFT_LIT) {
    const float *n = g->sh->nrm + 3 * i, *M = g->M;
    float nn[3], q[3] = {o->x, o->y, o->z}, col[3];
    for (int r = 0; r < 3; r++) nn[r] = M[3 * r] * n[0] + M[3 * r + 1] * n[1] + M[3 * r + 2] * n[2];
    float len = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    if (len > 0) {
      float il = 1.0f / len;
      nn[0] *= il, nn[1] *= il, nn[2] *= il;
    }
    light_vertex(g->L, g->nl, g->mt, q, nn, col);
    o->r = col[0], o->g = col[1], o->b = col[2];
  } else {
    o->r = o->g = o->b = 1.0f;
  }
  if (o->z <= (float)-g->cam->znear) project_attr(o, &s->sv[i]);
}

/* vertex i in the camera frame (once per geom and view) */
static void place_at(const geom_pass *g, int i, const float t[3]) {
  sim_soft *s = g->s;
  if (s->lit[i]) return;
  int pi = g->sh->pid[i];
  float *q = s->pcam + 3 * pi;
  double *sc = s->pscr + 3 * pi;
  float zn = (float)-g->cam->znear;
  if (!s->pdone[pi]) {
    const float *p = g->sh->pos + 3 * i, *M = g->M;
    q[0] = M[0] * p[0] + M[1] * p[1] + M[2] * p[2] + t[0];
    q[1] = M[3] * p[0] + M[4] * p[1] + M[5] * p[2] + t[1];
    q[2] = M[6] * p[0] + M[7] * p[1] + M[8] * p[2] + t[2];
    if (q[2] <= zn) {
      soft_vtx tmp = {.x = q[0], .y = q[1], .z = q[2]};
      soft_svtx sv;
      project_pos(s, g->cam, &tmp, &sv);
      sc[0] = sv.sx, sc[1] = sv.sy, sc[2] = sv.iw;
    }
    s->pdone[pi] = 1;
  }
  soft_vtx *o = &s->vtx[i];
  o->x = q[0], o->y = q[1], o->z = q[2];
  o->u = g->sh->uv ? g->sh->uv[2 * i] : 0.0f, o->v = g->sh->uv ? g->sh->uv[2 * i + 1] : 0.0f;
  o->r = o->g = o->b = 0.0f;
  s->lit[i] = 1;
  if (o->z <= zn) s->sv[i].sx = sc[0], s->sv[i].sy = sc[1], s->sv[i].iw = (float)sc[2];
}

void sim_soft_render(sim_soft *s, const mjModel *m, const mjData *d, const sim_soft_view *v,
                     uint8_t *rgb, uint8_t *twin, int *ids) {
  size_t npx = (size_t)s->w * (size_t)s->h;
  memset(s->depth, 0, sizeof(float) * npx);
  for (size_t i = 0; i < npx; i++) s->tri[i] = -1;
  s->nrec = 0;
  int nmat = 0;
  if (rgb) memset(rgb, 0, 3 * npx);
  if (twin && rgb && v->mode == SIM_SOFT_LIT) memset(twin, 0, 3 * npx);
  else twin = NULL;
  if (ids)
    for (size_t i = 0; i < npx; i++) ids[i] = -1;
  soft_cam cam;
  for (int k = 0; k < 9; k++) cam.R[k] = d->cam_xmat[9 * v->cam + k];
  for (int k = 0; k < 3; k++) cam.p[k] = d->cam_xpos[3 * v->cam + k];
  cam.znear = m->vis.map.znear * m->stat.extent;
  double hs, hc;
  soft_sincos(0.5 * m->cam_fovy[v->cam] * M_PI / 180.0, &hs, &hc);
  cam.tany = hs / hc;
  cam.tanx = cam.tany * s->w / s->h;
  cam.f = 0.5 * s->h / cam.tany;
  /* lights in the camera frame: the headlight (shining along the view),
   * then the model's active lights */
  soft_light L[1 + 8];
  int nl = 0;
  if (v->mode == SIM_SOFT_LIT) {
    if (m->vis.headlight.active) {
      soft_light *l = &L[nl++];
      memset(l, 0, sizeof *l);
      l->directional = 1;
      l->dir[2] = -1;
      for (int k = 0; k < 3; k++)
        l->amb[k] = m->vis.headlight.ambient[k], l->dif[k] = m->vis.headlight.diffuse[k],
        l->spc[k] = m->vis.headlight.specular[k];
      l->att[0] = 1;
    }
    for (int i = 0; i < m->nlight && nl < 9; i++) {
      if (!m->light_active[i]) continue;
      soft_light *l = &L[nl++];
      const double *lp = d->light_xpos + 3 * i, *ld = d->light_xdir + 3 * i;
      double dp[3] = {lp[0] - cam.p[0], lp[1] - cam.p[1], lp[2] - cam.p[2]}, dl = 0;
      for (int r = 0; r < 3; r++) dl += ld[r] * ld[r];
      dl = dl > 0 ? 1.0 / sqrt(dl) : 0.0;
      for (int c = 0; c < 3; c++) {
        l->pos[c] = (float)(cam.R[c] * dp[0] + cam.R[3 + c] * dp[1] + cam.R[6 + c] * dp[2]);
        l->dir[c] = (float)((cam.R[c] * ld[0] + cam.R[3 + c] * ld[1] + cam.R[6 + c] * ld[2]) * dl);
      }
      l->directional = m->light_directional[i];
      for (int k = 0; k < 3; k++)
        l->amb[k] = m->light_ambient[3 * i + k], l->dif[k] = m->light_diffuse[3 * i + k],
        l->spc[k] = m->light_specular[3 * i + k], l->att[k] = m->light_attenuation[3 * i + k];
      double cs, cc;
      soft_sincos(m->light_cutoff[i] * M_PI / 180.0, &cs, &cc);
      l->cos_cut = (float)cc;
      l->expo = m->light_exponent[i];
      if (l->directional) l->att[0] = 1, l->att[1] = l->att[2] = 0, l->cos_cut = -2, l->expo = 0;
      l->spot_pow = pow_table(s, l->expo);
    }
  }
  /* nearest geoms first (their centres' depth), so hidden surfaces fail
   * the depth test before any shading */
  for (int g = 0; g < m->ngeom; g++) {
    const double *xg = d->geom_xpos + 3 * g;
    double z = 0;
    for (int r = 0; r < 3; r++) z += cam.R[3 * r + 2] * (xg[r] - cam.p[r]);
    int k = g;
    while (k > 0 && s->key[k - 1] < z)
      s->order[k] = s->order[k - 1], s->key[k] = s->key[k - 1], k--;
    s->order[k] = g, s->key[k] = z;
  }
  for (int gi = 0; gi < m->ngeom; gi++) {
    int g = s->order[gi];
    const soft_shape *sh = &s->shape[g];
    int grp = m->geom_group[g];
    if (sh->nt == 0 || grp < 0 || grp >= 6 || !v->groups[grp]) continue;
    if (v->only_geom >= 0 && g != v->only_geom) continue;
    soft_mat *mp = &s->mats[nmat];
    geom_material(m, s, g, v, twin, mp);
    if (mp->rgba[3] == 0) continue;
    nmat++;
    /* camera from geom: M = R_c^T R_g, t = R_c^T (x_g - p_c) */
    const double *Rg = d->geom_xmat + 9 * g, *xg = d->geom_xpos + 3 * g;
    double M[9], t[3], dx[3] = {xg[0] - cam.p[0], xg[1] - cam.p[1], xg[2] - cam.p[2]};
    for (int r = 0; r < 3; r++) {
      t[r] = cam.R[r] * dx[0] + cam.R[3 + r] * dx[1] + cam.R[6 + r] * dx[2];
      for (int c = 0; c < 3; c++)
        M[3 * r + c] = cam.R[r] * Rg[c] + cam.R[3 + r] * Rg[3 + c] + cam.R[6 + r] * Rg[6 + c];
    }
    if (culled(&cam, t, m->geom_rbound[g])) continue;
    float Mf[9], tf[3];
    for (int k = 0; k < 9; k++) Mf[k] = (float)M[k];
    for (int k = 0; k < 3; k++) tf[k] = (float)t[k];
    geom_pass gp = {s, &cam, sh, mp, L, nl, v->mode, Mf};
    float zn = (float)-cam.znear;
    memset(s->lit, 0, (size_t)sh->nv);
    memset(s->pdone, 0, (size_t)sh->np);
    /* the camera in the geom's frame: R_g^T (p_c - x_g) */
    float eye[3];
    for (int c = 0; c < 3; c++)
      eye[c] = (float)(Rg[c] * -dx[0] + Rg[3 + c] * -dx[1] + Rg[6 + c] * -dx[2]);
    if (!sh->uv) mp->tex = NULL, mp->tex2 = NULL;
    for (int i = 0; i < sh->nt; i++) {
      const int *tr = sh->tri + 3 * i;
      const float *pl = sh->plane + 4 * i;
      if (pl[0] * eye[0] + pl[1] * eye[1] + pl[2] * eye[2] <= pl[3]) continue; /* back face */
      for (int k = 0; k < 3; k++) place_at(&gp, tr[k], tf);
      const soft_vtx *p0 = &s->vtx[tr[0]], *p1 = &s->vtx[tr[1]], *p2 = &s->vtx[tr[2]];
      int in = (p0->z <= zn) + (p1->z <= zn) + (p2->z <= zn);
      if (in == 0) continue;
      if (in < 3) {
        for (int k = 0; k < 3; k++) light_at(&gp, tr[k]);
        draw_tri(s, &cam, p0, p1, p2, mp);
        continue;
      }
      /* wholly in front: back faces and triangles off the image go before
       * any lighting */
      const soft_svtx *a = &s->sv[tr[0]], *b = &s->sv[tr[1]], *c = &s->sv[tr[2]];
      double area = (b->sx - a->sx) * (c->sy - a->sy) - (b->sy - a->sy) * (c->sx - a->sx);
      int box[4];
      if (!(area > 0) || !tri_box(s, a, b, c, box)) continue;
      const soft_vtx *tp[3] = {p0, p1, p2};
      const float *n0 = sh->nrm + 3 * tr[0];
      if ((box[1] - box[0] + 1) * (box[3] - box[2] + 1) <= 2 &&
          memcmp(n0, sh->nrm + 3 * tr[1], 3 * sizeof(float)) == 0 &&
          memcmp(n0, sh->nrm + 3 * tr[2], 3 * sizeof(float)) == 0) {
        /* a flat triangle over at most two pixel centres: lit once, at its
         * first corner (across it the light changes by far less than a
         * grey level), and only when it is in front */
        if (!raster_in(s, a, b, c, area, box)) continue;
        light_at(&gp, tr[0]);
        soft_svtx ts[3] = {*a, *b, *c};
        for (int k = 1; k < 3; k++) {
          float iw = ts[k].iw;
          ts[k].a[0] = p0->r * iw, ts[k].a[1] = p0->g * iw, ts[k].a[2] = p0->b * iw;
          ts[k].a[3] = tp[k]->u * iw, ts[k].a[4] = tp[k]->v * iw;
        }
        int lv[2] = {tri_level(mp->tex, tp, ts), tri_level(mp->tex2, tp, ts)};
        rec_commit(s, &ts[0], &ts[1], &ts[2], mp, lv);
        continue;
      }
      /* lit only when it won pixels */
      if (!raster_in(s, a, b, c, area, box)) continue;
      for (int k = 0; k < 3; k++) light_at(&gp, tr[k]);
      soft_svtx ts[3] = {*a, *b, *c};
      int lv[2] = {tri_level(mp->tex, tp, ts), tri_level(mp->tex2, tp, ts)};
      rec_commit(s, a, b, c, mp, lv);
    }
  }
  resolve(s, v->mode == SIM_SOFT_SEGMENT ? NULL : rgb, ids);
}
