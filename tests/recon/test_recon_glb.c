/* `hearth recon` on a small virtual-rig instance (a cup, 10 views, no
 * stand-in) writes recon/mesh.glb, the hand-over an outside tool gives:
 * the Khronos glTF validator (tests/mesh/validate_glb.js, the npm package
 * gltf-validator in $HEARTH_SOURCE_DIR/.tools) must report 0 errors and 0
 * warnings on it. The file read back has UVs in [0,1]^2 whose area (the
 * packing efficiency, measured here from the triangles) is the report's
 * figure and at least 0.5. Missing node or package is a failure, not a
 * skip. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/core.h"
#include "hearth/mesh.h"
#include "test_util.h"

/* the number after "key": in text, NAN when absent */
static double json_number_after(const char *text, const char *key) {
  const char *p = text ? strstr(text, key) : NULL;
  if (!p) return NAN;
  p = strchr(p + strlen(key), ':');
  return p ? strtod(p + 1, NULL) : NAN;
}

int main(void) {
  const char *src = getenv("HEARTH_SOURCE_DIR");
  if (!src || !*src) src = ".";
  if (system("node --version >/dev/null 2>&1") != 0) {
    fprintf(stderr, "FAIL: node is not installed; run scripts/setup.sh\n");
    return 1;
  }
  char path[2048], cmd[8192], out[16384];
  snprintf(path, sizeof path, "%s/.tools/node_modules/gltf-validator/package.json", src);
  if (!hearth_path_exists(path)) {
    fprintf(stderr, "FAIL: %s is missing; run scripts/setup.sh\n", path);
    return 1;
  }
  const char *dir = test_tmpdir("recon_glb");
  char root[1200];
  snprintf(root, sizeof root, "%s/rel", dir);
  CHECK(test_sh("'%s' synth --out '%s' --categories cup --states neutral --views 10 "
                "--no-calibration --draft-rgb --texture 256 --map-res 64 --recon none --quiet",
                HEARTH_EXE, root) == 0);
  CHECK(test_sh("'%s' recon '%s' --quiet --triangles 6000", HEARTH_EXE, root) == 0);
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/mesh.glb", root);
  CHECK_MSG(hearth_path_exists(path), "%s missing", path);

  /* the validator: its summary line counts errors and warnings */
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

  /* read back: UVs inside the square, their area the report's packing */
  hearth_err e = {0};
  hearth_glb_read_opts ro;
  hearth_glb_read_opts_default(&ro);
  ro.require_uvs = 1;
  hearth_mesh m;
  CHECK_OK(hearth_glb_read(path, &ro, &m, &e), &e);
  if (m.uvs) {
    size_t outside = 0;
    for (size_t i = 0; i < 2 * m.n_vertices; i++) outside += !(m.uvs[i] >= 0 && m.uvs[i] <= 1);
    double auv = 0;
    for (size_t t = 0; t < m.n_triangles; t++) {
      const float *a = m.uvs + 2 * (size_t)m.indices[3 * t],
                  *b = m.uvs + 2 * (size_t)m.indices[3 * t + 1],
                  *c = m.uvs + 2 * (size_t)m.indices[3 * t + 2];
      auv += 0.5 * fabs(((double)b[0] - a[0]) * ((double)c[1] - a[1]) -
                        ((double)c[0] - a[0]) * ((double)b[1] - a[1]));
    }
    snprintf(path, sizeof path, "%s/instances/cup_01/recon/report.json", root);
    char *rep = test_slurp(path, NULL);
    double eff = json_number_after(rep, "\"packing_efficiency\"");
    printf("recon/mesh.glb: %zu triangles, UV area %.4f, report's packing %.4f\n", m.n_triangles,
           auv, eff);
    CHECK_MSG(outside == 0, "%zu UV coordinates outside [0,1]", outside);
    CHECK_NEAR(auv, eff, 1e-3);
    CHECK_MSG(auv >= 0.5, "packing %g", auv);
    free(rep);
    hearth_mesh_free(&m);
  }
  TEST_MAIN_END();
}
