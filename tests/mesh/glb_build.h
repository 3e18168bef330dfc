/* A small GLB writer for the reader's tests, and the cube they share. The
 * writer puts one mesh of one primitive on one node (optional scale and
 * translation): POSITION and up to two UV sets stored as any component
 * type, and an optional embedded base colour texture with a sampler and a
 * KHR_texture_transform. Values are given as doubles in the stored type's
 * units (already quantised for integer types); accessor min/max are
 * computed from them as the spec requires. The files are meant to pass the
 * Khronos validator. */
#ifndef HEARTH_TESTS_GLB_BUILD_H
#define HEARTH_TESTS_GLB_BUILD_H
#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/image.h"
#include "hearth/mesh.h"

#define TB_FLOAT 5126
#define TB_BYTE 5120
#define TB_UBYTE 5121
#define TB_SHORT 5122
#define TB_USHORT 5123

typedef struct tb_glb {
  size_t nv, nt;
  const double *pos;      /* 3 per vertex */
  int pos_type, pos_norm; /* componentType (0: FLOAT), normalized */
  const double *uv[2];    /* TEXCOORD_0, TEXCOORD_1: 2 per vertex, or NULL */
  int uv_type, uv_norm;
  const uint32_t *idx;               /* 3 per triangle */
  const double *scale, *translation; /* node TRS parts, 3 each, or NULL */
  int texture;                       /* embed a 4x4 PNG as the base colour texture */
  int wrap_s, wrap_t;                /* sampler wrap modes; both 0: no sampler */
  int tex_coord;                     /* textureInfo.texCoord; < 0: absent */
  const char *transform;             /* JSON object text of KHR_texture_transform, or NULL */
  int quantization;                  /* declare KHR_mesh_quantization (used and required) */
  int transform_required;            /* list KHR_texture_transform in extensionsRequired too */
  const char *required_extra;        /* one more extension, used and required, or NULL */
} tb_glb;

static size_t tb_csize(int t) {
  return t == TB_BYTE || t == TB_UBYTE ? 1 : t == TB_SHORT || t == TB_USHORT ? 2 : 4;
}

static void tb_put(uint8_t *p, int t, double v) {
  switch (t) {
    case TB_BYTE: *(int8_t *)p = (int8_t)lrint(v); break;
    case TB_UBYTE: *p = (uint8_t)lrint(v); break;
    case TB_SHORT: {
      int16_t s = (int16_t)lrint(v);
      memcpy(p, &s, 2);
      break;
    }
    case TB_USHORT: {
      uint16_t s = (uint16_t)lrint(v);
      memcpy(p, &s, 2);
      break;
    }
    default: {
      float f = (float)v;
      memcpy(p, &f, 4);
    }
  }
}

/* append one attribute (its own bufferView, elements 4-byte aligned) */
static void tb_attr(json_t *views, json_t *accs, uint8_t *bin, size_t *len, const double *v,
                    size_t n, int ncomp, int ctype, int norm) {
  if (!ctype) ctype = TB_FLOAT;
  size_t elem = (size_t)ncomp * tb_csize(ctype), stride = (elem + 3) & ~(size_t)3;
  double lo[3], hi[3];
  for (int k = 0; k < ncomp; k++) lo[k] = INFINITY, hi[k] = -INFINITY;
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < ncomp; k++) {
      double x = v[i * ncomp + k];
      if (ctype != TB_FLOAT) x = (double)lrint(x);
      else x = (double)(float)x;
      tb_put(bin + *len + i * stride + (size_t)k * tb_csize(ctype), ctype, x);
      lo[k] = x < lo[k] ? x : lo[k];
      hi[k] = x > hi[k] ? x : hi[k];
    }
  json_t *bv = json_pack("{s:i,s:I,s:I,s:i}", "buffer", 0, "byteOffset", (json_int_t)*len,
                         "byteLength", (json_int_t)(stride * n), "target", 34962);
  if (stride != elem) json_object_set_new(bv, "byteStride", json_integer((json_int_t)stride));
  json_t *a = json_pack("{s:I,s:i,s:I,s:s}", "bufferView", (json_int_t)json_array_size(views),
                        "componentType", ctype, "count", (json_int_t)n, "type",
                        ncomp == 3 ? "VEC3" : "VEC2");
  if (norm) json_object_set_new(a, "normalized", json_true());
  json_t *jl = json_array(), *jh = json_array();
  for (int k = 0; k < ncomp; k++) {
    json_array_append_new(jl,
                          ctype == TB_FLOAT ? json_real(lo[k]) : json_integer((json_int_t)lo[k]));
    json_array_append_new(jh,
                          ctype == TB_FLOAT ? json_real(hi[k]) : json_integer((json_int_t)hi[k]));
  }
  json_object_set_new(a, "min", jl);
  json_object_set_new(a, "max", jh);
  json_array_append_new(views, bv);
  json_array_append_new(accs, a);
  *len += stride * n;
}

/* the file's bytes (malloc'ed), or NULL */
static uint8_t *tb_encode(const tb_glb *g, size_t *size) {
  uint8_t *png = NULL;
  size_t png_size = 0;
  if (g->texture) {
    hearth_image img = {0};
    hearth_err e = {0};
    if (hearth_image_alloc(&img, 4, 4, 3, HEARTH_PIX_U8, &e)) return NULL;
    for (size_t i = 0; i < 48; i++) ((uint8_t *)img.data)[i] = (uint8_t)(i * 5);
    hearth_status s = hearth_png_encode(&img, &png, &png_size, &e);
    hearth_image_free(&img);
    if (s) return NULL;
  }
  size_t cap = g->nv * 40 + g->nt * 12 + png_size + 64;
  uint8_t *bin = calloc(cap, 1);
  size_t len = 0;
  json_t *views = json_array(), *accs = json_array(), *attrs = json_object();
  tb_attr(views, accs, bin, &len, g->pos, g->nv, 3, g->pos_type, g->pos_norm);
  json_object_set_new(attrs, "POSITION", json_integer(0));
  for (int s = 0; s < 2; s++)
    if (g->uv[s]) {
      char name[16];
      snprintf(name, sizeof name, "TEXCOORD_%d", s);
      json_object_set_new(attrs, name, json_integer((json_int_t)json_array_size(accs)));
      tb_attr(views, accs, bin, &len, g->uv[s], g->nv, 2, g->uv_type, g->uv_norm);
    }
  size_t ioff = len;
  for (size_t i = 0; i < 3 * g->nt; i++) {
    memcpy(bin + len, &g->idx[i], 4);
    len += 4;
  }
  json_array_append_new(views,
                        json_pack("{s:i,s:I,s:I,s:i}", "buffer", 0, "byteOffset", (json_int_t)ioff,
                                  "byteLength", (json_int_t)(len - ioff), "target", 34963));
  json_array_append_new(accs, json_pack("{s:I,s:i,s:I,s:s}", "bufferView",
                                        (json_int_t)json_array_size(views) - 1, "componentType",
                                        5125, "count", (json_int_t)(3 * g->nt), "type", "SCALAR"));
  json_t *prim = json_pack("{s:o,s:I,s:i}", "attributes", attrs, "indices",
                           (json_int_t)json_array_size(accs) - 1, "mode", 4);
  json_t *root = json_pack("{s:{s:s},s:i,s:[{s:[i]}]}", "asset", "version", "2.0", "scene", 0,
                           "scenes", "nodes", 0);
  json_t *node = json_pack("{s:i}", "mesh", 0);
  if (g->scale)
    json_object_set_new(node, "scale", json_pack("[f,f,f]", g->scale[0], g->scale[1], g->scale[2]));
  if (g->translation)
    json_object_set_new(node, "translation",
                        json_pack("[f,f,f]", g->translation[0], g->translation[1],
                                  g->translation[2]));
  json_object_set_new(root, "nodes", json_pack("[o]", node));
  json_t *used = json_array(), *req = json_array();
  if (g->quantization) {
    json_array_append_new(used, json_string("KHR_mesh_quantization"));
    json_array_append_new(req, json_string("KHR_mesh_quantization"));
  }
  if (g->texture) {
    json_object_set_new(prim, "material", json_integer(0));
    size_t poff = len;
    memcpy(bin + len, png, png_size);
    len += png_size;
    json_array_append_new(views, json_pack("{s:i,s:I,s:I}", "buffer", 0, "byteOffset",
                                           (json_int_t)poff, "byteLength", (json_int_t)png_size));
    json_t *bct = json_pack("{s:i}", "index", 0);
    if (g->tex_coord >= 0) json_object_set_new(bct, "texCoord", json_integer(g->tex_coord));
    if (g->transform) {
      json_error_t je;
      json_t *tt = json_loads(g->transform, 0, &je);
      json_object_set_new(bct, "extensions", json_pack("{s:o}", "KHR_texture_transform", tt));
      json_array_append_new(used, json_string("KHR_texture_transform"));
      if (g->transform_required) json_array_append_new(req, json_string("KHR_texture_transform"));
    }
    json_object_set_new(root, "materials",
                        json_pack("[{s:{s:o,s:f}}]", "pbrMetallicRoughness", "baseColorTexture",
                                  bct, "metallicFactor", 0.0));
    json_t *tex = json_pack("{s:i}", "source", 0);
    if (g->wrap_s || g->wrap_t) {
      json_object_set_new(tex, "sampler", json_integer(0));
      json_object_set_new(root, "samplers",
                          json_pack("[{s:i,s:i}]", "wrapS", g->wrap_s ? g->wrap_s : 10497, "wrapT",
                                    g->wrap_t ? g->wrap_t : 10497));
    }
    json_object_set_new(root, "textures", json_pack("[o]", tex));
    json_object_set_new(root, "images",
                        json_pack("[{s:I,s:s}]", "bufferView",
                                  (json_int_t)json_array_size(views) - 1, "mimeType", "image/png"));
  }
  if (g->required_extra) {
    json_array_append_new(used, json_string(g->required_extra));
    json_array_append_new(req, json_string(g->required_extra));
  }
  if (json_array_size(used)) json_object_set_new(root, "extensionsUsed", used);
  else json_decref(used);
  if (json_array_size(req)) json_object_set_new(root, "extensionsRequired", req);
  else json_decref(req);
  json_object_set_new(root, "meshes", json_pack("[{s:[o]}]", "primitives", prim));
  json_object_set_new(root, "accessors", accs);
  json_object_set_new(root, "bufferViews", views);
  size_t blen = (len + 3) & ~(size_t)3;
  json_object_set_new(root, "buffers", json_pack("[{s:I}]", "byteLength", (json_int_t)blen));
  char *js = json_dumps(root, JSON_COMPACT);
  json_decref(root);
  size_t jl = strlen(js), jp = (jl + 3) & ~(size_t)3, total = 12 + 8 + jp + 8 + blen;
  uint8_t *f = calloc(total, 1);
  uint32_t hdr[5] = {0x46546C67u, 2, (uint32_t)total, (uint32_t)jp, 0x4E4F534Au};
  memcpy(f, hdr, sizeof hdr); /* little-endian hosts only, as the tests run */
  memcpy(f + 20, js, jl);
  memset(f + 20 + jl, ' ', jp - jl);
  uint32_t bh[2] = {(uint32_t)blen, 0x004E4942u};
  memcpy(f + 20 + jp, bh, 8);
  memcpy(f + 28 + jp, bin, len);
  free(js);
  free(bin);
  free(png);
  *size = total;
  return f;
}

/* ---- the cube: 6 faces, each its own UV island in a 3 x 2 atlas ------------ */
#define CUBE_NV 24
#define CUBE_NT 12
static double g_pos[CUBE_NV * 3], g_uv[CUBE_NV * 2];
static uint32_t g_idx[CUBE_NT * 3];

/* face f: 4 vertices 4f..4f+3, counter-clockwise from outside; UV cell
 * (f % 3, f / 3) of 0.25 x 0.25 at multiples of 1/16 (exact under any
 * whole-tile shift) */
static void tb_cube_init(void) {
  static const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  static const double cu[4] = {0, 1, 1, 0}, cv[4] = {0, 0, 1, 1};
  for (int f = 0; f < 6; f++) {
    double u0 = 0.0625 + 0.3125 * (f % 3), v0 = 0.0625 + 0.4375 * (f / 3);
    for (int k = 0; k < 4; k++) {
      int c = quads[f][k], v = 4 * f + k;
      g_pos[3 * v] = (c & 1) ? 0.5 : -0.5;
      g_pos[3 * v + 1] = (c & 2) ? 0.5 : -0.5;
      g_pos[3 * v + 2] = (c & 4) ? 0.5 : -0.5;
      g_uv[2 * v] = u0 + 0.25 * cu[k];
      g_uv[2 * v + 1] = v0 + 0.25 * cv[k];
    }
    uint32_t b = (uint32_t)(4 * f), *t = g_idx + 6 * f;
    t[0] = b, t[1] = b + 1, t[2] = b + 2, t[3] = b, t[4] = b + 2, t[5] = b + 3;
  }
}

/* ---- the cube quantised --------------------------------------------------------- */
/* A component type as KHR_mesh_quantization allows it for POSITION and
 * TEXCOORD: stored values c in [cmin, cmax], decoded c * dec. */
typedef struct tb_qtype {
  int ctype, norm;
  double cmin, cmax, dec;
} tb_qtype;
#define TB_N_QTYPES 8
static const tb_qtype tb_qtypes[TB_N_QTYPES] = {
    {TB_BYTE, 1, -127, 127, 1.0 / 127},        {TB_BYTE, 0, -127, 127, 1},
    {TB_UBYTE, 1, 0, 255, 1.0 / 255},          {TB_UBYTE, 0, 0, 255, 1},
    {TB_SHORT, 1, -32767, 32767, 1.0 / 32767}, {TB_SHORT, 0, -32767, 32767, 1},
    {TB_USHORT, 1, 0, 65535, 1.0 / 65535},     {TB_USHORT, 0, 0, 65535, 1},
};

/* The cube (tb_cube_init first) scaled into the box [lo, hi], positions and
 * UVs stored as type q over its whole range: the node's scale and
 * translation dequantise the positions, KHR_texture_transform's offset and
 * scale the UVs (in [0,1] again). ref: the float positions. */
typedef struct tb_qcube {
  double pos[CUBE_NV * 3], ref[CUBE_NV * 3], uv[CUBE_NV * 2];
  double scale[3], trans[3], us, uo;
  char xf[200];
  tb_glb g;
} tb_qcube;

static void tb_quantized_cube(const tb_qtype *q, const double lo[3], const double hi[3],
                              tb_qcube *c) {
  double span = q->cmax - q->cmin;
  for (int k = 0; k < 3; k++) {
    c->scale[k] = (hi[k] - lo[k]) / (span * q->dec);
    c->trans[k] = lo[k] - q->cmin * q->dec * c->scale[k];
  }
  for (int v = 0; v < CUBE_NV; v++)
    for (int k = 0; k < 3; k++) {
      double t01 = g_pos[3 * v + k] + 0.5;
      c->ref[3 * v + k] = lo[k] + t01 * (hi[k] - lo[k]);
      c->pos[3 * v + k] = round(q->cmin + t01 * span);
    }
  c->us = 1.0 / (span * q->dec);
  c->uo = -q->cmin * q->dec * c->us;
  for (int i = 0; i < 2 * CUBE_NV; i++) c->uv[i] = round(q->cmin + g_uv[i] * span);
  snprintf(c->xf, sizeof c->xf, "{\"offset\":[%.17g,%.17g],\"scale\":[%.17g,%.17g]}", c->uo, c->uo,
           c->us, c->us);
  memset(&c->g, 0, sizeof c->g);
  c->g.nv = CUBE_NV, c->g.nt = CUBE_NT, c->g.idx = g_idx;
  c->g.pos = c->pos, c->g.pos_type = q->ctype, c->g.pos_norm = q->norm;
  c->g.uv[0] = c->uv, c->g.uv_type = q->ctype, c->g.uv_norm = q->norm;
  c->g.scale = c->scale, c->g.translation = c->trans;
  c->g.texture = 1, c->g.tex_coord = -1, c->g.transform = c->xf, c->g.quantization = 1;
}

#endif
