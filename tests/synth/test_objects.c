/* Procedural objects and temperature fields of the virtual rig: closed,
 * outward-wound meshes with packed UV islands, triangle counts that follow
 * the target, real-world sizes, and fields with the structure the paper
 * describes (hot cup body above handle and rim, iced can colder at the
 * bottom, phone warm at the battery). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hearth/mesh.h"
#include "synth/synth_object.h"
#include "test_util.h"

/* ---- independent mesh checks ---------------------------------------------- */

typedef struct vkey {
  float p[3];
  uint32_t i;
} vkey;

static int cmp_vkey(const void *a, const void *b) {
  const vkey *x = a, *y = b;
  for (int k = 0; k < 3; k++) {
    if (x->p[k] < y->p[k]) return -1;
    if (x->p[k] > y->p[k]) return 1;
  }
  return (x->i > y->i) - (x->i < y->i);
}

static int cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

/* weld by exact position; then every directed edge must occur once and its
 * reverse once: a closed, consistently oriented surface. Returns the number
 * of bad edges. */
static size_t bad_edges(const hearth_mesh *m) {
  size_t nv = m->n_vertices, nt = m->n_triangles;
  vkey *k = malloc(nv * sizeof *k);
  uint32_t *canon = malloc(nv * sizeof *canon);
  uint64_t *e = malloc(3 * nt * sizeof *e);
  for (size_t v = 0; v < nv; v++) {
    memcpy(k[v].p, m->positions + 3 * v, sizeof k[v].p);
    k[v].i = (uint32_t)v;
  }
  qsort(k, nv, sizeof *k, cmp_vkey);
  uint32_t id = 0;
  for (size_t v = 0; v < nv; v++) {
    if (v > 0 && memcmp(k[v].p, k[v - 1].p, sizeof k[v].p) != 0) id++;
    canon[k[v].i] = id;
  }
  size_t bad = 0;
  for (size_t t = 0; t < nt; t++)
    for (int c = 0; c < 3; c++) {
      uint64_t a = canon[m->indices[3 * t + c]], b = canon[m->indices[3 * t + (c + 1) % 3]];
      if (a == b) bad++;
      e[3 * t + c] = a << 32 | b;
    }
  qsort(e, 3 * nt, sizeof *e, cmp_u64);
  for (size_t i = 0; i < 3 * nt; i++) {
    if (i > 0 && e[i] == e[i - 1]) bad++;
    uint64_t rev = (e[i] & 0xffffffffULL) << 32 | e[i] >> 32;
    if (!bsearch(&rev, e, 3 * nt, sizeof *e, cmp_u64)) bad++;
  }
  free(k);
  free(canon);
  free(e);
  return bad;
}

static double signed_volume(const hearth_mesh *m) {
  double v = 0;
  for (size_t t = 0; t < m->n_triangles; t++) {
    const float *a = m->positions + 3 * m->indices[3 * t];
    const float *b = m->positions + 3 * m->indices[3 * t + 1];
    const float *c = m->positions + 3 * m->indices[3 * t + 2];
    v += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
          a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
          a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) /
         6.0;
  }
  return v;
}

/* rasterise every UV triangle at R x R (texel centres strictly inside);
 * count texels claimed by two triangles (overlap or fold) */
static size_t uv_overlaps(const hearth_mesh *m, size_t R) {
  uint32_t *own = malloc(R * R * sizeof *own);
  for (size_t i = 0; i < R * R; i++) own[i] = UINT32_MAX;
  size_t over = 0;
  for (size_t t = 0; t < m->n_triangles; t++) {
    double u[3], v[3];
    for (int k = 0; k < 3; k++) {
      u[k] = m->uvs[2 * m->indices[3 * t + k]] * (double)R;
      v[k] = m->uvs[2 * m->indices[3 * t + k] + 1] * (double)R;
    }
    double area = (u[1] - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (v[1] - v[0]);
    if (fabs(area) < 1e-14) continue;
    long c0 = (long)floor(fmin(u[0], fmin(u[1], u[2]))),
         c1 = (long)ceil(fmax(u[0], fmax(u[1], u[2])));
    long r0 = (long)floor(fmin(v[0], fmin(v[1], v[2]))),
         r1 = (long)ceil(fmax(v[0], fmax(v[1], v[2])));
    for (long r = r0 < 0 ? 0 : r0; r <= r1 && r < (long)R; r++)
      for (long c = c0 < 0 ? 0 : c0; c <= c1 && c < (long)R; c++) {
        double px = c + 0.5, py = r + 0.5, w[3];
        for (int k = 0; k < 3; k++) {
          int a = (k + 1) % 3, b = (k + 2) % 3;
          w[k] = ((u[b] - u[a]) * (py - v[a]) - (v[b] - v[a]) * (px - u[a])) / area;
        }
        if (w[0] > 1e-6 && w[1] > 1e-6 && w[2] > 1e-6) {
          if (own[r * R + c] != UINT32_MAX) over++;
          own[r * R + c] = (uint32_t)t;
        }
      }
  }
  free(own);
  return over;
}

/* expected sizes: {height lo, hi, largest horizontal extent lo, hi} (m) */
typedef struct size_rule {
  const char *cat;
  double hlo, hhi, wlo, whi;
} size_rule;
static const size_rule k_sizes[] = {
    {"cup", 0.088, 0.102, 0.10, 0.14},           {"canned_drink", 0.118, 0.124, 0.064, 0.068},
    {"bottled_drink", 0.19, 0.24, 0.058, 0.070}, {"orange", 0.063, 0.082, 0.070, 0.086},
    {"smartphone", 0.007, 0.0095, 0.144, 0.161}, {"sponge", 0.024, 0.04, 0.099, 0.151},
    {"electric_kettle", 0.20, 0.27, 0.19, 0.30}, {"pot", 0.09, 0.20, 0.24, 0.33},
    {"mouse", 0.03, 0.041, 0.099, 0.121},        {"eraser", 0.009, 0.014, 0.044, 0.066},
    {"laptop", 0.014, 0.020, 0.29, 0.35},        {"wallet", 0.011, 0.021, 0.10, 0.125},
    {"tissue", 0.07, 0.1, 0.21, 0.25},           {"glasses_case", 0.03, 0.05, 0.15, 0.175},
    {"pillow", 0.09, 0.15, 0.44, 0.56},          {"cushion", 0.08, 0.14, 0.37, 0.46},
    {"storage_bag", 0.01, 0.026, 0.16, 0.28},    {"headset", 0.07, 0.2, 0.15, 0.26},
};

static void check_object(const char *cat, size_t target) {
  hearth_err err = {0};
  synth_object o;
  CHECK_OK(synth_object_make(cat, 42, target, 256, &o, &err), &err);
  if (err.status) return;
  const hearth_mesh *m = &o.mesh;
  CHECK_OK(hearth_mesh_validate(m, cat, &err), &err);
  double ratio = (double)m->n_triangles / (double)target;
  CHECK_MSG(ratio > 0.75 && ratio < 1.25, "%s: %zu triangles for target %zu", cat, m->n_triangles,
            target);
  CHECK(strcmp(o.category, cat) == 0);
  CHECK(o.n_parts >= 1 && o.n_parts <= SYNTH_MAX_PARTS);
  for (size_t t = 0; t < m->n_triangles; t++)
    if (o.part_of_tri[t] >= o.n_parts) {
      CHECK_MSG(0, "%s: triangle %zu has part %d", cat, t, o.part_of_tri[t]);
      break;
    }
  int uv_ok = 1;
  for (size_t i = 0; i < 2 * m->n_vertices; i++)
    if (!(m->uvs[i] >= 0 && m->uvs[i] <= 1)) uv_ok = 0;
  CHECK_MSG(uv_ok, "%s: UVs outside [0,1]", cat);

  /* islands: several, few, each a connected patch; bounding boxes apart by
   * at least 8 texels at 1024 */
  uint32_t *isl = malloc(m->n_triangles * sizeof *isl), ni = 0;
  CHECK_OK(hearth_uv_islands(m, isl, &ni, &err), &err);
  CHECK_MSG(ni > 1 && ni < 40, "%s: %u islands", cat, ni);
  if (ni > 0 && ni < 1000) {
    double(*bb)[4] = malloc(ni * sizeof *bb);
    for (uint32_t i = 0; i < ni; i++) bb[i][0] = bb[i][1] = 2, bb[i][2] = bb[i][3] = -1;
    for (size_t t = 0; t < m->n_triangles; t++)
      for (int k = 0; k < 3; k++) {
        const float *uv = m->uvs + 2 * m->indices[3 * t + k];
        double *b = bb[isl[t]];
        b[0] = fmin(b[0], uv[0]);
        b[1] = fmin(b[1], uv[1]);
        b[2] = fmax(b[2], uv[0]);
        b[3] = fmax(b[3], uv[1]);
      }
    double gut = 8.0 / 1024.0;
    size_t close = 0;
    for (uint32_t i = 0; i < ni; i++)
      for (uint32_t j = i + 1; j < ni; j++) {
        double dx = fmax(bb[j][0] - bb[i][2], bb[i][0] - bb[j][2]);
        double dy = fmax(bb[j][1] - bb[i][3], bb[i][1] - bb[j][3]);
        if (dx < gut && dy < gut) close++;
      }
    CHECK_MSG(close == 0, "%s: %zu island pairs closer than 8 texels", cat, close);
    free(bb);
  }
  free(isl);
  size_t ov = uv_overlaps(m, 512);
  CHECK_MSG(ov == 0, "%s: %zu texels covered twice at 512", cat, ov);

  /* closed and outward */
  size_t be = bad_edges(m);
  CHECK_MSG(be == 0, "%s: %zu edges not shared by exactly two opposite triangles", cat, be);
  double vol = signed_volume(m);
  CHECK_MSG(vol > 0, "%s: signed volume %g", cat, vol);

  /* sizes */
  double lo[3], hi[3];
  hearth_mesh_bounds(m, lo, hi);
  CHECK_NEAR(lo[2], 0, 1e-6);
  CHECK_NEAR(o.height, hi[2], 1e-6);
  double wmax = fmax(hi[0] - lo[0], hi[1] - lo[1]);
  for (size_t i = 0; i < sizeof k_sizes / sizeof k_sizes[0]; i++)
    if (strcmp(k_sizes[i].cat, cat) == 0) {
      CHECK_MSG(hi[2] >= k_sizes[i].hlo && hi[2] <= k_sizes[i].hhi, "%s: height %g", cat, hi[2]);
      CHECK_MSG(wmax >= k_sizes[i].wlo && wmax <= k_sizes[i].whi, "%s: width %g", cat, wmax);
    }
  CHECK(o.albedo.width == 256 && o.albedo.channels == 3 && o.albedo.type == HEARTH_PIX_U8);

  /* fields: neutral near ambient; every state accepted, finite, smooth in a
   * part (the same value at a shared vertex from either triangle) */
  static const char *const states[] = {"neutral", "hot", "warm", "iced", "used"};
  for (int s = 0; s < 5; s++) {
    synth_field f;
    CHECK_OK(synth_field_make(&o, states[s], 7, 22.0, &f, &err), &err);
    double tmin = 1e9, tmax = -1e9;
    for (size_t t = 0; t < m->n_triangles; t += 7) {
      const float *a = m->positions + 3 * m->indices[3 * t];
      double p[3] = {a[0], a[1], a[2]};
      double v = synth_field_eval(&f, &o, (uint32_t)t, p);
      tmin = fmin(tmin, v);
      tmax = fmax(tmax, v);
    }
    CHECK_MSG(isfinite(tmin) && isfinite(tmax) && tmin > -5 && tmax < 100, "%s/%s: range %g..%g",
              cat, states[s], tmin, tmax);
    if (s == 0) CHECK_MSG(tmin > 21 && tmax < 23, "%s/neutral: %g..%g", cat, tmin, tmax);
  }
  synth_object_free(&o);
}

/* mean field over triangle centroids that pass a filter */
typedef int (*tri_filter)(const synth_object *o, size_t t, const double c[3], void *ctx);
static double mean_field(const synth_field *f, const synth_object *o, tri_filter flt, void *ctx,
                         double *vmax, size_t *n_out) {
  double s = 0, mx = -1e9;
  size_t n = 0;
  for (size_t t = 0; t < o->mesh.n_triangles; t++) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++)
      for (int d = 0; d < 3; d++) c[d] += o->mesh.positions[3 * o->mesh.indices[3 * t + k] + d] / 3;
    if (!flt(o, t, c, ctx)) continue;
    double v = synth_field_eval(f, o, (uint32_t)t, c);
    s += v;
    mx = fmax(mx, v);
    n++;
  }
  if (vmax) *vmax = mx;
  if (n_out) *n_out = n;
  return n ? s / (double)n : NAN;
}

static int part_is(const synth_object *o, size_t t, const char *name) {
  return strcmp(o->part_names[o->part_of_tri[t]], name) == 0;
}

typedef struct zsel {
  const char *part;
  double zlo, zhi;
} zsel;
static int f_part_z(const synth_object *o, size_t t, const double c[3], void *ctx) {
  const zsel *z = ctx;
  return part_is(o, t, z->part) && c[2] >= z->zlo && c[2] <= z->zhi;
}

static void check_fields(void) {
  hearth_err err = {0};
  synth_object cup, can, phone;
  CHECK_OK(synth_object_make("cup", 3, 20000, 64, &cup, &err), &err);
  CHECK_OK(synth_object_make("canned_drink", 3, 8000, 64, &can, &err), &err);
  CHECK_OK(synth_object_make("smartphone", 3, 8000, 64, &phone, &err), &err);
  if (err.status) return;

  /* hot cup: below the liquid line hot, above it and the handle cooler */
  synth_field f;
  CHECK_OK(synth_field_make(&cup, "hot", 11, 22.0, &f, &err), &err);
  double H = cup.height, zf = cup.fill_level * H;
  CHECK(zf > 0.7 * H && zf < 0.92 * H);
  zsel below = {"body", 0.25 * H, zf - 0.01}, above = {"body", zf + 0.006, H};
  zsel handle = {"handle", -1, 1}, inner_lo = {"inner", 0.01, zf - 0.01};
  double t_below = mean_field(&f, &cup, f_part_z, &below, NULL, NULL);
  double t_above = mean_field(&f, &cup, f_part_z, &above, NULL, NULL);
  double t_handle_max, t_handle = mean_field(&f, &cup, f_part_z, &handle, &t_handle_max, NULL);
  double t_inner = mean_field(&f, &cup, f_part_z, &inner_lo, NULL, NULL);
  CHECK_MSG(t_below > 50 && t_below < 65, "hot cup body %g", t_below);
  CHECK_MSG(t_below - t_above >= 10, "hot cup body below %g, above %g", t_below, t_above);
  CHECK_MSG(t_below > t_handle_max + 10, "hot cup body %g, handle max %g", t_below, t_handle_max);
  CHECK_MSG(t_handle > 28 && t_handle < 39, "hot cup handle %g", t_handle);
  CHECK_MSG(t_inner > 50, "hot cup inner wall below the line %g", t_inner);

  /* the liquid line is sharp but smooth: no jump between samples 0.2 mm apart */
  double maxstep = 0;
  uint32_t tb = 0;
  for (size_t t = 0; t < cup.mesh.n_triangles; t++)
    if (part_is(&cup, t, "body")) {
      tb = (uint32_t)t;
      break;
    }
  for (double z = 0.01; z < H - 0.003; z += 0.0002) {
    double p0[3] = {0.04, 0, z}, p1[3] = {0.04, 0, z + 0.0002};
    maxstep = fmax(maxstep,
                   fabs(synth_field_eval(&f, &cup, tb, p1) - synth_field_eval(&f, &cup, tb, p0)));
  }
  CHECK_MSG(maxstep < 2.0 && maxstep > 0.1, "hot cup: largest step over 0.2 mm %g", maxstep);

  /* determinism: same seed, same values; another seed, other values */
  synth_field g, h;
  CHECK_OK(synth_field_make(&cup, "hot", 11, 22.0, &g, &err), &err);
  CHECK_OK(synth_field_make(&cup, "hot", 12, 22.0, &h, &err), &err);
  double p[3] = {0.03, 0.02, 0.05};
  CHECK(synth_field_eval(&f, &cup, tb, p) == synth_field_eval(&g, &cup, tb, p));
  CHECK(synth_field_eval(&f, &cup, tb, p) != synth_field_eval(&h, &cup, tb, p));

  /* iced can: bottom colder than the top, both well below ambient */
  CHECK_OK(synth_field_make(&can, "iced", 5, 22.0, &f, &err), &err);
  zsel lo = {"body", 0, 0.2 * can.height}, hi = {"body", 0.8 * can.height, 1};
  double t_lo = mean_field(&f, &can, f_part_z, &lo, NULL, NULL);
  double t_hi = mean_field(&f, &can, f_part_z, &hi, NULL, NULL);
  CHECK_MSG(t_lo < t_hi - 2 && t_lo > 0 && t_hi < 13, "iced can %g .. %g", t_lo, t_hi);

  /* warm phone: battery on the back warmer than the frame */
  CHECK_OK(synth_field_make(&phone, "warm", 5, 22.0, &f, &err), &err);
  zsel back = {"back", -1, 1}, frame = {"frame", -1, 1};
  double back_max, t_frame = mean_field(&f, &phone, f_part_z, &frame, NULL, NULL);
  mean_field(&f, &phone, f_part_z, &back, &back_max, NULL);
  CHECK_MSG(back_max > 35 && back_max > t_frame + 6, "warm phone back %g, frame %g", back_max,
            t_frame);

  /* bad state names are refused with the name in the message */
  CHECK(synth_field_make(&cup, "boiling", 1, 22.0, &f, &err) == HEARTH_E_ARG);
  CHECK(strstr(err.msg, "boiling") != NULL);
  synth_object_free(&cup);
  synth_object_free(&can);
  synth_object_free(&phone);
}

static void check_misc(void) {
  hearth_err err = {0};
  synth_object o, o2;
  /* same seed, same bytes */
  CHECK_OK(synth_object_make("bottled_drink", 9, 5000, 64, &o, &err), &err);
  CHECK_OK(synth_object_make("bottled_drink", 9, 5000, 64, &o2, &err), &err);
  CHECK(o.mesh.n_vertices == o2.mesh.n_vertices && o.mesh.n_triangles == o2.mesh.n_triangles);
  if (o.mesh.n_vertices == o2.mesh.n_vertices) {
    CHECK(memcmp(o.mesh.positions, o2.mesh.positions, 12 * o.mesh.n_vertices) == 0);
    CHECK(memcmp(o.mesh.uvs, o2.mesh.uvs, 8 * o.mesh.n_vertices) == 0);
    CHECK(memcmp(o.albedo.data, o2.albedo.data, 64 * 64 * 3) == 0);
  }
  synth_object_free(&o2);
  /* and whatever the thread count */
  setenv("HEARTH_THREADS", "1", 1);
  CHECK_OK(synth_object_make("bottled_drink", 9, 5000, 64, &o2, &err), &err);
  unsetenv("HEARTH_THREADS");
  CHECK(memcmp(o.albedo.data, o2.albedo.data, 64 * 64 * 3) == 0);
  synth_object_free(&o2);

  /* wrapping a mesh: rescaled to the size, on the axis, resting on z = 0 */
  synth_object w;
  CHECK_OK(synth_object_from_mesh(&o.mesh, 0.5, "cup", 32, &w, &err), &err);
  double lo[3], hi[3];
  hearth_mesh_bounds(&w.mesh, lo, hi);
  CHECK_NEAR(fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2])), 0.5, 1e-5);
  CHECK_NEAR(lo[2], 0, 1e-6);
  CHECK_NEAR(lo[0] + hi[0], 0, 1e-5);
  CHECK(w.n_parts == 1 && w.albedo.width == 32);
  synth_field f;
  CHECK_OK(synth_field_make(&w, "hot", 1, 22.0, &f, &err), &err);
  synth_object_free(&w);
  synth_object_free(&o);

  /* the category list and default states */
  const char *names[32], *st[4];
  size_t n = synth_object_categories(names, 32);
  CHECK(n >= 8);
  CHECK(synth_category_states("cup", st, 4) == 2 && strcmp(st[0], "neutral") == 0 &&
        strcmp(st[1], "hot") == 0);
  CHECK(synth_category_states("canned_drink", st, 4) == 2 && strcmp(st[1], "iced") == 0);
  CHECK(synth_category_states("smartphone", st, 4) == 2 && strcmp(st[1], "warm") == 0);
  CHECK(synth_category_states("eraser", st, 4) == 1);
  CHECK(synth_object_make("teapot", 1, 1000, 64, &o, &err) == HEARTH_E_ARG);
  CHECK(strstr(err.msg, "teapot") != NULL);
}

int main(void) {
  const char *names[32];
  size_t n = synth_object_categories(names, 32);
  for (size_t i = 0; i < n && i < 32; i++) {
    check_object(names[i], 1500);
    check_object(names[i], 30000);
  }
  check_fields();
  check_misc();
  TEST_MAIN_END();
}
