/* `hearth recon` on a small virtual-rig instance (a cup, 10 views, no
 * stand-in) writes recon/mesh.glb, the hand-over an outside tool gives:
 * the Khronos glTF validator (tests/recon/glb_check.h) must report 0
 * errors and 0 warnings on it. The file read back has UVs in [0,1]^2 whose
 * area (the packing efficiency, measured here from the triangles) is the
 * report's figure and at least 0.5. The textured form the build writes is
 * recon/test_recon_glb_build's. */
#include "glb_check.h"

int main(void) {
  const char *src = getenv("HEARTH_SOURCE_DIR");
  if (!src || !*src) src = ".";
  if (glb_check_tools(src)) return 1;
  char path[2048];
  const char *dir = test_tmpdir("recon_glb");
  char root[1200];
  snprintf(root, sizeof root, "%s/rel", dir);
  CHECK(test_sh("'%s' synth --out '%s' --categories cup --states neutral --views 10 "
                "--no-calibration --draft-rgb --texture 256 --map-res 64 --recon none --quiet",
                HEARTH_EXE, root) == 0);
  CHECK(test_sh("'%s' recon '%s' --quiet --triangles 6000", HEARTH_EXE, root) == 0);
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/mesh.glb", root);
  CHECK_MSG(hearth_path_exists(path), "%s missing", path);
  glb_check_validator(src, path);

  /* read back: UVs inside the square, their area the report's packing */
  hearth_err e = {0};
  hearth_glb_read_opts ro;
  hearth_glb_read_opts_default(&ro);
  ro.require_uvs = 1;
  hearth_mesh m;
  CHECK_OK(hearth_glb_read(path, &ro, &m, &e), &e);
  if (m.uvs) {
    size_t outside;
    double auv = glb_check_uv_area(&m, &outside);
    snprintf(path, sizeof path, "%s/instances/cup_01/recon/report.json", root);
    char *rep = test_slurp(path, NULL);
    double eff = glb_check_json_number(rep, "\"packing_efficiency\"");
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
