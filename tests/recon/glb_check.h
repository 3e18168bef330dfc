/* glb_check.h - checks shared by the recon GLB tests: the Khronos glTF
 * validator (tests/mesh/validate_glb.js, the npm package gltf-validator in
 * $HEARTH_SOURCE_DIR/.tools) on one file, and the UVs of a mesh read back.
 * A missing node or package is a failure, not a skip. */
#ifndef HEARTH_TESTS_RECON_GLB_CHECK_H
#define HEARTH_TESTS_RECON_GLB_CHECK_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/core.h"
#include "hearth/mesh.h"
#include "test_util.h"

/* 0 when node and the validator package are there (else says why) */
static int glb_check_tools(const char *src) {
  char path[2048];
  if (system("node --version >/dev/null 2>&1") != 0) {
    fprintf(stderr, "FAIL: node is not installed; run scripts/setup.sh\n");
    return 1;
  }
  snprintf(path, sizeof path, "%s/.tools/node_modules/gltf-validator/package.json", src);
  if (!hearth_path_exists(path)) {
    fprintf(stderr, "FAIL: %s is missing; run scripts/setup.sh\n", path);
    return 1;
  }
  return 0;
}

/* the validator on path: a failed check unless it exits 0 with a summary
 * line of 0 errors and 0 warnings */
static void glb_check_validator(const char *src, const char *path) {
  char cmd[8192], out[16384];
  snprintf(cmd, sizeof cmd, "node '%s/tests/mesh/validate_glb.js' '%s'", src, path);
  int rc = test_run_capture(cmd, out, sizeof out);
  printf("%s", out);
  const char *sum = strstr(out, "validator ");
  int n_err = -1, n_warn = -1;
  if (sum) {
    const char *c = strchr(sum, ':');
    if (c) sscanf(c + 1, " %d errors, %d warnings", &n_err, &n_warn);
  }
  CHECK_MSG(rc == 0 && n_err == 0 && n_warn == 0, "%s: exit %d, %d errors, %d warnings", path, rc,
            n_err, n_warn);
}

/* the UV area of m (the packing efficiency, from its triangles); counts
 * UV coordinates outside [0,1] into *outside */
static double glb_check_uv_area(const hearth_mesh *m, size_t *outside) {
  *outside = 0;
  for (size_t i = 0; i < 2 * m->n_vertices; i++) *outside += !(m->uvs[i] >= 0 && m->uvs[i] <= 1);
  double auv = 0;
  for (size_t t = 0; t < m->n_triangles; t++) {
    const float *a = m->uvs + 2 * (size_t)m->indices[3 * t],
                *b = m->uvs + 2 * (size_t)m->indices[3 * t + 1],
                *c = m->uvs + 2 * (size_t)m->indices[3 * t + 2];
    auv += 0.5 * fabs(((double)b[0] - a[0]) * ((double)c[1] - a[1]) -
                      ((double)c[0] - a[0]) * ((double)b[1] - a[1]));
  }
  return auv;
}

/* the number after "key": in text, NAN when absent */
static double glb_check_json_number(const char *text, const char *key) {
  const char *p = text ? strstr(text, key) : NULL;
  if (!p) return NAN;
  p = strchr(p + strlen(key), ':');
  return p ? strtod(p + 1, NULL) : NAN;
}

#endif
