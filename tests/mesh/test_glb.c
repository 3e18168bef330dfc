/* GLB reader/writer: round trip with texture, a hand-built file with a node
 * hierarchy checked against closed-form positions, winding under mirroring,
 * and every rejection naming the file and element. */
#include "hearth/mesh.h"
#include "test_util.h"
#include <dirent.h>
#include <jansson.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- byte helpers ---------------------------------------------------------- */
static void put_u32(uint8_t *p, uint32_t v) {
  for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}
static uint32_t get_u32(const uint8_t *p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static void put_f32(uint8_t *p, float f) {
  uint32_t u;
  memcpy(&u, &f, 4);
  put_u32(p, u);
}
static float get_f32(const uint8_t *p) {
  uint32_t u = get_u32(p);
  float f;
  memcpy(&f, &u, 4);
  return f;
}
static void put_u16(uint8_t *p, uint16_t v) {
  p[0] = (uint8_t)v;
  p[1] = (uint8_t)(v >> 8);
}

/* Assemble a GLB by hand: header, JSON chunk padded with spaces, BIN chunk
 * padded with zeros (omitted when bin == NULL). */
static uint8_t *make_glb(const char *json, const uint8_t *bin, size_t bin_len, size_t *size) {
  size_t jl = strlen(json), jp = (jl + 3) & ~(size_t)3, bp = (bin_len + 3) & ~(size_t)3;
  size_t total = 12 + 8 + jp + (bin ? 8 + bp : 0);
  uint8_t *f = calloc(total, 1);
  put_u32(f, 0x46546C67u);
  put_u32(f + 4, 2);
  put_u32(f + 8, (uint32_t)total);
  put_u32(f + 12, (uint32_t)jp);
  put_u32(f + 16, 0x4E4F534Au);
  memcpy(f + 20, json, jl);
  memset(f + 20 + jl, ' ', jp - jl);
  if (bin) {
    put_u32(f + 20 + jp, (uint32_t)bp);
    put_u32(f + 24 + jp, 0x004E4942u);
    memcpy(f + 28 + jp, bin, bin_len);
  }
  *size = total;
  return f;
}

/* s with the first occurrence of a replaced by b (malloc'ed); the test fails
 * if a is absent so a variant can never silently equal the base file. */
static char *replace(const char *s, const char *a, const char *b) {
  const char *p = strstr(s, a);
  CHECK_MSG(p != NULL, "pattern %s not in JSON", a);
  if (!p) return strdup(s);
  size_t n = strlen(s) - strlen(a) + strlen(b);
  char *r = malloc(n + 1);
  size_t pre = (size_t)(p - s);
  memcpy(r, s, pre);
  strcpy(r + pre, b);
  strcat(r, p + strlen(a));
  return r;
}

/* ---- the hand-built file ---------------------------------------------------- */
/* primitive A (no indices): 3 positions + normalised UNSIGNED_SHORT UVs;
 * primitive B (UNSIGNED_SHORT indices): 4 vertices interleaved pos|uv with
 * byteStride 20, the UV accessor at byteOffset 12. */
static const float A_POS[3][3] = {{0.5f, -1.0f, 2.0f}, {1.5f, 0.25f, -1.0f}, {-2.0f, 1.0f, 0.75f}};
static const uint16_t A_UV[3][2] = {{0, 65535}, {65535, 0}, {32768, 16384}};
static const float B_POS[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.5f}};
static const float B_UV[4][2] = {{0.125f, 0.25f}, {0.75f, 0.25f}, {0.125f, 0.875f}, {0.75f, 0.875f}};
static const uint16_t B_IDX[6] = {0, 1, 2, 2, 1, 3};
#define HAND_BIN_LEN 140

static void hand_bin(uint8_t bin[HAND_BIN_LEN]) {
  memset(bin, 0, HAND_BIN_LEN);
  for (int v = 0; v < 3; v++) {
    for (int k = 0; k < 3; k++) put_f32(bin + 12 * v + 4 * k, A_POS[v][k]);
    for (int k = 0; k < 2; k++) put_u16(bin + 36 + 4 * v + 2 * k, A_UV[v][k]);
  }
  for (int v = 0; v < 4; v++) {
    for (int k = 0; k < 3; k++) put_f32(bin + 48 + 20 * v + 4 * k, B_POS[v][k]);
    for (int k = 0; k < 2; k++) put_f32(bin + 48 + 20 * v + 12 + 4 * k, B_UV[v][k]);
  }
  for (int i = 0; i < 6; i++) put_u16(bin + 128 + 2 * i, B_IDX[i]);
}

/* node 0: T(1,2,3) R(90 deg about z) S(2) -> child node 1: matrix with
 * y scale 3 and translation (0,0,5), holding mesh 0. Node 2 holds the mesh
 * too but is not in the scene, so it must not appear. */
static const char *HAND_JSON =
    "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
    "\"nodes\":[{\"translation\":[1,2,3],\"rotation\":[0,0,0.7071067811865476,"
    "0.7071067811865476],\"scale\":[2,2,2],\"children\":[1]},"
    "{\"matrix\":[1,0,0,0,0,3,0,0,0,0,1,0,0,0,5,1],\"mesh\":0},"
    "{\"mesh\":0,\"translation\":[100,0,0]}],"
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1}},"
    "{\"attributes\":{\"POSITION\":2,\"TEXCOORD_0\":3},\"indices\":4,\"mode\":4}]}],"
    "\"accessors\":["
    "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
    "{\"bufferView\":1,\"componentType\":5123,\"normalized\":true,\"count\":3,\"type\":\"VEC2\"},"
    "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
    "{\"bufferView\":2,\"byteOffset\":12,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
    "{\"bufferView\":3,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],"
    "\"bufferViews\":["
    "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
    "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":12},"
    "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":80,\"byteStride\":20},"
    "{\"buffer\":0,\"byteOffset\":128,\"byteLength\":12}],"
    "\"buffers\":[{\"byteLength\":140}]}";

/* closed form of node0 * node1 applied to p */
static void hand_world(const float p[3], double w[3]) {
  /* node 1: (x, 3y, z + 5); scale 2; rotate 90 deg about z: (x,y) -> (-y, x); + (1,2,3) */
  double x = p[0], y = 3.0 * p[1], z = p[2] + 5.0;
  x *= 2, y *= 2, z *= 2;
  w[0] = -y + 1.0;
  w[1] = x + 2.0;
  w[2] = z + 3.0;
}

static hearth_status parse_json_variant(const char *json, const uint8_t *bin, int require_uvs,
                                        hearth_mesh *m, hearth_err *e) {
  size_t n;
  uint8_t *f = make_glb(json, bin, HAND_BIN_LEN, &n);
  hearth_glb_read_opts o = {require_uvs, 1, 0};
  hearth_status s = hearth_glb_parse(f, n, "hand.glb", &o, m, e);
  free(f);
  return s;
}

static void test_hand_built(void) {
  uint8_t bin[HAND_BIN_LEN];
  hand_bin(bin);
  hearth_mesh m;
  hearth_err e = {0};
  CHECK_OK(parse_json_variant(HAND_JSON, bin, 1, &m, &e), &e);
  CHECK(m.n_vertices == 7);
  CHECK(m.n_triangles == 3);
  CHECK(m.uvs != NULL);
  CHECK(m.texture.data == NULL);
  if (m.n_vertices == 7 && m.n_triangles == 3 && m.uvs) {
    for (int v = 0; v < 7; v++) {
      const float *p = v < 3 ? A_POS[v] : B_POS[v - 3];
      double w[3];
      hand_world(p, w);
      for (int k = 0; k < 3; k++) CHECK_NEAR(m.positions[3 * v + k], w[k], 1e-5);
    }
    for (int v = 0; v < 3; v++)
      for (int k = 0; k < 2; k++) CHECK_NEAR(m.uvs[2 * v + k], A_UV[v][k] / 65535.0, 1e-7);
    for (int v = 0; v < 4; v++)
      for (int k = 0; k < 2; k++) CHECK(m.uvs[2 * (3 + v) + k] == B_UV[v][k]);
    /* positive determinant: winding kept; primitive B offset by 3 vertices */
    uint32_t want[9] = {0, 1, 2, 3 + 0, 3 + 1, 3 + 2, 3 + 2, 3 + 1, 3 + 3};
    for (int i = 0; i < 9; i++) CHECK(m.indices[i] == want[i]);
  }
  hearth_mesh_free(&m);

  /* no scene: every root node (node 0 and node 2) is instanced */
  char *j = replace(HAND_JSON, "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],", "");
  CHECK_OK(parse_json_variant(j, bin, 0, &m, &e), &e);
  CHECK(m.n_vertices == 14 && m.n_triangles == 6);
  if (m.n_vertices == 14) {
    /* second instance: node 2 translates by 100 in x */
    CHECK_NEAR(m.positions[3 * 7 + 0], A_POS[0][0] + 100.0, 1e-5);
    CHECK_NEAR(m.positions[3 * 7 + 2], A_POS[0][2], 1e-6);
    CHECK(m.indices[9] == 7 && m.indices[10] == 8 && m.indices[11] == 9);
  }
  hearth_mesh_free(&m);
  free(j);

  /* missing UVs are fine when not required: the mesh then has none */
  j = replace(HAND_JSON, "\"POSITION\":0,\"TEXCOORD_0\":1", "\"POSITION\":0");
  CHECK_OK(parse_json_variant(j, bin, 0, &m, &e), &e);
  CHECK(m.uvs == NULL && m.n_triangles == 3);
  hearth_mesh_free(&m);
  free(j);
}

/* geometric normal of triangle t */
static void tri_normal(const hearth_mesh *m, size_t t, double n[3]) {
  const float *a = m->positions + 3 * m->indices[3 * t],
              *b = m->positions + 3 * m->indices[3 * t + 1],
              *c = m->positions + 3 * m->indices[3 * t + 2];
  double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
         e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

static void test_mirror_flips_winding(void) {
  uint8_t bin[HAND_BIN_LEN];
  hand_bin(bin);
  /* one node mirroring x, holding a mesh with only primitive A */
  const char *j2 =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"scale\":[-1,1,1],\"mesh\":0}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}],"
      "\"buffers\":[{\"byteLength\":140}]}";
  hearth_mesh m;
  hearth_err e = {0};
  CHECK_OK(parse_json_variant(j2, bin, 0, &m, &e), &e);
  CHECK(m.n_vertices == 3 && m.n_triangles == 1);
  if (m.n_triangles == 1) {
    for (int v = 0; v < 3; v++) {
      CHECK(m.positions[3 * v] == -A_POS[v][0]);
      CHECK(m.positions[3 * v + 1] == A_POS[v][1]);
      CHECK(m.positions[3 * v + 2] == A_POS[v][2]);
    }
    CHECK(m.indices[0] == 0 && m.indices[1] == 2 && m.indices[2] == 1);
    /* the front face normal of a mirrored surface is the mirrored normal */
    double n0[3], n1[3];
    const float *a = A_POS[0], *b = A_POS[1], *c = A_POS[2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
           e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n0[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n0[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n0[2] = e1[0] * e2[1] - e1[1] * e2[0];
    tri_normal(&m, 0, n1);
    CHECK_NEAR(n1[0], -n0[0], 1e-5);
    CHECK_NEAR(n1[1], n0[1], 1e-5);
    CHECK_NEAR(n1[2], n0[2], 1e-5);
  }
  hearth_mesh_free(&m);
}

/* a parse must fail with status want and a message naming the file and
 * every fragment given */
static void expect_fail(const uint8_t *f, size_t n, int require_uvs, hearth_status want,
                        const char *frag1, const char *frag2) {
  hearth_mesh m;
  hearth_err e = {0};
  hearth_glb_read_opts o = {require_uvs, 1, 0};
  hearth_status s = hearth_glb_parse(f, n, "hand.glb", &o, &m, &e);
  CHECK_MSG(s == want, "got %s (%s), want %s", hearth_status_name(s), e.msg,
            hearth_status_name(want));
  CHECK_MSG(strstr(e.msg, "hand.glb") != NULL, "message lacks the file: %s", e.msg);
  if (frag1) CHECK_MSG(strstr(e.msg, frag1) != NULL, "message lacks '%s': %s", frag1, e.msg);
  if (frag2) CHECK_MSG(strstr(e.msg, frag2) != NULL, "message lacks '%s': %s", frag2, e.msg);
  CHECK(m.positions == NULL && m.indices == NULL && m.n_triangles == 0);
}

static void expect_json_fail(const char *json, const uint8_t *bin, int require_uvs,
                             hearth_status want, const char *frag1, const char *frag2) {
  size_t n;
  uint8_t *f = make_glb(json, bin, HAND_BIN_LEN, &n);
  expect_fail(f, n, require_uvs, want, frag1, frag2);
  free(f);
}

static void test_rejections(void) {
  uint8_t bin[HAND_BIN_LEN];
  hand_bin(bin);
  char *j;

  j = replace(HAND_JSON, "\"scene\":0,",
              "\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
              "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],\"scene\":0,");
  expect_json_fail(j, bin, 0, HEARTH_E_UNSUPPORTED, "extensionsRequired[0]",
                   "KHR_draco_mesh_compression");
  free(j);
  j = replace(HAND_JSON, "\"scene\":0,",
              "\"extensionsRequired\":[\"EXT_meshopt_compression\"],\"scene\":0,");
  expect_json_fail(j, bin, 0, HEARTH_E_UNSUPPORTED, "EXT_meshopt_compression", NULL);
  free(j);

  j = replace(HAND_JSON, "\"mode\":4", "\"mode\":5");
  expect_json_fail(j, bin, 0, HEARTH_E_UNSUPPORTED, "meshes[0].primitives[1]: mode 5",
                   "TRIANGLE_STRIP");
  free(j);

  j = replace(HAND_JSON, "\"POSITION\":0,\"TEXCOORD_0\":1", "\"POSITION\":0");
  expect_json_fail(j, bin, 1, HEARTH_E_NOT_FOUND, "meshes[0].primitives[0]", "TEXCOORD_0");
  free(j);

  /* index 9 in primitive B, which has 4 vertices */
  uint8_t bad[HAND_BIN_LEN];
  memcpy(bad, bin, sizeof bad);
  put_u16(bad + 128 + 2 * 5, 9);
  expect_json_fail(HAND_JSON, bad, 0, HEARTH_E_RANGE, "meshes[0].primitives[1].indices", "index 9");

  /* accessor reaching past its bufferView (5 strided elements need 100 of 80 bytes) */
  j = replace(HAND_JSON, "{\"bufferView\":2,\"componentType\":5126,\"count\":4",
              "{\"bufferView\":2,\"componentType\":5126,\"count\":5");
  expect_json_fail(j, bin, 0, HEARTH_E_RANGE, "accessors[2]", "bufferViews[2]");
  free(j);
  /* buffer declared larger than the BIN chunk */
  j = replace(HAND_JSON, "\"byteLength\":140", "\"byteLength\":400");
  expect_json_fail(j, bin, 0, HEARTH_E_PARSE, "buffers[0]", "BIN chunk");
  free(j);

  j = replace(HAND_JSON, "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}",
              "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"sparse\":"
              "{\"count\":1,\"indices\":{\"bufferView\":3,\"componentType\":5123},\"values\":"
              "{\"bufferView\":0}}}");
  expect_json_fail(j, bin, 0, HEARTH_E_UNSUPPORTED, "accessors[0]", "sparse");
  free(j);

  j = replace(HAND_JSON, "\"children\":[1]", "\"children\":[1]},{\"children\":[0]");
  char *j2 = replace(j, "\"mesh\":0},", "\"mesh\":0,\"children\":[0]},");
  expect_json_fail(j2, bin, 0, HEARTH_E_PARSE, "cycle", "nodes[0]");
  free(j);
  free(j2);

  j = replace(HAND_JSON, "\"version\":\"2.0\"", "\"version\":\"1.0\"");
  expect_json_fail(j, bin, 0, HEARTH_E_UNSUPPORTED, "asset.version", NULL);
  free(j);

  j = replace(HAND_JSON, "\"buffers\":[{", "\"buffers\":[{\"uri\":\"hand.bin\",");
  expect_json_fail(j, bin, 0, HEARTH_E_UNSUPPORTED, "buffers[0]", "uri");
  free(j);

  expect_json_fail("{\"asset\":{\"version\":\"2.0\"},\"nodes\":[", bin, 0, HEARTH_E_PARSE,
                   "JSON chunk: line 1", NULL);

  /* container-level damage */
  size_t n;
  uint8_t *f = make_glb(HAND_JSON, bin, HAND_BIN_LEN, &n);
  uint8_t *g = malloc(n);

  memcpy(g, f, n);
  g[0] = 'X';
  expect_fail(g, n, 0, HEARTH_E_PARSE, "magic", NULL);

  memcpy(g, f, n);
  put_u32(g + 8, (uint32_t)n + 4);
  expect_fail(g, n, 0, HEARTH_E_PARSE, "length", "file size");

  /* truncated BIN: cut 8 bytes and fix the header length so only the chunk lies */
  memcpy(g, f, n);
  put_u32(g + 8, (uint32_t)(n - 8));
  expect_fail(g, n - 8, 0, HEARTH_E_PARSE, "chunk 1", "past the end");

  /* a chunk length that is not 4-aligned */
  memcpy(g, f, n);
  put_u32(g + 12, get_u32(g + 12) - 2);
  expect_fail(g, n, 0, HEARTH_E_PARSE, "chunk", "multiple of 4");

  /* wrong first chunk type */
  memcpy(g, f, n);
  put_u32(g + 16, 0x004E4942u);
  expect_fail(g, n, 0, HEARTH_E_PARSE, "chunk 0", "JSON");

  memcpy(g, f, n);
  put_u32(g + 4, 1);
  expect_fail(g, n, 0, HEARTH_E_UNSUPPORTED, "version", NULL);

  expect_fail(f, 7, 0, HEARTH_E_PARSE, "too short", NULL);

  /* triangle limit */
  hearth_mesh m;
  hearth_err e = {0};
  hearth_glb_read_opts o = {0, 0, 2};
  hearth_status s = hearth_glb_parse(f, n, "hand.glb", &o, &m, &e);
  CHECK_MSG(s == HEARTH_E_LIMIT && strstr(e.msg, "hand.glb"), "%s", e.msg);
  free(f);
  free(g);
}

/* ---- round trip ------------------------------------------------------------ */
static void fill_mesh(hearth_mesh *m, int with_texture) {
  hearth_err e = {0};
  const size_t nv = 40, nt = 50;
  CHECK_OK(hearth_mesh_alloc(m, nv, nt, 1, &e), &e);
  hearth_rng r;
  hearth_rng_seed(&r, 7);
  for (size_t i = 0; i < 3 * nv; i++) m->positions[i] = (float)hearth_rng_range(&r, -2.0, 2.0);
  for (size_t i = 0; i < 2 * nv; i++) m->uvs[i] = (float)hearth_rng_uniform(&r);
  for (size_t t = 0; t < nt; t++) {
    /* distinct corners so no triangle is degenerate by index */
    uint32_t a = (uint32_t)(t % nv), b = (uint32_t)((t * 7 + 1) % nv),
             c = (uint32_t)((t * 13 + 5) % nv);
    if (b == a) b = (a + 1) % nv;
    if (c == a || c == b) c = (uint32_t)((b + 2) % nv == a ? (b + 3) % nv : (b + 2) % nv);
    m->indices[3 * t] = a;
    m->indices[3 * t + 1] = b;
    m->indices[3 * t + 2] = c;
  }
  if (with_texture) {
    CHECK_OK(hearth_image_alloc(&m->texture, 6, 5, 3, HEARTH_PIX_U8, &e), &e);
    uint8_t *px = m->texture.data;
    for (size_t i = 0; i < 6 * 5 * 3; i++) px[i] = (uint8_t)(i * 37 + 11);
  }
}

static void test_round_trip(const char *dir) {
  hearth_mesh m, r;
  hearth_err e = {0};
  fill_mesh(&m, 1);
  uint8_t *a = NULL, *b = NULL;
  size_t na = 0, nb = 0;
  CHECK_OK(hearth_glb_encode(&m, &a, &na, &e), &e);
  CHECK_OK(hearth_glb_encode(&m, &b, &nb, &e), &e);
  /* deterministic bytes */
  CHECK(na == nb && a && b && memcmp(a, b, na) == 0);

  /* container layout: header length, 4-aligned chunks, space/zero padding */
  CHECK(na % 4 == 0 && get_u32(a + 8) == na);
  size_t jl = get_u32(a + 12);
  CHECK(jl % 4 == 0 && get_u32(a + 16) == 0x4E4F534Au);
  size_t bl = get_u32(a + 20 + jl);
  CHECK(bl % 4 == 0 && get_u32(a + 24 + jl) == 0x004E4942u && 28 + jl + bl == na);
  json_error_t je;
  json_t *root = json_loadb((const char *)a + 20, jl, 0, &je);
  CHECK(root != NULL);
  if (root) {
    json_t *views = json_object_get(root, "bufferViews");
    size_t nviews = json_array_size(views);
    CHECK(nviews == 5);
    for (size_t i = 0; i < nviews; i++) {
      json_t *v = json_array_get(views, i);
      CHECK(json_integer_value(json_object_get(v, "byteOffset")) % 4 == 0);
    }
    /* vertex views 34962, index view 34963, image view no target */
    json_t *img = json_array_get(json_object_get(root, "images"), 0);
    size_t iv = (size_t)json_integer_value(json_object_get(img, "bufferView"));
    CHECK(strcmp(json_string_value(json_object_get(img, "mimeType")), "image/png") == 0);
    CHECK(json_object_get(json_array_get(views, iv), "target") == NULL);
    json_t *prim =
        json_array_get(json_object_get(json_array_get(json_object_get(root, "meshes"), 0),
                                       "primitives"),
                       0);
    json_t *accs = json_object_get(root, "accessors");
    json_t *ia = json_array_get(accs, (size_t)json_integer_value(json_object_get(prim, "indices")));
    CHECK(json_integer_value(json_object_get(ia, "componentType")) == 5125);
    json_t *iview =
        json_array_get(views, (size_t)json_integer_value(json_object_get(ia, "bufferView")));
    CHECK(json_integer_value(json_object_get(iview, "target")) == 34963);
    json_t *attrs = json_object_get(prim, "attributes");
    const char *names[3] = {"POSITION", "NORMAL", "TEXCOORD_0"};
    for (int k = 0; k < 3; k++) {
      json_t *acc =
          json_array_get(accs, (size_t)json_integer_value(json_object_get(attrs, names[k])));
      CHECK(acc != NULL);
      json_t *vw =
          json_array_get(views, (size_t)json_integer_value(json_object_get(acc, "bufferView")));
      CHECK(json_integer_value(json_object_get(vw, "target")) == 34962);
    }
    json_decref(root);
  }
  /* the JSON padding is spaces */
  for (size_t i = 20; i < 20 + jl; i++)
    if (a[i] == 0) {
      CHECK(!"NUL inside JSON chunk");
      break;
    }

  hearth_glb_read_opts o = {1, 1, 0};
  CHECK_OK(hearth_glb_parse(a, na, "rt.glb", &o, &r, &e), &e);
  CHECK(r.n_vertices == m.n_vertices && r.n_triangles == m.n_triangles && r.uvs);
  if (r.n_vertices == m.n_vertices && r.n_triangles == m.n_triangles && r.uvs) {
    CHECK(memcmp(r.positions, m.positions, 3 * m.n_vertices * sizeof(float)) == 0);
    CHECK(memcmp(r.uvs, m.uvs, 2 * m.n_vertices * sizeof(float)) == 0);
    CHECK(memcmp(r.indices, m.indices, 3 * m.n_triangles * sizeof(uint32_t)) == 0);
  }
  CHECK(r.texture.data && r.texture.width == 6 && r.texture.height == 5 &&
        r.texture.channels == 3 && r.texture.type == HEARTH_PIX_U8);
  if (r.texture.data && r.texture.width == 6 && r.texture.height == 5 && r.texture.channels == 3)
    CHECK(memcmp(r.texture.data, m.texture.data, 90) == 0);
  hearth_mesh_free(&r);

  /* load_texture = 0 leaves the texture out */
  hearth_glb_read_opts o2 = {1, 0, 0};
  CHECK_OK(hearth_glb_parse(a, na, "rt.glb", &o2, &r, &e), &e);
  CHECK(r.texture.data == NULL && r.n_triangles == m.n_triangles);
  hearth_mesh_free(&r);

  /* through a file */
  char path[1200];
  snprintf(path, sizeof path, "%s/rt.glb", dir);
  CHECK_OK(hearth_glb_write(path, &m, &e), &e);
  uint8_t *fb = NULL;
  size_t fn = 0;
  CHECK_OK(hearth_read_file(path, 1 << 20, &fb, &fn, &e), &e);
  CHECK(fn == na && fb && memcmp(fb, a, na) == 0);
  free(fb);
  CHECK_OK(hearth_glb_read(path, &o, &r, &e), &e);
  CHECK(r.n_triangles == m.n_triangles && r.texture.data != NULL);
  hearth_mesh_free(&r);
  free(a);
  free(b);

  /* a file error names the path */
  char missing[1200];
  snprintf(missing, sizeof missing, "%s/nope.glb", dir);
  CHECK(hearth_glb_read(missing, &o, &r, &e) == HEARTH_E_IO && strstr(e.msg, "nope.glb"));

  /* a mesh that cannot be written leaves no file (and no temporary) behind */
  char badp[1200];
  snprintf(badp, sizeof badp, "%s/bad.glb", dir);
  m.indices[7] = 1000;
  hearth_status s = hearth_glb_write(badp, &m, &e);
  CHECK(s == HEARTH_E_RANGE && strstr(e.msg, "bad.glb") && strstr(e.msg, "triangle 2"));
  CHECK(!hearth_path_exists(badp));
  DIR *d = opendir(dir);
  int n_files = 0;
  struct dirent *de;
  while (d && (de = readdir(d)) != NULL)
    if (de->d_name[0] != '.') n_files++;
  if (d) closedir(d);
  CHECK_MSG(n_files == 1, "%d files in %s, want only rt.glb", n_files, dir);
  hearth_mesh_free(&m);
}

/* Area-weighted vertex normals against a closed form: triangle A (area 1/2,
 * normal +z) and triangle B (area 1, normal -y) share the edge v0-v1. */
static void test_normals(void) {
  hearth_mesh m;
  hearth_err e = {0};
  CHECK_OK(hearth_mesh_alloc(&m, 5, 2, 0, &e), &e);
  const float P[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, -2, 9, 9, 9}; /* v4 unused */
  const uint32_t I[6] = {0, 1, 2, 1, 0, 3};
  memcpy(m.positions, P, sizeof P);
  memcpy(m.indices, I, sizeof I);
  uint8_t *a = NULL;
  size_t na = 0;
  CHECK_OK(hearth_glb_encode(&m, &a, &na, &e), &e);
  if (!a) return;
  size_t jl = get_u32(a + 12);
  const uint8_t *bin = a + 28 + jl;
  json_error_t je;
  json_t *root = json_loadb((const char *)a + 20, jl, 0, &je);
  json_t *prim = json_array_get(json_object_get(json_array_get(json_object_get(root, "meshes"), 0),
                                                "primitives"),
                                0);
  CHECK(json_object_get(json_object_get(prim, "attributes"), "TEXCOORD_0") == NULL);
  size_t ai =
      (size_t)json_integer_value(json_object_get(json_object_get(prim, "attributes"), "NORMAL"));
  json_t *acc = json_array_get(json_object_get(root, "accessors"), ai);
  json_t *view = json_array_get(json_object_get(root, "bufferViews"),
                                (size_t)json_integer_value(json_object_get(acc, "bufferView")));
  size_t off = (size_t)json_integer_value(json_object_get(view, "byteOffset")) +
               (size_t)json_integer_value(json_object_get(acc, "byteOffset"));
  double s5 = sqrt(5.0);
  const double want[5][3] = {{0, -2 / s5, 1 / s5},
                             {0, -2 / s5, 1 / s5},
                             {0, 0, 1},
                             {0, -1, 0},
                             {0, 0, 1}};
  for (int v = 0; v < 5; v++)
    for (int k = 0; k < 3; k++) CHECK_NEAR(get_f32(bin + off + 12 * v + 4 * k), want[v][k], 1e-6);
  /* POSITION min/max cover every vertex */
  json_t *pa =
      json_array_get(json_object_get(root, "accessors"),
                     (size_t)json_integer_value(
                         json_object_get(json_object_get(prim, "attributes"), "POSITION")));
  CHECK_NEAR(json_number_value(json_array_get(json_object_get(pa, "min"), 2)), -2.0, 0);
  CHECK_NEAR(json_number_value(json_array_get(json_object_get(pa, "max"), 0)), 9.0, 0);
  json_decref(root);
  free(a);
  hearth_mesh_free(&m);

  /* empty meshes cannot be written */
  hearth_mesh z;
  memset(&z, 0, sizeof z);
  CHECK(hearth_glb_encode(&z, &a, &na, &e) == HEARTH_E_SIZE);
}

/* Embedded JPEG and gray PNG base-colour textures on the hand-built file:
 * the JPEG must decode to what the JPEG reader gives for the same bytes, the
 * gray PNG must come back as RGB with r = g = b = gray. */
static void test_embedded_images(const char *dir) {
  uint8_t bin0[HAND_BIN_LEN];
  hand_bin(bin0);
  hearth_err e = {0};
  for (int kind = 0; kind < 2; kind++) {
    hearth_image src;
    CHECK_OK(hearth_image_alloc(&src, 9, 7, kind == 0 ? 3 : 1, HEARTH_PIX_U8, &e), &e);
    uint8_t *px = src.data;
    for (size_t i = 0; i < hearth_image_bytes(&src); i++) px[i] = (uint8_t)((i * 53) % 251);
    uint8_t *img = NULL;
    size_t n_img = 0;
    hearth_image ref = {0};
    if (kind == 0) {
      char jp[1200];
      snprintf(jp, sizeof jp, "%s/tex.jpg", dir);
      CHECK_OK(hearth_jpeg_write(jp, &src, 95, &e), &e);
      CHECK_OK(hearth_read_file(jp, 1 << 20, &img, &n_img, &e), &e);
      CHECK_OK(hearth_jpeg_read(jp, &ref, &e), &e);
      remove(jp);
    } else {
      CHECK_OK(hearth_png_encode(&src, &img, &n_img, &e), &e);
    }
    if (!img) continue;
    size_t bl = HAND_BIN_LEN + n_img;
    uint8_t *bin = calloc(bl, 1);
    memcpy(bin, bin0, HAND_BIN_LEN);
    memcpy(bin + HAND_BIN_LEN, img, n_img);
    char tail[512];
    snprintf(tail, sizeof tail,
             "{\"buffer\":0,\"byteOffset\":128,\"byteLength\":12},"
             "{\"buffer\":0,\"byteOffset\":140,\"byteLength\":%zu}],"
             "\"images\":[{\"bufferView\":4,\"mimeType\":\"%s\"}],\"textures\":[{\"source\":0}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],",
             n_img, kind == 0 ? "image/jpeg" : "image/png");
    char *j1 = replace(HAND_JSON, "{\"buffer\":0,\"byteOffset\":128,\"byteLength\":12}],", tail);
    char blen[64];
    snprintf(blen, sizeof blen, "\"byteLength\":%zu}]}", bl);
    char *j2 = replace(j1, "\"byteLength\":140}]}", blen);
    /* material on the second primitive: the first one has none */
    char *j3 = replace(j2, "\"indices\":4,", "\"indices\":4,\"material\":0,");
    size_t n;
    uint8_t *f = make_glb(j3, bin, bl, &n);
    hearth_mesh m;
    hearth_glb_read_opts o = {1, 1, 0};
    CHECK_OK(hearth_glb_parse(f, n, "img.glb", &o, &m, &e), &e);
    CHECK(m.texture.data && m.texture.width == 9 && m.texture.height == 7 &&
          m.texture.channels == 3 && m.texture.type == HEARTH_PIX_U8);
    if (m.texture.data && m.texture.width == 9 && m.texture.height == 7 &&
        m.texture.channels == 3) {
      const uint8_t *t = m.texture.data;
      if (kind == 0) {
        CHECK(ref.data && ref.channels == 3 && memcmp(t, ref.data, 9 * 7 * 3) == 0);
      } else {
        int bad = 0;
        for (size_t i = 0; i < 63; i++)
          bad += t[3 * i] != px[i] || t[3 * i + 1] != px[i] || t[3 * i + 2] != px[i];
        CHECK(bad == 0);
      }
    }
    hearth_mesh_free(&m);
    /* an unknown mimeType is refused, naming the image */
    char *j4 = replace(j3, kind == 0 ? "image/jpeg" : "image/png", "image/webp");
    free(f);
    f = make_glb(j4, bin, bl, &n);
    hearth_status s = hearth_glb_parse(f, n, "img.glb", &o, &m, &e);
    CHECK_MSG(s == HEARTH_E_UNSUPPORTED && strstr(e.msg, "images[0]"), "%s", e.msg);
    free(f);
    free(j1);
    free(j2);
    free(j3);
    free(j4);
    free(bin);
    free(img);
    hearth_image_free(&ref);
    hearth_image_free(&src);
  }
}

int main(void) {
  const char *dir = test_tmpdir("mesh_glb");
  test_hand_built();
  test_mirror_flips_winding();
  test_rejections();
  test_round_trip(dir);
  test_normals();
  test_embedded_images(dir);
  TEST_MAIN_END();
}
