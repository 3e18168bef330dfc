/* Every GLB hearth writes must pass the Khronos glTF validator (npm package
 * gltf-validator, installed into $HEARTH_SOURCE_DIR/.tools by
 * scripts/setup.sh). Writes a textured, an untextured and a UV-less mesh,
 * runs tests/mesh/validate_glb.js on each and asserts zero errors; a
 * deliberately broken file must be flagged so the check cannot pass
 * vacuously. The reader's own fixtures (glb_build.h: the cube quantised in
 * every KHR_mesh_quantization type, with KHR_texture_transform, and with
 * UVs in other tiles) and the fuzz corpus's valid_*.glb must be valid
 * files too. Missing node or package is a failure, not a skip. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include "glb_build.h"
#include "hearth/mesh.h"
#include "test_util.h"

/* A closed UV sphere (lat/long grid with duplicated seam vertices), with a
 * checker texture of size tex x tex when tex > 0. */
static void make_sphere(hearth_mesh *m, int with_uvs, size_t tex) {
  hearth_err e = {0};
  const size_t nu = 16, nv = 9; /* columns, rows of vertices */
  CHECK_OK(hearth_mesh_alloc(m, nu * nv, 2 * (nu - 1) * (nv - 1), with_uvs, &e), &e);
  const double pi = 3.14159265358979323846;
  for (size_t r = 0; r < nv; r++)
    for (size_t c = 0; c < nu; c++) {
      double th = pi * (double)r / (double)(nv - 1), ph = 2 * pi * (double)c / (double)(nu - 1);
      float *p = m->positions + 3 * (r * nu + c);
      p[0] = (float)(0.1 * sin(th) * cos(ph));
      p[1] = (float)(0.1 * cos(th));
      p[2] = (float)(-0.1 * sin(th) * sin(ph));
      if (with_uvs) {
        m->uvs[2 * (r * nu + c)] = (float)c / (float)(nu - 1);
        m->uvs[2 * (r * nu + c) + 1] = (float)r / (float)(nv - 1);
      }
    }
  size_t t = 0;
  for (size_t r = 0; r + 1 < nv; r++)
    for (size_t c = 0; c + 1 < nu; c++) {
      uint32_t a = (uint32_t)(r * nu + c), b = a + 1, d = (uint32_t)((r + 1) * nu + c), f = d + 1;
      uint32_t *ix = m->indices + 3 * t;
      ix[0] = a, ix[1] = d, ix[2] = b;
      ix[3] = b, ix[4] = d, ix[5] = f;
      t += 2;
    }
  if (tex) {
    CHECK_OK(hearth_image_alloc(&m->texture, tex, tex, 3, HEARTH_PIX_U8, &e), &e);
    uint8_t *px = m->texture.data;
    for (size_t y = 0; y < tex; y++)
      for (size_t x = 0; x < tex; x++) {
        uint8_t v = ((x / 4 + y / 4) & 1) ? 230 : 40;
        px[3 * (y * tex + x)] = v;
        px[3 * (y * tex + x) + 1] = (uint8_t)(x * 255 / tex);
        px[3 * (y * tex + x) + 2] = (uint8_t)(y * 255 / tex);
      }
  }
}

/* exit status of `node validate_glb.js path`, or -1 if it could not run */
static int run_validator(const char *src, const char *path) {
  char cmd[4096];
  snprintf(cmd, sizeof cmd, "node '%s/tests/mesh/validate_glb.js' '%s'", src, path);
  int rc = system(cmd);
  if (rc == -1 || !WIFEXITED(rc)) return -1;
  return WEXITSTATUS(rc);
}

int main(void) {
  const char *src = getenv("HEARTH_SOURCE_DIR");
  if (!src || !*src) src = ".";
  if (system("node --version >/dev/null 2>&1") != 0) {
    fprintf(stderr,
            "FAIL: node is not installed; run scripts/setup.sh (CI installs node and "
            "the gltf-validator package)\n");
    return 1;
  }
  char pkg[4096];
  snprintf(pkg, sizeof pkg, "%s/.tools/node_modules/gltf-validator/package.json", src);
  if (!hearth_path_exists(pkg)) {
    fprintf(stderr,
            "FAIL: %s is missing; run scripts/setup.sh to install the Khronos glTF "
            "validator (npm package gltf-validator) into %s/.tools\n",
            pkg, src);
    return 1;
  }

  const char *dir = test_tmpdir("mesh_glb_validator");
  char path[1200];
  hearth_err e = {0};
  struct {
    const char *name;
    int uvs;
    size_t tex;
  } cases[] = {{"textured.glb", 1, 64},
               {"textured_npot.glb", 1, 24},
               {"untextured.glb", 1, 0},
               {"no_uvs.glb", 0, 0}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    hearth_mesh m;
    make_sphere(&m, cases[i].uvs, cases[i].tex);
    snprintf(path, sizeof path, "%s/%s", dir, cases[i].name);
    CHECK_OK(hearth_glb_write(path, &m, &e), &e);
    int rc = run_validator(src, path);
    CHECK_MSG(rc == 0, "%s: validator exit status %d (1: errors, 3: package missing)", path, rc);
    hearth_mesh_free(&m);
  }

  /* a degenerate triangle and an unused vertex: normals must still be unit */
  {
    hearth_mesh m;
    CHECK_OK(hearth_mesh_alloc(&m, 5, 2, 1, &e), &e);
    const float P[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 7, 7, 7};
    const uint32_t I[6] = {0, 1, 2, 0, 1, 3}; /* second triangle is collinear */
    memcpy(m.positions, P, sizeof P);
    memcpy(m.indices, I, sizeof I);
    for (int k = 0; k < 10; k++) m.uvs[k] = 0.1f * (float)k;
    snprintf(path, sizeof path, "%s/degenerate.glb", dir);
    CHECK_OK(hearth_glb_write(path, &m, &e), &e);
    int rc = run_validator(src, path);
    CHECK_MSG(rc == 0, "%s: validator exit status %d", path, rc);
    hearth_mesh_free(&m);
  }

  /* the reader's fixtures, validated in one run of node */
  {
    tb_cube_init();
    char list[8192] = "";
    size_t used = 0;
    const double lo[3] = {-0.05, 0.01, -0.2}, hi[3] = {0.07, 0.09, 0.3};
    for (size_t q = 0; q <= TB_N_QTYPES; q++) {
      tb_qcube qc;
      tb_glb g;
      double uv[CUBE_NV * 2];
      if (q < TB_N_QTYPES) {
        tb_quantized_cube(&tb_qtypes[q], lo, hi, &qc);
        g = qc.g;
        snprintf(path, sizeof path, "%s/quantized_%zu.glb", dir, q);
      } else {
        /* UVs in tiles (1, 0) .. (-2, -2), a rotating texture transform,
           MIRRORED_REPEAT along u */
        memset(&g, 0, sizeof g);
        for (int v = 0; v < CUBE_NV; v++) {
          uv[2 * v] = g_uv[2 * v] + (v / 4) - 2;
          uv[2 * v + 1] = g_uv[2 * v + 1] + (v / 8);
        }
        g.nv = CUBE_NV, g.nt = CUBE_NT, g.pos = g_pos, g.uv[0] = uv, g.idx = g_idx;
        g.texture = 1, g.tex_coord = 0, g.wrap_s = 33648, g.wrap_t = 10497;
        g.transform = "{\"offset\":[0.25,1],\"rotation\":0.5,\"scale\":[2,0.5]}";
        g.transform_required = 1;
        snprintf(path, sizeof path, "%s/texture_transform.glb", dir);
      }
      size_t n = 0;
      uint8_t *f = tb_encode(&g, &n);
      CHECK(f != NULL);
      if (f) CHECK_OK(hearth_write_file_atomic(path, f, n, &e), &e);
      free(f);
      used += (size_t)snprintf(list + used, sizeof list - used, " '%s'", path);
    }
    const char *corpus[] = {"valid_quantized.glb", "valid_texture_transform.glb"};
    for (size_t i = 0; i < 2; i++)
      used += (size_t)snprintf(list + used, sizeof list - used, " '%s/fuzz/corpus/glb/%s'", src,
                               corpus[i]);
    char cmd[9000];
    snprintf(cmd, sizeof cmd, "node '%s/tests/mesh/validate_glb.js'%s", src, list);
    int rc = system(cmd);
    CHECK_MSG(rc != -1 && WIFEXITED(rc) && WEXITSTATUS(rc) == 0,
              "the reader's fixtures: validator exit status %d", rc);
  }

  /* negative control: retarget the index view as a vertex buffer */
  {
    hearth_mesh m;
    make_sphere(&m, 1, 16);
    uint8_t *data = NULL;
    size_t n = 0;
    CHECK_OK(hearth_glb_encode(&m, &data, &n, &e), &e);
    const char *needle = "\"target\":34963";
    int patched = 0;
    for (size_t i = 0; data && i + strlen(needle) <= n; i++)
      if (memcmp(data + i, needle, strlen(needle)) == 0) {
        memcpy(data + i, "\"target\":34962", strlen(needle));
        patched = 1;
        break;
      }
    CHECK(patched);
    snprintf(path, sizeof path, "%s/broken.glb", dir);
    CHECK_OK(hearth_write_file_atomic(path, data, n, &e), &e);
    int rc = run_validator(src, path);
    CHECK_MSG(rc == 1, "%s: validator should report errors, exit status %d", path, rc);
    free(data);
    hearth_mesh_free(&m);
  }
  TEST_MAIN_END();
}
