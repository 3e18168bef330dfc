/* glTF 2.0 binary (GLB) reader and writer.
 *
 * The reader walks the default scene's node tree, composes node transforms
 * and concatenates every triangle primitive of every mesh instance into one
 * hearth_mesh. Everything read from the file is treated as untrusted: every
 * offset, stride and count is checked against the buffer it points into.
 * The writer emits one mesh / node / primitive with computed normals and an
 * optional embedded PNG base-colour texture, laid out so the Khronos
 * validator reports no errors. */
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "hearth/mesh.h"

#define GLB_MAGIC 0x46546C67u      /* "glTF" */
#define GLB_CHUNK_JSON 0x4E4F534Au /* "JSON" */
#define GLB_CHUNK_BIN 0x004E4942u  /* "BIN\0" */

#define GL_BYTE 5120
#define GL_UNSIGNED_BYTE 5121
#define GL_SHORT 5122
#define GL_UNSIGNED_SHORT 5123
#define GL_UNSIGNED_INT 5125
#define GL_FLOAT 5126

#define GLB_DEFAULT_MAX_TRIANGLES ((size_t)50000000)
/* node visits (instances included) before a file is judged hostile */
#define GLB_MAX_NODE_VISITS ((size_t)1 << 20)
#define GLB_MAX_DEPTH 512
/* largest GLB file hearth_glb_read accepts */
#define GLB_MAX_FILE ((size_t)4 << 30)

/* ---- little-endian byte access (independent of the host) ------------------ */
static uint32_t rd_u32(const uint8_t *p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static uint16_t rd_u16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static float rd_f32(const uint8_t *p) {
  uint32_t u = rd_u32(p);
  float f;
  memcpy(&f, &u, 4);
  return f;
}
static void wr_u32(uint8_t *p, uint32_t v) {
  p[0] = (uint8_t)v;
  p[1] = (uint8_t)(v >> 8);
  p[2] = (uint8_t)(v >> 16);
  p[3] = (uint8_t)(v >> 24);
}
static void wr_f32(uint8_t *p, float f) {
  uint32_t u;
  memcpy(&u, &f, 4);
  wr_u32(p, u);
}

static int add_size(size_t a, size_t b, size_t *out) {
  if (a > SIZE_MAX - b) return 0;
  *out = a + b;
  return 1;
}

/* ==== reader ================================================================ */

typedef struct glb_ctx {
  const char *name;
  json_t *root;
  const uint8_t *bin; /* BIN chunk payload (NULL if none) */
  size_t bin_size;
  hearth_err *err;
  json_t *accessors, *views, *buffers, *meshes, *nodes;
  int quantization; /* KHR_mesh_quantization declared: integer POSITION/UVs allowed */
} glb_ctx;

/* A resolved accessor: where element i, component c lives. base == NULL means
 * an accessor without bufferView (all zeros by the spec). */
typedef struct glb_acc {
  const uint8_t *base;
  size_t count, stride, ncomp, comp_size;
  int comp_type, normalized;
} glb_acc;

/* One mesh instance found while walking the scene. */
typedef struct glb_inst {
  size_t mesh;
  double M[16]; /* column-major, M[c*4+r] */
  int flip;     /* negative determinant: reverse winding */
} glb_inst;

typedef struct glb_inst_list {
  glb_inst *v;
  size_t n, cap;
} glb_inst_list;

static const char *mode_name(long long mode) {
  switch (mode) {
    case 0: return "POINTS";
    case 1: return "LINES";
    case 2: return "LINE_LOOP";
    case 3: return "LINE_STRIP";
    case 4: return "TRIANGLES";
    case 5: return "TRIANGLE_STRIP";
    case 6: return "TRIANGLE_FAN";
    default: return "unknown";
  }
}

static size_t comp_size_of(long long t) {
  switch (t) {
    case GL_BYTE:
    case GL_UNSIGNED_BYTE: return 1;
    case GL_SHORT:
    case GL_UNSIGNED_SHORT: return 2;
    case GL_UNSIGNED_INT:
    case GL_FLOAT: return 4;
    default: return 0;
  }
}

static size_t ncomp_of(const char *type) {
  static const struct {
    const char *s;
    size_t n;
  } tab[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
             {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
  for (size_t i = 0; i < sizeof tab / sizeof tab[0]; i++)
    if (strcmp(type, tab[i].s) == 0) return tab[i].n;
  return 0;
}

/* Optional non-negative integer member; *present tells whether it was there. */
static hearth_status get_uint(glb_ctx *c, json_t *obj, const char *key, const char *where,
                              int required, size_t *out, int *present) {
  json_t *v = json_object_get(obj, key);
  if (present) *present = v != NULL;
  if (!v) {
    if (required)
      return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s: missing required \"%s\"", c->name,
                            where, key);
    return HEARTH_OK;
  }
  if (!json_is_integer(v) || json_integer_value(v) < 0)
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s.%s: expected a non-negative integer",
                          c->name, where, key);
  unsigned long long u = (unsigned long long)json_integer_value(v);
  if (u > (unsigned long long)SIZE_MAX)
    return hearth_err_set(c->err, HEARTH_E_RANGE, "%s: %s.%s: value too large", c->name, where,
                          key);
  *out = (size_t)u;
  return HEARTH_OK;
}

/* The idx-th object of a top-level array ("accessors", "nodes", ...). */
static hearth_status get_elem(glb_ctx *c, json_t *arr, const char *arr_name, size_t idx,
                              const char *where, json_t **out) {
  if (!arr || idx >= json_array_size(arr))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s: %s[%zu] does not exist (%zu defined)",
                          c->name, where, arr_name, idx, arr ? json_array_size(arr) : 0);
  json_t *e = json_array_get(arr, idx);
  if (!json_is_object(e))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s[%zu]: expected an object", c->name,
                          arr_name, idx);
  *out = e;
  return HEARTH_OK;
}

/* Resolve accessors[idx] down to bytes in the BIN chunk, checking every bound. */
static hearth_status resolve_accessor(glb_ctx *c, size_t idx, const char *where, glb_acc *a) {
  hearth_status s;
  json_t *acc = NULL;
  char at[48];
  memset(a, 0, sizeof *a);
  if ((s = get_elem(c, c->accessors, "accessors", idx, where, &acc))) return s;
  snprintf(at, sizeof at, "accessors[%zu]", idx);
  if (json_object_get(acc, "sparse"))
    return hearth_err_set(c->err, HEARTH_E_UNSUPPORTED,
                          "%s: %s (%s): sparse accessors are not supported", c->name, at, where);
  size_t ctype = 0, count = 0, off = 0, view_idx = 0;
  int has_view = 0;
  if ((s = get_uint(c, acc, "componentType", at, 1, &ctype, NULL))) return s;
  if ((s = get_uint(c, acc, "count", at, 1, &count, NULL))) return s;
  if ((s = get_uint(c, acc, "byteOffset", at, 0, &off, NULL))) return s;
  if ((s = get_uint(c, acc, "bufferView", at, 0, &view_idx, &has_view))) return s;
  a->comp_size = comp_size_of((long long)ctype);
  if (!a->comp_size)
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s: invalid componentType %zu", c->name, at,
                          ctype);
  json_t *type = json_object_get(acc, "type");
  if (!json_is_string(type) || !(a->ncomp = ncomp_of(json_string_value(type))))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s: invalid or missing \"type\"", c->name,
                          at);
  if (count == 0)
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s: count must be at least 1", c->name, at);
  json_t *norm = json_object_get(acc, "normalized");
  if (norm && !json_is_boolean(norm))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s.normalized: expected a boolean", c->name,
                          at);
  a->normalized = norm && json_is_true(norm);
  a->comp_type = (int)ctype;
  a->count = count;
  size_t elem = a->ncomp * a->comp_size;
  a->stride = elem;
  if (!has_view) return HEARTH_OK; /* all zeros */

  json_t *view;
  char vat[48];
  snprintf(vat, sizeof vat, "bufferViews[%zu]", view_idx);
  if ((s = get_elem(c, c->views, "bufferViews", view_idx, at, &view))) return s;
  size_t buf_idx = 0, voff = 0, vlen = 0, stride = 0;
  int has_stride = 0;
  if ((s = get_uint(c, view, "buffer", vat, 1, &buf_idx, NULL))) return s;
  if ((s = get_uint(c, view, "byteOffset", vat, 0, &voff, NULL))) return s;
  if ((s = get_uint(c, view, "byteLength", vat, 1, &vlen, NULL))) return s;
  if ((s = get_uint(c, view, "byteStride", vat, 0, &stride, &has_stride))) return s;
  if (has_stride) {
    if (stride < 4 || stride > 252 || stride % 4)
      return hearth_err_set(c->err, HEARTH_E_PARSE,
                            "%s: %s: byteStride %zu must be a multiple of 4 in [4, 252]", c->name,
                            vat, stride);
    if (stride < elem)
      return hearth_err_set(c->err, HEARTH_E_PARSE,
                            "%s: %s: byteStride %zu is smaller than the %zu-byte element of %s",
                            c->name, vat, stride, elem, at);
    a->stride = stride;
  }

  json_t *buf;
  char bat[48];
  snprintf(bat, sizeof bat, "buffers[%zu]", buf_idx);
  if ((s = get_elem(c, c->buffers, "buffers", buf_idx, vat, &buf))) return s;
  size_t blen = 0;
  if ((s = get_uint(c, buf, "byteLength", bat, 1, &blen, NULL))) return s;
  if (json_object_get(buf, "uri"))
    return hearth_err_set(c->err, HEARTH_E_UNSUPPORTED,
                          "%s: %s: buffers with a uri (external or data:) are not supported in a "
                          "GLB; expected the embedded BIN chunk",
                          c->name, bat);
  if (buf_idx != 0 || !c->bin)
    return hearth_err_set(c->err, HEARTH_E_PARSE,
                          "%s: %s: has no uri but is not buffer 0 backed by a BIN chunk", c->name,
                          bat);
  if (blen > c->bin_size)
    return hearth_err_set(c->err, HEARTH_E_PARSE,
                          "%s: %s: byteLength %zu exceeds the BIN chunk (%zu bytes)", c->name, bat,
                          blen, c->bin_size);
  size_t vend;
  if (!add_size(voff, vlen, &vend) || vend > blen)
    return hearth_err_set(c->err, HEARTH_E_RANGE,
                          "%s: %s: byteOffset %zu + byteLength %zu lies beyond %s (%zu bytes)",
                          c->name, vat, voff, vlen, bat, blen);
  /* last byte touched: off + stride * (count - 1) + elem */
  size_t span, end;
  if (!hearth_mul_size(a->stride, count - 1, &span) || !add_size(span, elem, &span) ||
      !add_size(off, span, &end) || end > vlen)
    return hearth_err_set(c->err, HEARTH_E_RANGE,
                          "%s: %s (%s): %zu elements from byteOffset %zu with stride %zu lie "
                          "beyond %s (byteLength %zu)",
                          c->name, at, where, count, off, a->stride, vat, vlen);
  a->base = c->bin + voff + off;
  return HEARTH_OK;
}

/* Component c of element i as a number (normalised integers mapped to [0, 1]
 * or [-1, 1] as the spec says). */
static double acc_get(const glb_acc *a, size_t i, size_t comp) {
  if (!a->base) return 0.0;
  const uint8_t *p = a->base + i * a->stride + comp * a->comp_size;
  switch (a->comp_type) {
    case GL_FLOAT: return rd_f32(p);
    case GL_UNSIGNED_BYTE: return a->normalized ? p[0] / 255.0 : p[0];
    case GL_UNSIGNED_SHORT: return a->normalized ? rd_u16(p) / 65535.0 : rd_u16(p);
    case GL_UNSIGNED_INT: return rd_u32(p);
    case GL_BYTE: {
      double v = (int8_t)p[0];
      return a->normalized ? fmax(v / 127.0, -1.0) : v;
    }
    case GL_SHORT: {
      double v = (int16_t)rd_u16(p);
      return a->normalized ? fmax(v / 32767.0, -1.0) : v;
    }
    default: return 0.0;
  }
}

static uint32_t acc_index(const glb_acc *a, size_t i) {
  if (!a->base) return 0;
  const uint8_t *p = a->base + i * a->stride;
  switch (a->comp_type) {
    case GL_UNSIGNED_BYTE: return p[0];
    case GL_UNSIGNED_SHORT: return rd_u16(p);
    default: return rd_u32(p);
  }
}

/* ---- node transforms ------------------------------------------------------ */
static void mat_identity(double M[16]) {
  memset(M, 0, 16 * sizeof(double));
  M[0] = M[5] = M[10] = M[15] = 1.0;
}

/* C = A * B (column-major 4x4) */
static void mat_mul(const double A[16], const double B[16], double C[16]) {
  double T[16];
  for (int col = 0; col < 4; col++)
    for (int r = 0; r < 4; r++) {
      double acc = 0.0;
      for (int k = 0; k < 4; k++) acc += A[k * 4 + r] * B[col * 4 + k];
      T[col * 4 + r] = acc;
    }
  memcpy(C, T, sizeof T);
}

static double mat_det3(const double M[16]) {
  return M[0] * (M[5] * M[10] - M[9] * M[6]) - M[4] * (M[1] * M[10] - M[9] * M[2]) +
         M[8] * (M[1] * M[6] - M[5] * M[2]);
}

/* Read a fixed-length array of numbers. */
static hearth_status get_numbers(glb_ctx *c, json_t *obj, const char *key, const char *where,
                                 size_t n, double *out, int *present) {
  json_t *v = json_object_get(obj, key);
  *present = v != NULL;
  if (!v) return HEARTH_OK;
  if (!json_is_array(v) || json_array_size(v) != n)
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s.%s: expected an array of %zu numbers",
                          c->name, where, key, n);
  for (size_t i = 0; i < n; i++) {
    json_t *e = json_array_get(v, i);
    if (!json_is_number(e))
      return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s.%s[%zu]: expected a number", c->name,
                            where, key, i);
    out[i] = json_number_value(e);
  }
  return HEARTH_OK;
}

/* The node's local transform: matrix, or T * R * S. */
static hearth_status node_local(glb_ctx *c, json_t *node, const char *where, double L[16]) {
  hearth_status s;
  double mat[16], t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, sc[3] = {1, 1, 1};
  int has_m, has_t, has_r, has_s;
  if ((s = get_numbers(c, node, "matrix", where, 16, mat, &has_m))) return s;
  if ((s = get_numbers(c, node, "translation", where, 3, t, &has_t))) return s;
  if ((s = get_numbers(c, node, "rotation", where, 4, q, &has_r))) return s;
  if ((s = get_numbers(c, node, "scale", where, 3, sc, &has_s))) return s;
  if (has_m) {
    if (has_t || has_r || has_s)
      return hearth_err_set(c->err, HEARTH_E_PARSE,
                            "%s: %s: has both a matrix and translation/rotation/scale", c->name,
                            where);
    memcpy(L, mat, sizeof mat);
    return HEARTH_OK;
  }
  /* the spec requires a unit quaternion; renormalise small drift */
  double qn = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(qn > 1e-12) || !isfinite(qn))
    return hearth_err_set(c->err, HEARTH_E_RANGE, "%s: %s.rotation: zero-length quaternion",
                          c->name, where);
  double x = q[0] / qn, y = q[1] / qn, z = q[2] / qn, w = q[3] / qn;
  double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
                 2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                 2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
  mat_identity(L);
  for (int col = 0; col < 3; col++)
    for (int r = 0; r < 3; r++) L[col * 4 + r] = R[r * 3 + col] * sc[col];
  L[12] = t[0];
  L[13] = t[1];
  L[14] = t[2];
  return HEARTH_OK;
}

typedef struct walk_state {
  unsigned char *on_stack;
  size_t visits;
  glb_inst_list *list;
} walk_state;

static hearth_status visit_node(glb_ctx *c, walk_state *w, size_t idx, const double P[16],
                                int depth, const char *from) {
  hearth_status s;
  json_t *node;
  char at[48];
  if ((s = get_elem(c, c->nodes, "nodes", idx, from, &node))) return s;
  snprintf(at, sizeof at, "nodes[%zu]", idx);
  if (w->on_stack[idx])
    return hearth_err_set(c->err, HEARTH_E_PARSE,
                          "%s: %s: cycle in the node hierarchy (reached again from %s)", c->name,
                          at, from);
  if (depth > GLB_MAX_DEPTH)
    return hearth_err_set(c->err, HEARTH_E_LIMIT, "%s: %s: node hierarchy deeper than %d", c->name,
                          at, GLB_MAX_DEPTH);
  if (++w->visits > GLB_MAX_NODE_VISITS)
    return hearth_err_set(c->err, HEARTH_E_LIMIT, "%s: %s: more than %zu node instances", c->name,
                          at, GLB_MAX_NODE_VISITS);
  double L[16], M[16];
  if ((s = node_local(c, node, at, L))) return s;
  mat_mul(P, L, M);
  for (int k = 0; k < 16; k++)
    if (!isfinite(M[k]))
      return hearth_err_set(c->err, HEARTH_E_RANGE, "%s: %s: non-finite world transform", c->name,
                            at);
  size_t mesh = 0;
  int has_mesh = 0;
  if ((s = get_uint(c, node, "mesh", at, 0, &mesh, &has_mesh))) return s;
  if (has_mesh) {
    json_t *mj;
    if ((s = get_elem(c, c->meshes, "meshes", mesh, at, &mj))) return s;
    glb_inst_list *l = w->list;
    if (l->n == l->cap) {
      size_t nc = l->cap ? l->cap * 2 : 16;
      glb_inst *nv = hearth_alloc_array(nc, sizeof *nv);
      if (!nv) return hearth_err_set(c->err, HEARTH_E_NOMEM, "%s: out of memory", c->name);
      if (l->n) memcpy(nv, l->v, l->n * sizeof *nv);
      free(l->v);
      l->v = nv;
      l->cap = nc;
    }
    glb_inst *in = &l->v[l->n++];
    in->mesh = mesh;
    memcpy(in->M, M, sizeof M);
    in->flip = mat_det3(M) < 0.0;
  }
  json_t *kids = json_object_get(node, "children");
  if (kids && !json_is_array(kids))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s.children: expected an array", c->name,
                          at);
  w->on_stack[idx] = 1;
  for (size_t k = 0; k < json_array_size(kids); k++) {
    json_t *kv = json_array_get(kids, k);
    if (!json_is_integer(kv) || json_integer_value(kv) < 0) {
      w->on_stack[idx] = 0;
      return hearth_err_set(c->err, HEARTH_E_PARSE,
                            "%s: %s.children[%zu]: expected a non-negative integer", c->name, at,
                            k);
    }
    s = visit_node(c, w, (size_t)json_integer_value(kv), M, depth + 1, at);
    if (s) {
      w->on_stack[idx] = 0;
      return s;
    }
  }
  w->on_stack[idx] = 0;
  return HEARTH_OK;
}

/* Collect mesh instances of the default scene (or scene 0, or every root
 * node when the file has no scenes). */
static hearth_status collect_instances(glb_ctx *c, glb_inst_list *list) {
  hearth_status s;
  size_t n_nodes = json_array_size(c->nodes);
  walk_state w = {0};
  w.list = list;
  w.on_stack = calloc(n_nodes ? n_nodes : 1, 1);
  if (!w.on_stack) return hearth_err_set(c->err, HEARTH_E_NOMEM, "%s: out of memory", c->name);
  double I[16];
  mat_identity(I);
  json_t *scenes = json_object_get(c->root, "scenes");
  size_t scene = 0;
  int has_scene = 0;
  s = get_uint(c, c->root, "scene", "(root)", 0, &scene, &has_scene);
  if (!s && (has_scene || json_array_size(scenes) > 0)) {
    json_t *sc;
    char at[48];
    snprintf(at, sizeof at, "scenes[%zu]", scene);
    s = get_elem(c, scenes, "scenes", scene, "scene", &sc);
    json_t *roots = s ? NULL : json_object_get(sc, "nodes");
    if (!s && roots && !json_is_array(roots))
      s = hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s.nodes: expected an array", c->name, at);
    for (size_t k = 0; !s && k < json_array_size(roots); k++) {
      json_t *kv = json_array_get(roots, k);
      if (!json_is_integer(kv) || json_integer_value(kv) < 0)
        s = hearth_err_set(c->err, HEARTH_E_PARSE,
                           "%s: %s.nodes[%zu]: expected a non-negative integer", c->name, at, k);
      else s = visit_node(c, &w, (size_t)json_integer_value(kv), I, 0, at);
    }
  } else if (!s) {
    /* no scene: every node that is nobody's child is a root */
    unsigned char *is_child = calloc(n_nodes ? n_nodes : 1, 1);
    if (!is_child) s = hearth_err_set(c->err, HEARTH_E_NOMEM, "%s: out of memory", c->name);
    for (size_t i = 0; !s && i < n_nodes; i++) {
      json_t *kids = json_object_get(json_array_get(c->nodes, i), "children");
      for (size_t k = 0; k < json_array_size(kids); k++) {
        json_t *kv = json_array_get(kids, k);
        if (json_is_integer(kv) && json_integer_value(kv) >= 0 &&
            (unsigned long long)json_integer_value(kv) < n_nodes)
          is_child[json_integer_value(kv)] = 1;
      }
    }
    for (size_t i = 0; !s && i < n_nodes; i++)
      if (!is_child[i]) s = visit_node(c, &w, i, I, 0, "(root nodes)");
    free(is_child);
  }
  free(w.on_stack);
  return s;
}

/* ---- primitives ------------------------------------------------------------ */
/* Where a primitive's UVs come from: the UV set its base colour texture
 * samples, the texture transform and the sampler's wrap modes. */
typedef struct glb_uvsrc {
  size_t set;      /* TEXCOORD_<set> */
  int has_xform;   /* KHR_texture_transform present */
  double xf[6];    /* u' = xf[0] u + xf[1] v + xf[2], v' = xf[3] u + xf[4] v + xf[5] */
  uint8_t wrap[2]; /* hearth_uv_wrap of wrapS, wrapT */
} glb_uvsrc;

typedef struct glb_prim {
  glb_acc pos, uv, idx;
  int has_uv, has_idx;
  size_t n_tris;
  glb_uvsrc src;
  size_t mesh, prim, tbase; /* where it is in the file and in the output */
} glb_prim;

static hearth_status wrap_mode(glb_ctx *c, json_t *smp, const char *key, const char *at,
                               uint8_t *out) {
  size_t w = 10497;
  hearth_status s = get_uint(c, smp, key, at, 0, &w, NULL);
  if (s) return s;
  switch (w) {
    case 10497: *out = HEARTH_UV_REPEAT; return HEARTH_OK;
    case 33648: *out = HEARTH_UV_MIRRORED_REPEAT; return HEARTH_OK;
    case 33071: *out = HEARTH_UV_CLAMP_TO_EDGE; return HEARTH_OK;
    default:
      return hearth_err_set(c->err, HEARTH_E_PARSE,
                            "%s: %s.%s: %zu is not a wrap mode; expected 10497 (REPEAT), 33648 "
                            "(MIRRORED_REPEAT) or 33071 (CLAMP_TO_EDGE)",
                            c->name, at, key, w);
  }
}

/* The UV source of a primitive: TEXCOORD_0, REPEAT and no transform unless
 * its material has a base colour texture saying otherwise. */
static hearth_status resolve_uv_source(glb_ctx *c, json_t *prim, const char *pat, glb_uvsrc *out) {
  hearth_status s;
  memset(out, 0, sizeof *out);
  out->xf[0] = out->xf[4] = 1.0;
  size_t mat_idx = 0, tex_idx = 0, smp_idx = 0;
  int has;
  if ((s = get_uint(c, prim, "material", pat, 0, &mat_idx, &has)) || !has) return s;
  json_t *mat, *tex, *smp;
  if ((s = get_elem(c, json_object_get(c->root, "materials"), "materials", mat_idx, pat, &mat)))
    return s;
  json_t *pbr = json_object_get(mat, "pbrMetallicRoughness");
  json_t *bct = json_is_object(pbr) ? json_object_get(pbr, "baseColorTexture") : NULL;
  if (!json_is_object(bct)) return HEARTH_OK;
  char at[160], xat[224];
  snprintf(at, sizeof at, "materials[%zu].pbrMetallicRoughness.baseColorTexture", mat_idx);
  if ((s = get_uint(c, bct, "index", at, 1, &tex_idx, NULL))) return s;
  if ((s = get_uint(c, bct, "texCoord", at, 0, &out->set, NULL))) return s;
  if ((s = get_elem(c, json_object_get(c->root, "textures"), "textures", tex_idx, at, &tex)))
    return s;
  char tat[48];
  snprintf(tat, sizeof tat, "textures[%zu]", tex_idx);
  if ((s = get_uint(c, tex, "sampler", tat, 0, &smp_idx, &has))) return s;
  if (has) {
    char sat[48];
    snprintf(sat, sizeof sat, "samplers[%zu]", smp_idx);
    if ((s = get_elem(c, json_object_get(c->root, "samplers"), "samplers", smp_idx, tat, &smp)) ||
        (s = wrap_mode(c, smp, "wrapS", sat, &out->wrap[0])) ||
        (s = wrap_mode(c, smp, "wrapT", sat, &out->wrap[1])))
      return s;
  }
  json_t *ext = json_object_get(bct, "extensions");
  json_t *tt = json_is_object(ext) ? json_object_get(ext, "KHR_texture_transform") : NULL;
  if (!tt) return HEARTH_OK;
  snprintf(xat, sizeof xat, "%s.extensions.KHR_texture_transform", at);
  if (!json_is_object(tt))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s: expected an object", c->name, xat);
  double off[2] = {0, 0}, sc[2] = {1, 1}, rot = 0;
  int has_off, has_sc;
  if ((s = get_numbers(c, tt, "offset", xat, 2, off, &has_off)) ||
      (s = get_numbers(c, tt, "scale", xat, 2, sc, &has_sc)) ||
      (s = get_uint(c, tt, "texCoord", xat, 0, &out->set, NULL)))
    return s;
  json_t *r = json_object_get(tt, "rotation");
  if (r && !json_is_number(r))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s.rotation: expected a number", c->name,
                          xat);
  if (r) rot = json_number_value(r);
  /* T(offset) R(rotation) S(scale), the sign as in mesh.h */
  double cr = cos(rot), sr = sin(rot);
  out->xf[0] = cr * sc[0];
  out->xf[1] = sr * sc[1];
  out->xf[2] = off[0];
  out->xf[3] = -sr * sc[0];
  out->xf[4] = cr * sc[1];
  out->xf[5] = off[1];
  out->has_xform = out->xf[0] != 1.0 || out->xf[1] != 0.0 || out->xf[2] != 0.0 ||
                   out->xf[3] != 0.0 || out->xf[4] != 1.0 || out->xf[5] != 0.0;
  return HEARTH_OK;
}

static int is_int8_16(int t) {
  return t == GL_BYTE || t == GL_UNSIGNED_BYTE || t == GL_SHORT || t == GL_UNSIGNED_SHORT;
}

static hearth_status resolve_primitive(glb_ctx *c, size_t mesh, size_t p, json_t *prim,
                                       const hearth_glb_read_opts *o, glb_prim *out) {
  hearth_status s;
  char at[96], where[160];
  memset(out, 0, sizeof *out);
  snprintf(at, sizeof at, "meshes[%zu].primitives[%zu]", mesh, p);
  if (!json_is_object(prim))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s: expected an object", c->name, at);
  size_t mode = 4;
  if ((s = get_uint(c, prim, "mode", at, 0, &mode, NULL))) return s;
  if (mode != 4)
    return hearth_err_set(c->err, HEARTH_E_UNSUPPORTED,
                          "%s: %s: mode %zu (%s) not supported; expected 4 (TRIANGLES)", c->name,
                          at, mode, mode_name((long long)mode));
  /* morph targets, if any, are ignored: the base shape is used */
  json_t *attrs = json_object_get(prim, "attributes");
  if (!json_is_object(attrs))
    return hearth_err_set(c->err, HEARTH_E_PARSE, "%s: %s: missing \"attributes\" object", c->name,
                          at);
  snprintf(where, sizeof where, "%s.attributes", at);
  size_t ai = 0;
  int has = 0;
  if ((s = get_uint(c, attrs, "POSITION", where, 0, &ai, &has))) return s;
  if (!has)
    return hearth_err_set(c->err, HEARTH_E_NOT_FOUND, "%s: %s: no POSITION attribute", c->name, at);
  snprintf(where, sizeof where, "%s.attributes.POSITION", at);
  if ((s = resolve_accessor(c, ai, where, &out->pos))) return s;
  int pt = out->pos.comp_type;
  if (out->pos.ncomp != 3 || (pt != GL_FLOAT && !(c->quantization && is_int8_16(pt))))
    return hearth_err_set(c->err, HEARTH_E_UNSUPPORTED,
                          "%s: %s (accessors[%zu]): expected FLOAT VEC3 positions (BYTE, "
                          "UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT with KHR_mesh_quantization)",
                          c->name, where, ai);

  /* the UV set the base colour texture samples */
  if ((s = resolve_uv_source(c, prim, at, &out->src))) return s;
  char set[40];
  snprintf(set, sizeof set, "TEXCOORD_%zu", out->src.set);
  snprintf(where, sizeof where, "%s.attributes", at);
  if ((s = get_uint(c, attrs, set, where, 0, &ai, &out->has_uv))) return s;
  if (!out->has_uv && o->require_uvs)
    return hearth_err_set(c->err, HEARTH_E_NOT_FOUND,
                          "%s: %s: no %s attribute (UVs are required%s)", c->name, at, set,
                          out->src.set ? "; the base colour texture's texCoord names it" : "");
  if (out->has_uv) {
    snprintf(where, sizeof where, "%s.attributes.%s", at, set);
    if ((s = resolve_accessor(c, ai, where, &out->uv))) return s;
    int t = out->uv.comp_type;
    int ok = out->uv.ncomp == 2 &&
             (t == GL_FLOAT ||
              ((t == GL_UNSIGNED_BYTE || t == GL_UNSIGNED_SHORT) && out->uv.normalized) ||
              (c->quantization && is_int8_16(t)));
    if (!ok)
      return hearth_err_set(c->err, HEARTH_E_UNSUPPORTED,
                            "%s: %s (accessors[%zu]): expected VEC2 of FLOAT or normalized "
                            "UNSIGNED_BYTE/UNSIGNED_SHORT (any BYTE/SHORT type with "
                            "KHR_mesh_quantization)",
                            c->name, where, ai);
    if (out->uv.count != out->pos.count)
      return hearth_err_set(c->err, HEARTH_E_INCONSISTENT,
                            "%s: %s: %s has %zu elements but POSITION has %zu", c->name, at, set,
                            out->uv.count, out->pos.count);
  }

  if ((s = get_uint(c, prim, "indices", at, 0, &ai, &out->has_idx))) return s;
  size_t n_corners = out->pos.count;
  if (out->has_idx) {
    snprintf(where, sizeof where, "%s.indices", at);
    if ((s = resolve_accessor(c, ai, where, &out->idx))) return s;
    int t = out->idx.comp_type;
    if (out->idx.ncomp != 1 || out->idx.normalized ||
        (t != GL_UNSIGNED_BYTE && t != GL_UNSIGNED_SHORT && t != GL_UNSIGNED_INT))
      return hearth_err_set(c->err, HEARTH_E_PARSE,
                            "%s: %s (accessors[%zu]): expected SCALAR UNSIGNED_BYTE, "
                            "UNSIGNED_SHORT or UNSIGNED_INT",
                            c->name, where, ai);
    n_corners = out->idx.count;
  }
  if (n_corners % 3)
    return hearth_err_set(c->err, HEARTH_E_SIZE,
                          "%s: %s: %zu %s is not a multiple of 3 for TRIANGLES", c->name, at,
                          n_corners, out->has_idx ? "indices" : "vertices");
  out->n_tris = n_corners / 3;
  return HEARTH_OK;
}

/* Find and decode the base colour texture of the first primitive that has
 * one; images given by uri (not embedded) are skipped. */
static void to_rgb8(hearth_image *img);
static hearth_status load_base_color(glb_ctx *c, json_t *prim, hearth_image *tex, int *done) {
  hearth_status s;
  size_t mat_idx = 0, tex_idx = 0, img_idx = 0, view_idx = 0;
  int has;
  char at[48];
  if ((s = get_uint(c, prim, "material", "primitive", 0, &mat_idx, &has)) || !has) return s;
  json_t *mat, *t, *img, *view;
  if ((s = get_elem(c, json_object_get(c->root, "materials"), "materials", mat_idx, "primitive",
                    &mat)))
    return s;
  json_t *pbr = json_object_get(mat, "pbrMetallicRoughness");
  json_t *bct = json_is_object(pbr) ? json_object_get(pbr, "baseColorTexture") : NULL;
  if (!json_is_object(bct)) return HEARTH_OK;
  snprintf(at, sizeof at, "materials[%zu]", mat_idx);
  if ((s = get_uint(c, bct, "index", at, 1, &tex_idx, NULL))) return s;
  if ((s = get_elem(c, json_object_get(c->root, "textures"), "textures", tex_idx, at, &t)))
    return s;
  snprintf(at, sizeof at, "textures[%zu]", tex_idx);
  if ((s = get_uint(c, t, "source", at, 0, &img_idx, &has))) return s;
  if (!has) return HEARTH_OK; /* only an extension source: not decodable here */
  if ((s = get_elem(c, json_object_get(c->root, "images"), "images", img_idx, at, &img))) return s;
  snprintf(at, sizeof at, "images[%zu]", img_idx);
  if ((s = get_uint(c, img, "bufferView", at, 0, &view_idx, &has))) return s;
  if (!has) return HEARTH_OK; /* uri image: not embedded */
  json_t *mime = json_object_get(img, "mimeType");
  const char *ms = json_is_string(mime) ? json_string_value(mime) : "";
  if ((s = get_elem(c, c->views, "bufferViews", view_idx, at, &view))) return s;
  char vat[48];
  snprintf(vat, sizeof vat, "bufferViews[%zu]", view_idx);
  size_t buf_idx = 0, voff = 0, vlen = 0, blen = 0;
  if ((s = get_uint(c, view, "buffer", vat, 1, &buf_idx, NULL))) return s;
  if ((s = get_uint(c, view, "byteOffset", vat, 0, &voff, NULL))) return s;
  if ((s = get_uint(c, view, "byteLength", vat, 1, &vlen, NULL))) return s;
  json_t *buf;
  if ((s = get_elem(c, c->buffers, "buffers", buf_idx, vat, &buf))) return s;
  if ((s = get_uint(c, buf, "byteLength", "buffer", 1, &blen, NULL))) return s;
  size_t end;
  if (buf_idx != 0 || json_object_get(buf, "uri") || !c->bin || blen > c->bin_size ||
      !add_size(voff, vlen, &end) || end > blen)
    return hearth_err_set(c->err, HEARTH_E_RANGE,
                          "%s: %s (%s): image bytes are not inside the BIN chunk", c->name, vat,
                          at);
  char iname[256];
  snprintf(iname, sizeof iname, "%s: %s", c->name, at);
  const uint8_t *bytes = c->bin + voff;
  int is_png = vlen >= 8 && memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0;
  int is_jpg = vlen >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
  if (strcmp(ms, "image/png") == 0 || (!*ms && is_png))
    s = hearth_png_read_mem(bytes, vlen, iname, tex, c->err);
  else if (strcmp(ms, "image/jpeg") == 0 || (!*ms && is_jpg))
    s = hearth_jpeg_read_mem(bytes, vlen, iname, tex, c->err);
  else
    return hearth_err_set(c->err, HEARTH_E_UNSUPPORTED,
                          "%s: %s: mimeType \"%s\" not supported; expected image/png or "
                          "image/jpeg",
                          c->name, at, ms);
  if (s) return s;
  to_rgb8(tex);
  if (!tex->data)
    return hearth_err_set(c->err, HEARTH_E_NOMEM, "%s: %s: out of memory converting the image",
                          c->name, at);
  *done = 1;
  return HEARTH_OK;
}

/* Bring a decoded image to U8 RGB/RGBA as hearth_mesh.texture requires
 * (gray expands, 16-bit keeps the high byte). Frees and zeroes on failure. */
static void to_rgb8(hearth_image *img) {
  int ch = img->channels;
  if (img->type == HEARTH_PIX_U8 && (ch == 3 || ch == 4)) return;
  int out_ch = (ch == 2 || ch == 4) ? 4 : 3;
  size_t n = img->width * img->height;
  uint8_t *dst = hearth_alloc_array(n, (size_t)out_ch);
  if (!dst || (img->type != HEARTH_PIX_U8 && img->type != HEARTH_PIX_U16)) {
    free(dst);
    hearth_image_free(img);
    memset(img, 0, sizeof *img);
    return;
  }
  for (size_t i = 0; i < n; i++) {
    uint8_t v[4];
    for (int k = 0; k < ch; k++)
      v[k] = img->type == HEARTH_PIX_U8 ? ((const uint8_t *)img->data)[i * ch + k]
                                        : (uint8_t)(((const uint16_t *)img->data)[i * ch + k] >> 8);
    uint8_t *d = dst + i * (size_t)out_ch;
    if (ch <= 2) {
      d[0] = d[1] = d[2] = v[0];
      if (ch == 2) d[3] = v[1];
    } else {
      d[0] = v[0];
      d[1] = v[1];
      d[2] = v[2];
      if (ch == 4) d[3] = v[3];
    }
  }
  free(img->data);
  img->data = dst;
  img->channels = out_ch;
  img->type = HEARTH_PIX_U8;
}

/* Fold the UV islands of the assembled mesh into [0,1]^2 (mesh.h, "UV
 * tiles"), with each triangle's wrap modes from its primitive's sampler;
 * islands that cannot be folded fail a read that requires UVs. */
static hearth_status fold_tiles(glb_ctx *c, const glb_prim *prims, size_t n_prims,
                                const hearth_glb_read_opts *o, hearth_mesh *m,
                                hearth_glb_report *rep) {
  uint8_t *wrap = NULL;
  for (size_t q = 0; q < n_prims && !wrap; q++)
    if (prims[q].src.wrap[0] || prims[q].src.wrap[1]) {
      wrap = hearth_alloc_array(m->n_triangles, 2);
      if (!wrap) return hearth_err_set(c->err, HEARTH_E_NOMEM, "%s: out of memory", c->name);
      for (size_t r = 0; r < n_prims; r++)
        for (size_t t = 0; t < prims[r].n_tris; t++) {
          wrap[2 * (prims[r].tbase + t)] = prims[r].src.wrap[0];
          wrap[2 * (prims[r].tbase + t) + 1] = prims[r].src.wrap[1];
        }
    }
  hearth_uv_tiles ut;
  hearth_status s = hearth_uv_fold_tiles(m, wrap, &ut, c->err);
  free(wrap);
  if (s) return hearth_err_prefix(c->err, "%s", c->name);
  rep->uv_islands_moved = ut.moved;
  rep->uv_islands_mirrored = ut.mirrored;
  rep->uv_islands_left = ut.straddling + ut.clamped;
  rep->uv_triangles_straddling = ut.triangles_straddling;
  if (!o->require_uvs || ut.first_left == SIZE_MAX) return HEARTH_OK;
  /* name the first triangle left where the file has it */
  size_t t = ut.first_left, q = 0;
  while (q + 1 < n_prims && t >= prims[q].tbase + prims[q].n_tris) q++;
  const glb_prim *gp = &prims[q];
  const float *uv = m->uvs + 2 * (size_t)m->indices[3 * t];
  char first[200];
  snprintf(first, sizeof first, "first: meshes[%zu].primitives[%zu] triangle %zu, UV (%g, %g)",
           gp->mesh, gp->prim, t - gp->tbase, (double)uv[0], (double)uv[1]);
  if (ut.straddling)
    return hearth_err_set(c->err, HEARTH_E_UNSUPPORTED,
                          "%s: %u UV island%s span%s more than one texture tile (%zu triangles "
                          "in them, %zu crossing a tile border; %s): maps cover [0,1] and an "
                          "island moves only by whole tiles; split the islands at the tile "
                          "borders or pack them into [0,1]",
                          c->name, ut.straddling, ut.straddling == 1 ? "" : "s",
                          ut.straddling == 1 ? "s" : "", ut.triangles_left, ut.triangles_straddling,
                          first);
  return hearth_err_set(c->err, HEARTH_E_UNSUPPORTED,
                        "%s: %u UV island%s (%zu triangles; %s) lie%s outside [0,1] under a "
                        "CLAMP_TO_EDGE sampler, which shows the texture's edge texels there, so "
                        "they have no texels to map and moving them would change what they "
                        "show; use REPEAT or pack them into [0,1]",
                        c->name, ut.clamped, ut.clamped == 1 ? "" : "s", ut.triangles_left, first,
                        ut.clamped == 1 ? "s" : "");
}

/* The 12-byte GLB header of a file of file_size bytes (n of them at d). */
static hearth_status check_header(const uint8_t *d, size_t n, size_t file_size, const char *name,
                                  hearth_err *err) {
  if (n < 12)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: %zu bytes is too short for a GLB header", name,
                          n);
  if (rd_u32(d) != GLB_MAGIC)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: header: bad magic 0x%08x; expected \"glTF\" (0x46546c67)", name,
                          rd_u32(d));
  if (rd_u32(d + 4) != 2)
    return hearth_err_set(err, HEARTH_E_UNSUPPORTED, "%s: header: container version %u; expected 2",
                          name, rd_u32(d + 4));
  if ((size_t)rd_u32(d + 8) != file_size)
    return hearth_err_set(err, HEARTH_E_PARSE,
                          "%s: header: length field %u does not match the file size %zu", name,
                          rd_u32(d + 8), file_size);
  return HEARTH_OK;
}

/* Split the container into its JSON and BIN chunks. */
static hearth_status split_chunks(const uint8_t *d, size_t size, const char *name,
                                  const uint8_t **json, size_t *json_len, const uint8_t **bin,
                                  size_t *bin_len, hearth_err *err) {
  *bin = NULL;
  *bin_len = 0;
  hearth_status hs = check_header(d, size, size, name, err);
  if (hs) return hs;
  size_t pos = 12;
  int chunk = 0;
  while (pos < size) {
    if (size - pos < 8)
      return hearth_err_set(err, HEARTH_E_PARSE, "%s: chunk %d at byte %zu: truncated chunk header",
                            name, chunk, pos);
    size_t len = rd_u32(d + pos);
    uint32_t type = rd_u32(d + pos + 4);
    if (len > size - pos - 8)
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: chunk %d at byte %zu: length %zu runs past the end of the file "
                            "(%zu bytes left)",
                            name, chunk, pos, len, size - pos - 8);
    if (len % 4)
      return hearth_err_set(err, HEARTH_E_PARSE,
                            "%s: chunk %d at byte %zu: length %zu is not a multiple of 4", name,
                            chunk, pos, len);
    const uint8_t *payload = d + pos + 8;
    if (chunk == 0) {
      if (type != GLB_CHUNK_JSON)
        return hearth_err_set(err, HEARTH_E_PARSE,
                              "%s: chunk 0: type 0x%08x; expected JSON (0x4e4f534a)", name, type);
      *json = payload;
      *json_len = len;
    } else if (chunk == 1 && type == GLB_CHUNK_BIN) {
      *bin = payload;
      *bin_len = len;
    } else if (type == GLB_CHUNK_JSON || type == GLB_CHUNK_BIN) {
      return hearth_err_set(err, HEARTH_E_PARSE, "%s: chunk %d: a second or misplaced %s chunk",
                            name, chunk, type == GLB_CHUNK_JSON ? "JSON" : "BIN");
    } /* other chunk types are skipped, as the spec says */
    pos += 8 + len;
    chunk++;
  }
  if (chunk == 0)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: no JSON chunk after the header", name);
  return HEARTH_OK;
}

hearth_status hearth_glb_parse(const void *data, size_t size, const char *name,
                               const hearth_glb_read_opts *opts, hearth_mesh *out,
                               hearth_err *err) {
  hearth_status s;
  if (!name) name = "(glb)";
  if (!out || (!data && size))
    return hearth_err_set(err, HEARTH_E_ARG, "%s: hearth_glb_parse: NULL argument", name);
  memset(out, 0, sizeof *out);
  hearth_glb_read_opts o = {0};
  if (opts) o = *opts;
  if (!o.max_triangles) o.max_triangles = GLB_DEFAULT_MAX_TRIANGLES;

  const uint8_t *jbytes = NULL, *bin = NULL;
  size_t jlen = 0, bin_len = 0;
  if ((s = split_chunks(data, size, name, &jbytes, &jlen, &bin, &bin_len, err))) return s;
  /* the JSON chunk is padded with spaces; tolerate NUL padding too */
  while (jlen && (jbytes[jlen - 1] == ' ' || jbytes[jlen - 1] == 0)) jlen--;
  json_error_t jerr;
  json_t *root = json_loadb((const char *)jbytes, jlen, JSON_REJECT_DUPLICATES, &jerr);
  if (!root)
    return hearth_err_set(err, HEARTH_E_PARSE, "%s: JSON chunk: line %d, column %d: %s", name,
                          jerr.line, jerr.column, jerr.text);

  glb_ctx c = {name, root, bin, bin_len, err, NULL, NULL, NULL, NULL, NULL, 0};
  glb_inst_list list = {0};
  glb_prim *prims = NULL;
  size_t n_prims = 0;
  hearth_glb_report rep;
  memset(&rep, 0, sizeof rep);
  if (!json_is_object(root)) {
    s = hearth_err_set(err, HEARTH_E_PARSE, "%s: JSON chunk: expected an object", name);
    goto done;
  }
  /* asset.version must be 2.x */
  json_t *asset = json_object_get(root, "asset");
  json_t *ver = json_is_object(asset) ? json_object_get(asset, "version") : NULL;
  if (!json_is_string(ver)) {
    s = hearth_err_set(err, HEARTH_E_PARSE, "%s: asset.version: missing", name);
    goto done;
  }
  if (strncmp(json_string_value(ver), "2.", 2) != 0) {
    s = hearth_err_set(err, HEARTH_E_UNSUPPORTED, "%s: asset.version: \"%s\"; expected \"2.x\"",
                       name, json_string_value(ver));
    goto done;
  }
  /* any required extension changes the meaning of the data: refuse */
  json_t *req = json_object_get(root, "extensionsRequired");
  if (req && !json_is_array(req)) {
    s = hearth_err_set(err, HEARTH_E_PARSE, "%s: extensionsRequired: expected an array", name);
    goto done;
  }
  json_t *used = json_object_get(root, "extensionsUsed");
  if (used && !json_is_array(used)) {
    s = hearth_err_set(err, HEARTH_E_PARSE, "%s: extensionsUsed: expected an array", name);
    goto done;
  }
  for (size_t i = 0; i < json_array_size(used); i++) {
    json_t *e = json_array_get(used, i);
    if (json_is_string(e) && strcmp(json_string_value(e), "KHR_mesh_quantization") == 0)
      c.quantization = 1;
  }
  for (size_t i = 0; i < json_array_size(req); i++) {
    json_t *e = json_array_get(req, i);
    const char *en = json_is_string(e) ? json_string_value(e) : "?";
    /* the two extensions the reader applies (see mesh.h) */
    if (strcmp(en, "KHR_mesh_quantization") == 0) {
      c.quantization = 1;
      continue;
    }
    if (strcmp(en, "KHR_texture_transform") == 0) continue;
    const char *why = strcmp(en, "KHR_draco_mesh_compression") == 0 ? " (Draco compression)"
                      : strcmp(en, "EXT_meshopt_compression") == 0  ? " (meshopt compression)"
                                                                    : "";
    s = hearth_err_set(err, HEARTH_E_UNSUPPORTED,
                       "%s: extensionsRequired[%zu]: \"%s\"%s is not supported; re-export the "
                       "file without it",
                       name, i, en, why);
    goto done;
  }
  c.accessors = json_object_get(root, "accessors");
  c.views = json_object_get(root, "bufferViews");
  c.buffers = json_object_get(root, "buffers");
  c.meshes = json_object_get(root, "meshes");
  c.nodes = json_object_get(root, "nodes");
  const char *arrays[] = {"accessors", "bufferViews", "buffers",  "meshes", "nodes",
                          "scenes",    "materials",   "textures", "images", "samplers"};
  for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++) {
    json_t *a = json_object_get(root, arrays[i]);
    if (a && !json_is_array(a)) {
      s = hearth_err_set(err, HEARTH_E_PARSE, "%s: %s: expected an array", name, arrays[i]);
      goto done;
    }
  }

  if ((s = collect_instances(&c, &list))) goto done;

  /* pass 1: resolve every primitive of every instance and count */
  size_t total_prims = 0;
  for (size_t i = 0; i < list.n; i++) {
    json_t *pr = json_object_get(json_array_get(c.meshes, list.v[i].mesh), "primitives");
    if (!json_is_array(pr)) {
      s = hearth_err_set(err, HEARTH_E_PARSE, "%s: meshes[%zu].primitives: expected an array", name,
                         list.v[i].mesh);
      goto done;
    }
    if (!add_size(total_prims, json_array_size(pr), &total_prims)) {
      s = hearth_err_set(err, HEARTH_E_LIMIT, "%s: too many primitives", name);
      goto done;
    }
  }
  prims = hearth_calloc_array(total_prims ? total_prims : 1, sizeof *prims);
  if (!prims) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory (%zu primitives)", name,
                       total_prims);
    goto done;
  }
  size_t nv = 0, nt = 0, max_v;
  int all_uv = 1;
  if (!hearth_mul_size(o.max_triangles, 3, &max_v)) max_v = SIZE_MAX;
  if (max_v > UINT32_MAX) max_v = UINT32_MAX;
  for (size_t i = 0; i < list.n; i++) {
    size_t mi = list.v[i].mesh;
    json_t *pr = json_object_get(json_array_get(c.meshes, mi), "primitives");
    for (size_t p = 0; p < json_array_size(pr); p++) {
      glb_prim *gp = &prims[n_prims++];
      if ((s = resolve_primitive(&c, mi, p, json_array_get(pr, p), &o, gp))) goto done;
      gp->mesh = mi;
      gp->prim = p;
      gp->tbase = nt;
      all_uv &= gp->has_uv;
      if (!add_size(nt, gp->n_tris, &nt) || nt > o.max_triangles) {
        s = hearth_err_set(err, HEARTH_E_LIMIT,
                           "%s: meshes[%zu].primitives[%zu]: more than %zu triangles in the "
                           "scene (limit)",
                           name, mi, p, o.max_triangles);
        goto done;
      }
      if (!add_size(nv, gp->pos.count, &nv) || nv > max_v) {
        s = hearth_err_set(err, HEARTH_E_LIMIT,
                           "%s: meshes[%zu].primitives[%zu]: more than %zu vertices in the "
                           "scene (limit)",
                           name, mi, p, max_v);
        goto done;
      }
    }
  }
  if (nt == 0) {
    s = hearth_err_set(err, HEARTH_E_NOT_FOUND, "%s: the scene has no triangles", name);
    goto done;
  }

  /* pass 2: transform and copy */
  out->n_vertices = nv;
  out->n_triangles = nt;
  out->positions = hearth_alloc_array(nv, 3 * sizeof(float));
  out->indices = hearth_alloc_array(nt, 3 * sizeof(uint32_t));
  out->uvs = all_uv ? hearth_alloc_array(nv, 2 * sizeof(float)) : NULL;
  if (!out->positions || !out->indices || (all_uv && !out->uvs)) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "%s: out of memory (%zu vertices, %zu triangles)", name,
                       nv, nt);
    goto done;
  }
  size_t vbase = 0, tbase = 0, k = 0;
  for (size_t i = 0; i < list.n; i++) {
    const glb_inst *in = &list.v[i];
    const double *M = in->M;
    json_t *pr = json_object_get(json_array_get(c.meshes, in->mesh), "primitives");
    for (size_t p = 0; p < json_array_size(pr); p++, k++) {
      const glb_prim *gp = &prims[k];
      size_t n = gp->pos.count;
      for (size_t v = 0; v < n; v++) {
        double x = acc_get(&gp->pos, v, 0), y = acc_get(&gp->pos, v, 1),
               z = acc_get(&gp->pos, v, 2);
        float *dst = out->positions + 3 * (vbase + v);
        for (int r = 0; r < 3; r++)
          dst[r] = (float)(M[r] * x + M[4 + r] * y + M[8 + r] * z + M[12 + r]);
        if (!isfinite(dst[0]) || !isfinite(dst[1]) || !isfinite(dst[2])) {
          s = hearth_err_set(err, HEARTH_E_RANGE,
                             "%s: meshes[%zu].primitives[%zu].attributes.POSITION: vertex %zu "
                             "is not finite",
                             name, in->mesh, p, v);
          goto done;
        }
        if (out->uvs) {
          float u, w;
          if (gp->src.has_xform) {
            const double *xf = gp->src.xf;
            double a = acc_get(&gp->uv, v, 0), b = acc_get(&gp->uv, v, 1);
            u = (float)(xf[0] * a + xf[1] * b + xf[2]);
            w = (float)(xf[3] * a + xf[4] * b + xf[5]);
          } else {
            u = (float)acc_get(&gp->uv, v, 0);
            w = (float)acc_get(&gp->uv, v, 1);
          }
          if (!isfinite(u) || !isfinite(w)) {
            s = hearth_err_set(err, HEARTH_E_RANGE,
                               "%s: meshes[%zu].primitives[%zu].attributes.TEXCOORD_%zu: vertex "
                               "%zu is not finite%s",
                               name, in->mesh, p, gp->src.set, v,
                               gp->src.has_xform ? " after KHR_texture_transform" : "");
            goto done;
          }
          out->uvs[2 * (vbase + v)] = u;
          out->uvs[2 * (vbase + v) + 1] = w;
        }
      }
      for (size_t t = 0; t < gp->n_tris; t++) {
        uint32_t tri[3];
        for (int j = 0; j < 3; j++) {
          size_t corner = 3 * t + (size_t)j;
          uint32_t ix = gp->has_idx ? acc_index(&gp->idx, corner) : (uint32_t)corner;
          if (ix >= n) {
            s = hearth_err_set(err, HEARTH_E_RANGE,
                               "%s: meshes[%zu].primitives[%zu].indices: index %u at position "
                               "%zu (triangle %zu) is out of range; POSITION has %zu vertices",
                               name, in->mesh, p, ix, corner, t, n);
            goto done;
          }
          tri[j] = (uint32_t)(vbase + ix);
        }
        uint32_t *dst = out->indices + 3 * (tbase + t);
        dst[0] = tri[0];
        dst[1] = in->flip ? tri[2] : tri[1];
        dst[2] = in->flip ? tri[1] : tri[2];
      }
      vbase += n;
      tbase += gp->n_tris;
    }
  }

  if (out->uvs && !o.keep_uv_tiles && (s = fold_tiles(&c, prims, n_prims, &o, out, &rep)))
    goto done;
  for (size_t q = 0; q < n_prims; q++) {
    rep.quantized_primitives += prims[q].pos.comp_type != GL_FLOAT ||
                                (prims[q].has_uv && prims[q].uv.comp_type != GL_FLOAT);
    rep.transformed_primitives += prims[q].has_uv && prims[q].src.has_xform;
  }

  /* base colour texture of the first primitive (in scene order) that has one */
  if (o.load_texture) {
    int got = 0;
    for (size_t i = 0; i < list.n && !got; i++) {
      json_t *pr = json_object_get(json_array_get(c.meshes, list.v[i].mesh), "primitives");
      for (size_t p = 0; p < json_array_size(pr) && !got; p++)
        if ((s = load_base_color(&c, json_array_get(pr, p), &out->texture, &got))) goto done;
    }
  }
  s = HEARTH_OK;
  if (o.report) *o.report = rep;

done:
  free(prims);
  free(list.v);
  json_decref(root);
  if (s) {
    free(out->positions);
    free(out->uvs);
    free(out->indices);
    hearth_image_free(&out->texture);
    memset(out, 0, sizeof *out);
  }
  return s;
}

hearth_status hearth_glb_read(const char *path, const hearth_glb_read_opts *opts, hearth_mesh *out,
                              hearth_err *err) {
  uint8_t *data = NULL;
  size_t size = 0;
  if (out) memset(out, 0, sizeof *out);
  /* the 12-byte header first: a file that is not a GLB, or whose declared
   * length is not its size, is refused before anything large is read */
  int fd = -1;
  size_t fsize = 0;
  hearth_status s = hearth_open_regular(path, &fd, &fsize, err);
  if (s) return s;
  uint8_t head[12];
  ssize_t got = read(fd, head, sizeof head);
  close(fd);
  if (got < 0)
    return hearth_err_set(err, HEARTH_E_IO, "%s: cannot read: %s", path, strerror(errno));
  if ((s = check_header(head, (size_t)got, fsize, path, err))) return s;
  s = hearth_read_file(path, GLB_MAX_FILE, &data, &size, err);
  if (s) return s;
  s = hearth_glb_parse(data, size, path, opts, out, err);
  free(data);
  return s;
}

/* ==== writer ================================================================ */

/* Append a bufferView {buffer 0, offset, length[, target]}. */
static int add_view(json_t *views, size_t off, size_t len, int target) {
  json_t *v = json_object();
  if (!v) return 0;
  json_object_set_new(v, "buffer", json_integer(0));
  json_object_set_new(v, "byteOffset", json_integer((json_int_t)off));
  json_object_set_new(v, "byteLength", json_integer((json_int_t)len));
  if (target) json_object_set_new(v, "target", json_integer(target));
  return json_array_append_new(views, v) == 0;
}

static json_t *make_accessor(size_t view, int ctype, size_t count, const char *type) {
  json_t *a = json_object();
  if (!a) return NULL;
  json_object_set_new(a, "bufferView", json_integer((json_int_t)view));
  json_object_set_new(a, "componentType", json_integer(ctype));
  json_object_set_new(a, "count", json_integer((json_int_t)count));
  json_object_set_new(a, "type", json_string(type));
  return a;
}

static json_t *vec3_json(const float v[3]) {
  json_t *a = json_array();
  for (int i = 0; i < 3; i++) json_array_append_new(a, json_real((double)v[i]));
  return a;
}

/* the GLB of m; tex_png: m->texture already PNG-encoded (its tex_size bytes
   are embedded as they are), NULL: encoded here */
static hearth_status glb_encode(const hearth_mesh *m, const uint8_t *tex_png, size_t tex_size,
                                uint8_t **out, size_t *size, hearth_err *err) {
  if (!m || !out || !size) return hearth_err_set(err, HEARTH_E_ARG, "glb encode: NULL argument");
  *out = NULL;
  *size = 0;
  size_t nv = m->n_vertices, nt = m->n_triangles;
  if (!nv || !nt || !m->positions || !m->indices)
    return hearth_err_set(err, HEARTH_E_SIZE,
                          "glb encode: empty mesh (%zu vertices, %zu triangles); glTF accessors "
                          "need at least one element",
                          nv, nt);
  if (nv > UINT32_MAX)
    return hearth_err_set(err, HEARTH_E_LIMIT, "glb encode: %zu vertices exceed uint32 indices",
                          nv);
  /* the file must be valid: indices in range, finite numbers */
  for (size_t t = 0; t < nt; t++)
    for (int j = 0; j < 3; j++)
      if (m->indices[3 * t + j] >= nv)
        return hearth_err_set(err, HEARTH_E_RANGE,
                              "glb encode: triangle %zu: index %u out of range (%zu vertices)", t,
                              m->indices[3 * t + j], nv);
  for (size_t i = 0; i < 3 * nv; i++)
    if (!isfinite(m->positions[i]))
      return hearth_err_set(err, HEARTH_E_RANGE, "glb encode: vertex %zu: non-finite position",
                            i / 3);
  if (m->uvs)
    for (size_t i = 0; i < 2 * nv; i++)
      if (!isfinite(m->uvs[i]))
        return hearth_err_set(err, HEARTH_E_RANGE, "glb encode: vertex %zu: non-finite UV", i / 2);

  hearth_status s = HEARTH_OK;
  uint8_t *png = NULL, *bin = NULL, *file = NULL;
  const uint8_t *png_bytes = NULL; /* png, or the caller's tex_png */
  size_t png_size = 0;
  double *nacc = NULL;
  char *jtext = NULL;
  json_t *root = NULL;
  if (m->texture.data) {
    if (m->texture.type != HEARTH_PIX_U8)
      return hearth_err_set(err, HEARTH_E_ARG, "glb encode: texture must be 8-bit");
    if (tex_png) {
      png_bytes = tex_png;
      png_size = tex_size;
    } else {
      if ((s = hearth_png_encode(&m->texture, &png, &png_size, err))) return s;
      png_bytes = png;
    }
  }

  /* BIN layout: positions | normals | uvs | indices | png, each 4-aligned */
  size_t sz_pos = 0, sz_uv = 0, sz_idx = 0, off_nrm, off_uv = 0, off_idx = 0, off_png = 0,
         bin_len = 0;
  int ok = hearth_mul_size(nv, 12, &sz_pos) && hearth_mul_size(nt, 12, &sz_idx) &&
           (!m->uvs || hearth_mul_size(nv, 8, &sz_uv));
  off_nrm = sz_pos;
  ok = ok && add_size(off_nrm, sz_pos, &off_uv) && add_size(off_uv, sz_uv, &off_idx) &&
       add_size(off_idx, sz_idx, &off_png) && add_size(off_png, png_size, &bin_len) &&
       bin_len <= UINT32_MAX - 64;
  if (!ok) {
    s = hearth_err_set(err, HEARTH_E_LIMIT, "glb encode: mesh too large for a GLB");
    goto done;
  }
  size_t bin_pad = (bin_len + 3) & ~(size_t)3;
  bin = calloc(bin_pad ? bin_pad : 1, 1);
  nacc = hearth_calloc_array(nv, 3 * sizeof(double));
  if (!bin || !nacc) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "glb encode: out of memory");
    goto done;
  }

  /* area-weighted normals: the unnormalised face normal is twice the area */
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *ix = m->indices + 3 * t;
    const float *a = m->positions + 3 * ix[0], *b = m->positions + 3 * ix[1],
                *c = m->positions + 3 * ix[2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 3; k++) nacc[3 * ix[j] + k] += n[k];
  }
  float pmin[3], pmax[3];
  for (int k = 0; k < 3; k++) pmin[k] = pmax[k] = m->positions[k];
  for (size_t i = 0; i < nv; i++) {
    const double *n = nacc + 3 * i;
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    /* unused or degenerate vertices still need a unit normal */
    float nf[3] = {0.0f, 0.0f, 1.0f};
    if (len > 1e-30 && isfinite(len))
      for (int k = 0; k < 3; k++) nf[k] = (float)(n[k] / len);
    for (int k = 0; k < 3; k++) {
      float p = m->positions[3 * i + k];
      if (p < pmin[k]) pmin[k] = p;
      if (p > pmax[k]) pmax[k] = p;
      wr_f32(bin + 12 * i + 4 * k, p);
      wr_f32(bin + off_nrm + 12 * i + 4 * k, nf[k]);
    }
    if (m->uvs) {
      wr_f32(bin + off_uv + 8 * i, m->uvs[2 * i]);
      wr_f32(bin + off_uv + 8 * i + 4, m->uvs[2 * i + 1]);
    }
  }
  for (size_t i = 0; i < 3 * nt; i++) wr_u32(bin + off_idx + 4 * i, m->indices[i]);
  if (png_size) memcpy(bin + off_png, png_bytes, png_size);

  /* JSON: one scene, node, mesh, primitive, material */
  root = json_object();
  json_t *asset = json_object(), *views = json_array(), *accs = json_array();
  json_object_set_new(asset, "generator", json_string("hearth " HEARTH_VERSION));
  json_object_set_new(asset, "version", json_string("2.0"));
  json_object_set_new(root, "asset", asset);
  json_object_set_new(root, "scene", json_integer(0));
  json_t *scene = json_object(), *scenes = json_array(), *roots = json_array();
  json_array_append_new(roots, json_integer(0));
  json_object_set_new(scene, "nodes", roots);
  json_array_append_new(scenes, scene);
  json_object_set_new(root, "scenes", scenes);
  json_t *node = json_object(), *nodes = json_array();
  json_object_set_new(node, "mesh", json_integer(0));
  json_array_append_new(nodes, node);
  json_object_set_new(root, "nodes", nodes);

  size_t vi = 0;
  ok = add_view(views, 0, sz_pos, 34962) && add_view(views, off_nrm, sz_pos, 34962);
  size_t view_pos = vi++, view_nrm = vi++, view_uv = 0, view_idx, view_png = 0;
  if (m->uvs) {
    ok = ok && add_view(views, off_uv, sz_uv, 34962);
    view_uv = vi++;
  }
  ok = ok && add_view(views, off_idx, sz_idx, 34963);
  view_idx = vi++;
  if (png_size) {
    ok = ok && add_view(views, off_png, png_size, 0);
    view_png = vi++;
  }

  json_t *a_pos = make_accessor(view_pos, GL_FLOAT, nv, "VEC3");
  json_object_set_new(a_pos, "min", vec3_json(pmin));
  json_object_set_new(a_pos, "max", vec3_json(pmax));
  json_array_append_new(accs, a_pos);
  json_array_append_new(accs, make_accessor(view_nrm, GL_FLOAT, nv, "VEC3"));
  size_t acc_idx = 2, acc_uv = 0;
  if (m->uvs) {
    json_array_append_new(accs, make_accessor(view_uv, GL_FLOAT, nv, "VEC2"));
    acc_uv = acc_idx++;
  }
  json_array_append_new(accs, make_accessor(view_idx, GL_UNSIGNED_INT, 3 * nt, "SCALAR"));
  size_t acc_ix = acc_idx++;

  json_t *attrs = json_object();
  json_object_set_new(attrs, "POSITION", json_integer(0));
  json_object_set_new(attrs, "NORMAL", json_integer(1));
  if (m->uvs) json_object_set_new(attrs, "TEXCOORD_0", json_integer((json_int_t)acc_uv));
  json_t *prim = json_object(), *prims = json_array(), *mesh = json_object(),
         *meshes = json_array();
  json_object_set_new(prim, "attributes", attrs);
  json_object_set_new(prim, "indices", json_integer((json_int_t)acc_ix));
  json_object_set_new(prim, "material", json_integer(0));
  json_object_set_new(prim, "mode", json_integer(4));
  json_array_append_new(prims, prim);
  json_object_set_new(mesh, "name", json_string("hearth_mesh"));
  json_object_set_new(mesh, "primitives", prims);
  json_array_append_new(meshes, mesh);
  json_object_set_new(root, "meshes", meshes);

  /* non-metallic so viewers show the texture as captured */
  json_t *mat = json_object(), *pbr = json_object(), *mats = json_array();
  json_object_set_new(pbr, "metallicFactor", json_real(0.0));
  json_object_set_new(pbr, "roughnessFactor", json_real(1.0));
  if (png_size) {
    json_t *bct = json_object();
    json_object_set_new(bct, "index", json_integer(0));
    json_object_set_new(pbr, "baseColorTexture", bct);
  }
  json_object_set_new(mat, "name", json_string("hearth_material"));
  json_object_set_new(mat, "pbrMetallicRoughness", pbr);
  json_array_append_new(mats, mat);
  json_object_set_new(root, "materials", mats);
  if (png_size) {
    json_t *smp = json_object(), *smps = json_array();
    json_object_set_new(smp, "magFilter", json_integer(9729)); /* LINEAR */
    json_object_set_new(smp, "minFilter", json_integer(9987)); /* LINEAR_MIPMAP_LINEAR */
    json_object_set_new(smp, "wrapS", json_integer(33071));    /* CLAMP_TO_EDGE */
    json_object_set_new(smp, "wrapT", json_integer(33071));
    json_array_append_new(smps, smp);
    json_object_set_new(root, "samplers", smps);
    json_t *tex = json_object(), *texs = json_array();
    json_object_set_new(tex, "sampler", json_integer(0));
    json_object_set_new(tex, "source", json_integer(0));
    json_array_append_new(texs, tex);
    json_object_set_new(root, "textures", texs);
    json_t *img = json_object(), *imgs = json_array();
    json_object_set_new(img, "bufferView", json_integer((json_int_t)view_png));
    json_object_set_new(img, "mimeType", json_string("image/png"));
    json_array_append_new(imgs, img);
    json_object_set_new(root, "images", imgs);
  }
  json_object_set_new(root, "accessors", accs);
  json_object_set_new(root, "bufferViews", views);
  json_t *buf = json_object(), *bufs = json_array();
  json_object_set_new(buf, "byteLength", json_integer((json_int_t)bin_len));
  json_array_append_new(bufs, buf);
  json_object_set_new(root, "buffers", bufs);

  jtext = ok ? json_dumps(root, JSON_COMPACT) : NULL;
  if (!jtext) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "glb encode: cannot build the JSON chunk");
    goto done;
  }
  size_t jlen = strlen(jtext), jpad = (jlen + 3) & ~(size_t)3;
  size_t total = 12 + 8 + jpad + 8 + bin_pad;
  if (total > UINT32_MAX) {
    s = hearth_err_set(err, HEARTH_E_LIMIT, "glb encode: %zu bytes exceed the GLB limit", total);
    goto done;
  }
  file = malloc(total);
  if (!file) {
    s = hearth_err_set(err, HEARTH_E_NOMEM, "glb encode: out of memory (%zu bytes)", total);
    goto done;
  }
  wr_u32(file, GLB_MAGIC);
  wr_u32(file + 4, 2);
  wr_u32(file + 8, (uint32_t)total);
  wr_u32(file + 12, (uint32_t)jpad);
  wr_u32(file + 16, GLB_CHUNK_JSON);
  memcpy(file + 20, jtext, jlen);
  memset(file + 20 + jlen, ' ', jpad - jlen);
  uint8_t *bc = file + 20 + jpad;
  wr_u32(bc, (uint32_t)bin_pad);
  wr_u32(bc + 4, GLB_CHUNK_BIN);
  memcpy(bc + 8, bin, bin_pad);
  *out = file;
  *size = total;
  file = NULL;

done:
  free(file);
  free(jtext);
  json_decref(root);
  free(nacc);
  free(bin);
  free(png);
  return s;
}

hearth_status hearth_glb_encode(const hearth_mesh *m, uint8_t **out, size_t *size,
                                hearth_err *err) {
  return glb_encode(m, NULL, 0, out, size, err);
}

static hearth_status glb_write(const char *path, const hearth_mesh *m, const uint8_t *tex_png,
                               size_t tex_size, hearth_err *err) {
  uint8_t *data = NULL;
  size_t size = 0;
  hearth_status s = glb_encode(m, tex_png, tex_size, &data, &size, err);
  if (s) {
    hearth_err_prefix(err, "%s", path);
    return s;
  }
  s = hearth_write_file_atomic(path, data, size, err);
  free(data);
  return s;
}

hearth_status hearth_glb_write(const char *path, const hearth_mesh *m, hearth_err *err) {
  return glb_write(path, m, NULL, 0, err);
}

hearth_status hearth_glb_write_png(const char *path, const hearth_mesh *m, const uint8_t *tex_png,
                                   size_t tex_size, hearth_err *err) {
  if (!tex_png || !tex_size)
    return hearth_err_set(err, HEARTH_E_ARG, "%s: glb encode: no texture PNG bytes", path);
  return glb_write(path, m, tex_png, tex_size, err);
}

void hearth_glb_read_opts_default(hearth_glb_read_opts *o) { memset(o, 0, sizeof *o); }
