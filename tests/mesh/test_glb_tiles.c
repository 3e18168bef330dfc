/* The GLB reader on real-world UV conventions: islands in other texture
 * tiles folded into [0,1] (REPEAT, MIRRORED_REPEAT, CLAMP_TO_EDGE), the
 * straddling error with its counts, KHR_mesh_quantization for every
 * component type and KHR_texture_transform; then, through the command line,
 * a tiled cube synthesised and mapped to the same bytes as the plain one,
 * and maps without surface refused. Every GLB is written here. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include "glb_build.h"
#include "hearth/mesh.h"
#include "test_util.h"

/* the cube with face f's UVs moved by tiles[f] (NULL: none) */
static uint8_t *cube_glb(const int tiles[6][2], int wrap_s, int wrap_t, size_t *n) {
  double uv[CUBE_NV * 2];
  memcpy(uv, g_uv, sizeof uv);
  for (int v = 0; tiles && v < CUBE_NV; v++) {
    uv[2 * v] += tiles[v / 4][0];
    uv[2 * v + 1] += tiles[v / 4][1];
  }
  tb_glb g = {0};
  g.nv = CUBE_NV, g.nt = CUBE_NT, g.pos = g_pos, g.uv[0] = uv, g.idx = g_idx;
  g.texture = 1, g.wrap_s = wrap_s, g.wrap_t = wrap_t, g.tex_coord = -1;
  return tb_encode(&g, n);
}

static hearth_status parse(const uint8_t *f, size_t n, int require_uvs, int keep, hearth_mesh *m,
                           hearth_glb_report *rep, hearth_err *e) {
  hearth_glb_read_opts o = {0};
  o.require_uvs = require_uvs;
  o.keep_uv_tiles = keep;
  o.report = rep;
  return hearth_glb_parse(f, n, "tiles.glb", &o, m, e);
}

/* every UV of m equals the plain cube's (bit for bit) */
static int same_as_plain(const hearth_mesh *m) {
  if (m->n_vertices != CUBE_NV || !m->uvs) return 0;
  for (int i = 0; i < 2 * CUBE_NV; i++)
    if (m->uvs[i] != (float)g_uv[i]) return 0;
  return 1;
}

static void test_tiles_repeat(void) {
  static const int whole_v1[6][2] = {{0, 1}, {0, 1}, {0, 1}, {0, 1}, {0, 1}, {0, 1}};
  static const int whole_23[6][2] = {{2, -3}, {2, -3}, {2, -3}, {2, -3}, {2, -3}, {2, -3}};
  static const int per_face[6][2] = {{0, 0}, {1, 0}, {-1, 2}, {3, -1}, {0, 1}, {-2, -2}};
  const struct {
    const int (*t)[2];
    uint32_t moved;
  } cases[] = {{whole_v1, 6}, {whole_23, 6}, {per_face, 5}};
  for (size_t c = 0; c < 3; c++) {
    size_t n;
    uint8_t *f = cube_glb(cases[c].t, 0, 0, &n);
    hearth_mesh m;
    hearth_glb_report rep;
    hearth_err e = {0};
    CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
    CHECK_MSG(same_as_plain(&m), "case %zu: UVs differ from the plain cube's", c);
    CHECK_MSG(rep.uv_islands_moved == cases[c].moved, "case %zu: %u moved", c,
              rep.uv_islands_moved);
    CHECK(rep.uv_islands_mirrored == 0 && rep.uv_islands_left == 0);
    hearth_mesh_free(&m);
    /* kept as stored on request */
    CHECK_OK(parse(f, n, 1, 1, &m, &rep, &e), &e);
    CHECK(m.uvs && m.uvs[2 * 4] == (float)(g_uv[2 * 4] + cases[c].t[1][0]));
    CHECK(m.uvs && m.uvs[2 * 4 + 1] == (float)(g_uv[2 * 4 + 1] + cases[c].t[1][1]));
    CHECK(rep.uv_islands_moved == 0);
    hearth_mesh_free(&m);
    free(f);
  }
  /* the plain cube: nothing to do */
  size_t n;
  uint8_t *f = cube_glb(NULL, 0, 0, &n);
  hearth_mesh m;
  hearth_glb_report rep;
  hearth_err e = {0};
  CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
  CHECK(same_as_plain(&m) && rep.uv_islands_moved == 0);
  hearth_mesh_free(&m);
  free(f);
}

static void test_tiles_straddling(void) {
  /* face 1 moved by half a tile spans u in [0.875, 1.125]; face 2 moved by
   * a whole tile is fine */
  double uv[CUBE_NV * 2];
  memcpy(uv, g_uv, sizeof uv);
  for (int v = 4; v < 8; v++) uv[2 * v] += 0.5;
  for (int v = 8; v < 12; v++) uv[2 * v + 1] += 1.0;
  tb_glb g = {0};
  g.nv = CUBE_NV, g.nt = CUBE_NT, g.pos = g_pos, g.uv[0] = uv, g.idx = g_idx, g.tex_coord = -1;
  size_t n;
  uint8_t *f = tb_encode(&g, &n);
  hearth_mesh m;
  hearth_glb_report rep;
  hearth_err e = {0};
  hearth_status s = parse(f, n, 1, 0, &m, &rep, &e);
  CHECK_MSG(s == HEARTH_E_UNSUPPORTED, "got %s: %s", hearth_status_name(s), e.msg);
  CHECK_MSG(strstr(e.msg, "tiles.glb") && strstr(e.msg, "1 UV island spans") &&
                strstr(e.msg, "2 triangles in them, 2 crossing a tile border") &&
                strstr(e.msg, "meshes[0].primitives[0] triangle 2"),
            "message: %s", e.msg);
  CHECK(m.positions == NULL && m.n_triangles == 0);
  /* UVs not required: left as stored, the others still folded, counted */
  CHECK_OK(parse(f, n, 0, 0, &m, &rep, &e), &e);
  CHECK(rep.uv_islands_left == 1 && rep.uv_triangles_straddling == 2 && rep.uv_islands_moved == 1);
  CHECK(m.uvs && m.uvs[2 * 4] == (float)uv[2 * 4] && m.uvs[2 * 8 + 1] == (float)g_uv[2 * 8 + 1]);
  hearth_mesh_free(&m);
  free(f);

  /* an island across u = 1 whose two triangles each lie in one tile (their
   * shared diagonal on the border): it spans tiles, no triangle crosses */
  memcpy(uv, g_uv, sizeof uv);
  uv[2 * 4] = uv[2 * 6] = 1.0;
  uv[2 * 5] = 1.25;
  uv[2 * 7] = 0.75;
  f = tb_encode(&g, &n);
  s = parse(f, n, 1, 0, &m, &rep, &e);
  CHECK_MSG(s == HEARTH_E_UNSUPPORTED && strstr(e.msg, "2 triangles in them, 0 crossing"),
            "got %s: %s", hearth_status_name(s), e.msg);
  free(f);
  /* an island on the border of [0,1], within the slack, stays (also under
   * CLAMP_TO_EDGE, where moving it would be refused) */
  memcpy(uv, g_uv, sizeof uv);
  for (int v = 4; v < 8; v++)
    uv[2 * v] =
        v == 4 || v == 7 ? 1.0 - 0.25 * HEARTH_UV_TILE_SLACK : 1.0 + 0.25 * HEARTH_UV_TILE_SLACK;
  g.texture = 1, g.wrap_s = 33071, g.wrap_t = 33071;
  f = tb_encode(&g, &n);
  CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
  CHECK(rep.uv_islands_moved == 0 && m.uvs && m.uvs[2 * 5] == (float)uv[2 * 5]);
  hearth_mesh_free(&m);
  free(f);
  g.texture = 0, g.wrap_s = g.wrap_t = 0;
  /* within the slack past a border: no move, no error */
  memcpy(uv, g_uv, sizeof uv);
  uv[2 * 5] = uv[2 * 6] = 1.0 + 0.5 * HEARTH_UV_TILE_SLACK;
  f = tb_encode(&g, &n);
  CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
  CHECK(rep.uv_islands_moved == 0 && m.uvs && m.uvs[2 * 5] == (float)uv[2 * 5]);
  hearth_mesh_free(&m);
  free(f);
}

static void test_tiles_wrap_modes(void) {
  /* u: MIRRORED_REPEAT. Face 1 in u-tile 1 (odd: reflected), face 2 in
   * u-tile 2 (even: translated), face 3 in u-tile -1 (odd) */
  static const int t[6][2] = {{0, 0}, {1, 0}, {2, 0}, {-1, 1}, {0, 0}, {0, 0}};
  size_t n;
  uint8_t *f = cube_glb(t, 33648, 10497, &n);
  hearth_mesh m;
  hearth_glb_report rep;
  hearth_err e = {0};
  CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
  CHECK(rep.uv_islands_moved == 3 && rep.uv_islands_mirrored == 2);
  for (int v = 0; m.uvs && v < CUBE_NV; v++) {
    int face = v / 4, k = t[face][0];
    double want_u = (k % 2) ? k + 1 - (g_uv[2 * v] + k) : g_uv[2 * v];
    CHECK_MSG(m.uvs[2 * v] == (float)want_u, "vertex %d: u %g, want %g", v, m.uvs[2 * v], want_u);
    CHECK(m.uvs[2 * v + 1] == (float)g_uv[2 * v + 1]);
  }
  hearth_mesh_free(&m);
  free(f);

  /* v: CLAMP_TO_EDGE. Islands moved along u (REPEAT) only are fine ... */
  static const int tu[6][2] = {{0, 0}, {3, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}};
  f = cube_glb(tu, 10497, 33071, &n);
  CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
  CHECK(same_as_plain(&m) && rep.uv_islands_moved == 1);
  hearth_mesh_free(&m);
  free(f);
  /* ... one outside [0,1] along v is not movable */
  static const int tv[6][2] = {{0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 1}, {0, 0}};
  f = cube_glb(tv, 10497, 33071, &n);
  hearth_status s = parse(f, n, 1, 0, &m, &rep, &e);
  CHECK_MSG(s == HEARTH_E_UNSUPPORTED && strstr(e.msg, "CLAMP_TO_EDGE") &&
                strstr(e.msg,
                       "1 UV island (2 triangles; first: meshes[0].primitives[0] "
                       "triangle 8"),
            "got %s: %s", hearth_status_name(s), e.msg);
  CHECK_OK(parse(f, n, 0, 0, &m, &rep, &e), &e);
  CHECK(rep.uv_islands_left == 1 && rep.uv_islands_moved == 0);
  hearth_mesh_free(&m);
  free(f);
}

/* ---- quantisation ---------------------------------------------------------- */
static void test_quantized(void) {
  const double lo[3] = {-0.05, 0.01, -0.2}, hi[3] = {0.07, 0.09, 0.3};
  for (size_t ti = 0; ti < TB_N_QTYPES; ti++) {
    const tb_qtype *q = &tb_qtypes[ti];
    tb_qcube qc;
    tb_quantized_cube(q, lo, hi, &qc);
    size_t n;
    uint8_t *f = tb_encode(&qc.g, &n);
    hearth_mesh m;
    hearth_glb_report rep;
    hearth_err e = {0};
    CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
    CHECK(rep.quantized_primitives == 1);
    CHECK(rep.transformed_primitives == (size_t)(qc.us != 1.0 || qc.uo != 0.0));
    for (int v = 0; m.uvs && v < CUBE_NV; v++) {
      for (int k = 0; k < 3; k++) {
        double step = (hi[k] - lo[k]) / (q->cmax - q->cmin);
        CHECK_MSG(fabs(m.positions[3 * v + k] - qc.ref[3 * v + k]) <= 0.5 * step + 1e-6,
                  "type %zu vertex %d axis %d: %g vs %g", ti, v, k, m.positions[3 * v + k],
                  qc.ref[3 * v + k]);
      }
      for (int k = 0; k < 2; k++)
        CHECK_MSG(fabs(m.uvs[2 * v + k] - g_uv[2 * v + k]) <= 0.5 / (q->cmax - q->cmin) + 1e-6,
                  "type %zu vertex %d uv %d: %g vs %g", ti, v, k, m.uvs[2 * v + k],
                  g_uv[2 * v + k]);
    }
    hearth_mesh_free(&m);
    free(f);
    /* undeclared: refused, naming the extension */
    qc.g.quantization = 0;
    f = tb_encode(&qc.g, &n);
    hearth_status s = parse(f, n, 1, 0, &m, &rep, &e);
    CHECK_MSG(s == HEARTH_E_UNSUPPORTED && strstr(e.msg, "KHR_mesh_quantization") &&
                  strstr(e.msg, "POSITION"),
              "type %zu: got %s: %s", ti, hearth_status_name(s), e.msg);
    free(f);
  }
}

/* ---- texture transform ------------------------------------------------------ */
static void test_texture_transform(void) {
  /* the extension's own example: offset (0, 1), rotation pi/2, scale 0.5
   * maps the unit square onto the lower-left quadrant, turned */
  const double r = 1.57079632679489662;
  const char *xf = "{\"offset\":[0,1],\"rotation\":1.57079632679489662,\"scale\":[0.5,0.5]}";
  tb_glb g = {0};
  g.nv = CUBE_NV, g.nt = CUBE_NT, g.pos = g_pos, g.uv[0] = g_uv, g.idx = g_idx;
  g.texture = 1, g.tex_coord = -1, g.transform = xf;
  size_t n;
  uint8_t *f = tb_encode(&g, &n);
  hearth_mesh m;
  hearth_glb_report rep;
  hearth_err e = {0};
  CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
  CHECK(rep.transformed_primitives == 1 && rep.quantized_primitives == 0);
  for (int v = 0; m.uvs && v < CUBE_NV; v++) {
    double u = g_uv[2 * v], w = g_uv[2 * v + 1];
    double wu = 0.5 * cos(r) * u + 0.5 * sin(r) * w, wv = 1.0 - 0.5 * sin(r) * u + 0.5 * cos(r) * w;
    CHECK_NEAR(m.uvs[2 * v], wu, 1e-6);
    CHECK_NEAR(m.uvs[2 * v + 1], wv, 1e-6);
    CHECK(m.uvs[2 * v] >= 0.0f && m.uvs[2 * v] <= 0.5f && m.uvs[2 * v + 1] >= 0.5f);
  }
  hearth_mesh_free(&m);
  free(f);

  /* offset + anisotropic scale + rotation, scale applied first */
  const double ox = 0.125, oy = -0.25, sx = 2.0, sy = 0.5, rot = 0.3;
  char xs[200];
  snprintf(xs, sizeof xs, "{\"offset\":[%.17g,%.17g],\"rotation\":%.17g,\"scale\":[%.17g,%.17g]}",
           ox, oy, rot, sx, sy);
  g.transform = xs;
  f = tb_encode(&g, &n);
  hearth_glb_read_opts o = {0};
  o.require_uvs = 1;
  o.keep_uv_tiles = 1; /* the raw transform, not folded */
  CHECK_OK(hearth_glb_parse(f, n, "xf.glb", &o, &m, &e), &e);
  for (int v = 0; m.uvs && v < CUBE_NV; v++) {
    double u = g_uv[2 * v], w = g_uv[2 * v + 1];
    CHECK_NEAR(m.uvs[2 * v], ox + sx * cos(rot) * u + sy * sin(rot) * w, 1e-6);
    CHECK_NEAR(m.uvs[2 * v + 1], oy - sx * sin(rot) * u + sy * cos(rot) * w, 1e-6);
  }
  hearth_mesh_free(&m);
  free(f);

  /* texCoord: the transform's overrides the textureInfo's */
  double uv1[CUBE_NV * 2];
  for (int i = 0; i < 2 * CUBE_NV; i++) uv1[i] = 0.5 * g_uv[i];
  g.uv[1] = uv1;
  g.tex_coord = 0;
  g.transform = "{\"texCoord\":1}";
  f = tb_encode(&g, &n);
  CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
  CHECK(m.uvs && m.uvs[2] == (float)uv1[2] && m.uvs[3] == (float)uv1[3]);
  CHECK(rep.transformed_primitives == 0); /* identity: only the set changed */
  hearth_mesh_free(&m);
  free(f);
  /* textureInfo.texCoord 1 without a transform; a missing set is named */
  g.tex_coord = 1;
  g.transform = NULL;
  g.uv[1] = NULL;
  f = tb_encode(&g, &n);
  hearth_status s = parse(f, n, 1, 0, &m, &rep, &e);
  CHECK_MSG(s == HEARTH_E_NOT_FOUND && strstr(e.msg, "TEXCOORD_1"), "got %s: %s",
            hearth_status_name(s), e.msg);
  free(f);

  /* required extensions: these two accepted, others refused by name */
  g.tex_coord = -1;
  g.transform = xf;
  g.transform_required = 1;
  g.quantization = 1;
  f = tb_encode(&g, &n);
  CHECK_OK(parse(f, n, 1, 0, &m, &rep, &e), &e);
  hearth_mesh_free(&m);
  free(f);
  g.required_extra = "KHR_materials_variants";
  f = tb_encode(&g, &n);
  s = parse(f, n, 1, 0, &m, &rep, &e);
  CHECK_MSG(s == HEARTH_E_UNSUPPORTED && strstr(e.msg, "extensionsRequired[2]") &&
                strstr(e.msg, "KHR_materials_variants"),
            "got %s: %s", hearth_status_name(s), e.msg);
  free(f);
}

static int same_file(const char *a, const char *b) {
  uint8_t *x = NULL, *y = NULL;
  size_t nx = 0, ny = 0;
  hearth_err e = {0};
  int same = hearth_read_file(a, 1 << 26, &x, &nx, &e) == HEARTH_OK &&
             hearth_read_file(b, 1 << 26, &y, &ny, &e) == HEARTH_OK && nx == ny &&
             memcmp(x, y, nx) == 0;
  free(x);
  free(y);
  return same;
}

static void write_file(const char *path, const uint8_t *f, size_t n) {
  hearth_err e = {0};
  CHECK_OK(hearth_write_file_atomic(path, f, n, &e), &e);
}

static void test_end_to_end(void) {
  static char out[1 << 16];
  char cmd[8192], a[2048], b[2048];
  const char *dir = test_tmpdir("mesh_glb_tiles");
  static const int per_face[6][2] = {{0, 0}, {1, 0}, {-1, 2}, {3, -1}, {0, 1}, {-2, -2}};
  const char *names[2] = {"plain", "tiled"};
  for (int c = 0; c < 2; c++) {
    size_t n;
    uint8_t *f = cube_glb(c ? per_face : NULL, 0, 0, &n);
    snprintf(a, sizeof a, "%s/%s.glb", dir, names[c]);
    write_file(a, f, n);
    free(f);
    snprintf(cmd, sizeof cmd,
             "'%s' synth --out '%s/%s' --mesh '%s' --mesh-size 0.1 --mesh-category cup --views 2 "
             "--texture 64 --map-res 64 --states hot --no-calibration --threads 2 --quiet",
             HEARTH_EXE, dir, names[c], a);
    int rc = test_run_capture(cmd, out, sizeof out);
    CHECK_MSG(rc == 0, "%s: synth exit %d: %s", names[c], rc, out);
    const char *g = "ground_truth/instances/cup_01";
    snprintf(cmd, sizeof cmd,
             "'%s' map '%s/%s' --instance cup_01 --state hot --mesh '%s/%s/%s/mesh.glb' --poses "
             "'%s/%s/%s/poses_thermal.json' --rig '%s/%s/ground_truth/rig.json' --resolution 64 "
             "--threads 2",
             HEARTH_EXE, dir, names[c], dir, names[c], g, dir, names[c], g, dir, names[c]);
    rc = test_run_capture(cmd, out, sizeof out);
    CHECK_MSG(rc == 0 && strstr(out, "surface 0 texels") == NULL, "%s: map exit %d: %s", names[c],
              rc, out);
  }
  /* the same ground truth and the same map, byte for byte */
  const char *files[] = {"ground_truth/instances/cup_01/hot/temperature_true.npy",
                         "instances/cup_01/derived/hot/temperature_filled.npy",
                         "instances/cup_01/derived/hot/mask.npy"};
  for (size_t i = 0; i < 3; i++) {
    snprintf(a, sizeof a, "%s/plain/%s", dir, files[i]);
    snprintf(b, sizeof b, "%s/tiled/%s", dir, files[i]);
    CHECK_MSG(same_file(a, b), "%s differs between the plain and the tiled cube", files[i]);
  }

  /* a layout covering no texel (every UV one point): synth and map refuse */
  double uv[CUBE_NV * 2];
  for (int i = 0; i < 2 * CUBE_NV; i++) uv[i] = 0.5;
  tb_glb gb = {0};
  gb.nv = CUBE_NV, gb.nt = CUBE_NT, gb.pos = g_pos, gb.uv[0] = uv, gb.idx = g_idx;
  gb.texture = 1, gb.tex_coord = -1;
  size_t n;
  uint8_t *f = tb_encode(&gb, &n);
  snprintf(a, sizeof a, "%s/point.glb", dir);
  write_file(a, f, n);
  free(f);
  snprintf(cmd, sizeof cmd,
           "'%s' synth --out '%s/point' --mesh '%s' --mesh-size 0.1 --views 1 --texture 64 "
           "--map-res 64 --states hot --no-calibration --threads 2 --quiet",
           HEARTH_EXE, dir, a);
  int rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc != 0 && strstr(out, "surface 0 texels") && strstr(out, "point.glb") &&
                strstr(out, "hot"),
            "synth on a point layout: exit %d: %s", rc, out);
  const char *g = "ground_truth/instances/cup_01";
  snprintf(cmd, sizeof cmd,
           "'%s' map '%s/plain' --instance cup_01 --state hot --mesh '%s' --poses "
           "'%s/plain/%s/poses_thermal.json' --rig '%s/plain/ground_truth/rig.json' "
           "--resolution 64 --threads 2",
           HEARTH_EXE, dir, a, dir, g, dir);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc != 0 && strstr(out, "surface 0 texels") && strstr(out, "point.glb") &&
                strstr(out, "cup_01/hot"),
            "map on a point layout: exit %d: %s", rc, out);
}

int main(void) {
  tb_cube_init();
  test_tiles_repeat();
  test_tiles_straddling();
  test_tiles_wrap_modes();
  test_quantized();
  test_texture_transform();
  test_end_to_end();
  TEST_MAIN_END();
}
