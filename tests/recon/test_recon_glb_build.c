/* `hearth build` on a small virtual-rig release without recon/ (a cup, 10
 * views, calibration/rig.json from the truth) reconstructs in its recon
 * stage and bakes the colour texture into recon/rgb_texture.png and
 * recon/mesh.glb: the textured hand-over an outside tool gives. The
 * Khronos glTF validator (tests/recon/glb_check.h) must report 0 errors
 * and 0 warnings on that file and on the build's derived/mesh.glb. Read
 * back, recon/mesh.glb embeds the very pixels of recon/rgb_texture.png
 * (the build's --rgb-resolution) and has UVs in [0,1]^2 whose area is the
 * report's packing efficiency. */
#include "glb_check.h"
#include "hearth/image.h"

int main(void) {
  const char *src = getenv("HEARTH_SOURCE_DIR");
  if (!src || !*src) src = ".";
  if (glb_check_tools(src)) return 1;
  char path[2048], cmd[4096], out[16384];
  const char *dir = test_tmpdir("recon_glb_build");
  char root[1200];
  snprintf(root, sizeof root, "%s/rel", dir);
  snprintf(cmd, sizeof cmd,
           "'%s' synth --out '%s' --categories cup --states neutral --views 10 --no-calibration "
           "--draft-rgb --texture 256 --map-res 64 --recon none --quiet && "
           "cp '%s/ground_truth/rig.json' '%s/calibration/rig.json'",
           HEARTH_EXE, root, root, root);
  CHECK(system(cmd) == 0);
  snprintf(cmd, sizeof cmd,
           "'%s' build '%s' --resolution 64 --rgb-resolution 256 --no-overlays --threads 2",
           HEARTH_EXE, root);
  int rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0 && strstr(out, "cup_01 recon: done"), "build: exit %d: %s", rc, out);

  snprintf(path, sizeof path, "%s/instances/cup_01/recon/mesh.glb", root);
  CHECK_MSG(hearth_path_exists(path), "%s missing", path);
  glb_check_validator(src, path);
  char derived[2048];
  snprintf(derived, sizeof derived, "%s/instances/cup_01/derived/mesh.glb", root);
  glb_check_validator(src, derived);

  /* read back with its texture: the baked PNG's pixels, UVs in the square
     with the report's packing */
  hearth_err e = {0};
  hearth_glb_read_opts ro;
  hearth_glb_read_opts_default(&ro);
  ro.require_uvs = 1;
  ro.load_texture = 1;
  hearth_mesh m;
  CHECK_OK(hearth_glb_read(path, &ro, &m, &e), &e);
  hearth_image png = {0};
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/rgb_texture.png", root);
  CHECK_OK(hearth_png_read(path, &png, &e), &e);
  if (m.uvs && png.data) {
    const hearth_image *t = &m.texture;
    CHECK_MSG(t->data != NULL, "recon/mesh.glb has no embedded texture");
    CHECK_MSG(png.width == 256 && png.height == 256, "rgb_texture.png %zu x %zu", png.width,
              png.height);
    if (t->data)
      CHECK_MSG(t->width == png.width && t->height == png.height && t->channels == png.channels &&
                    t->type == png.type &&
                    memcmp(t->data, png.data,
                           png.width * png.height * (size_t)png.channels * (size_t)png.type) == 0,
                "the embedded texture (%zu x %zu x %d) is not recon/rgb_texture.png", t->width,
                t->height, t->channels);
    size_t outside;
    double auv = glb_check_uv_area(&m, &outside);
    snprintf(path, sizeof path, "%s/instances/cup_01/recon/report.json", root);
    char *rep = test_slurp(path, NULL);
    double eff = glb_check_json_number(rep, "\"packing_efficiency\"");
    printf("recon/mesh.glb: %zu triangles, %zu x %zu texture, UV area %.4f, report's packing %.4f\n",
           m.n_triangles, t->width, t->height, auv, eff);
    CHECK_MSG(outside == 0, "%zu UV coordinates outside [0,1]", outside);
    CHECK_NEAR(auv, eff, 1e-3);
    CHECK_MSG(auv >= 0.5, "packing %g", auv);
    free(rep);
  }
  hearth_image_free(&png);
  hearth_mesh_free(&m);
  TEST_MAIN_END();
}
