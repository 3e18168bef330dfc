/* `hearth synth` from the command line: help text, a tiny release, and bad
 * options refused with a usage status naming the option. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include "hearth/dataset.h"
#include "hearth/thermal.h"
#include "hearth/mesh.h"
#include "synth/synth_object.h"
#include "test_util.h"

int main(void) {
  static char out[1 << 16];
  char cmd[4096], p[4096];
  const char *base = test_tmpdir("synth_cli");

  snprintf(cmd, sizeof cmd, "'%s' synth --help", HEARTH_EXE);
  CHECK(test_run_capture(cmd, out, sizeof out) == 0);
  CHECK(strstr(out, "usage: hearth synth") != NULL);
  CHECK(strstr(out, "--contact-sheet") != NULL && strstr(out, "--views") != NULL);

  /* a tiny release with a contact sheet */
  snprintf(cmd, sizeof cmd,
           "'%s' synth --out '%s/rel' --seed 3 --views 2 --triangles 1500 --texture 128 "
           "--map-res 64 --thermal-frames 1 --stereo-pairs 1 --contact-sheet --threads 2 --quiet",
           HEARTH_EXE, base);
  int rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "exit %d: %s", rc, out);
  hearth_err err = {0};
  hearth_release_doc rel;
  memset(&rel, 0, sizeof rel);
  snprintf(p, sizeof p, "%s/rel/release.json", base);
  CHECK_OK(hearth_release_read(p, &rel, &err), &err);
  CHECK(rel.n_instances == 1);
  hearth_release_free(&rel);
  hearth_manifest man = {0};
  snprintf(p, sizeof p, "%s/rel/instances/cup_01/raw/hot/manifest.json", base);
  CHECK_OK(hearth_manifest_read(p, &man, &err), &err);
  CHECK(man.n_views == 2);
  hearth_manifest_free(&man);
  hearth_image img = {0};
  snprintf(p, sizeof p, "%s/rel/instances/cup_01/raw/hot/contact_sheet.png", base);
  CHECK_OK(hearth_png_read(p, &img, &err), &err);
  CHECK(img.width > 512 && img.height > 192 && img.channels == 3);
  hearth_image_free(&img);
  snprintf(p, sizeof p, "%s/rel/calibration/captures/stereo/p000_thermal.csv", base);
  CHECK_OK(hearth_thermal_read_csv(p, NULL, &img, &err), &err);
  hearth_image_free(&img);

  /* the same root again: refused, exit status 1, the message names it */
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK(rc == 1);
  CHECK(strstr(out, "/rel") != NULL);

  /* bad options: usage status 2 and the option named */
  const char *bad[][2] = {
      {"--views 31", "--views"},
      {"--views x", "--views"},
      {"--netd -1", "--netd"},
      {"--bogus", "--bogus"},
      {"--categories teapotx", "--categories"},
      {"--states boiling", "--states"},
      {"--seed", "--seed"},
      {"--triangles 5", "--triangles"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    snprintf(cmd, sizeof cmd, "'%s' synth --out '%s/bad%zu' %s", HEARTH_EXE, base, i, bad[i][0]);
    rc = test_run_capture(cmd, out, sizeof out);
    CHECK_MSG(rc == 2, "'%s': exit %d", bad[i][0], rc);
    CHECK_MSG(strstr(out, bad[i][1]) != NULL, "'%s': message does not name the option: %s",
              bad[i][0], out);
    snprintf(p, sizeof p, "%s/bad%zu", base, i);
    struct stat sb;
    CHECK(stat(p, &sb) != 0);
  }
  /* --mesh: a given UV-mapped GLB on the turntable, rescaled to --mesh-size */
  synth_object obj;
  memset(&obj, 0, sizeof obj);
  CHECK_OK(synth_object_make("canned_drink", 5, 1200, 64, &obj, &err), &err);
  obj.mesh.texture = obj.albedo;
  snprintf(p, sizeof p, "%s/given.glb", base);
  CHECK_OK(hearth_glb_write(p, &obj.mesh, &err), &err);
  memset(&obj.mesh.texture, 0, sizeof obj.mesh.texture);
  synth_object_free(&obj);
  snprintf(cmd, sizeof cmd,
           "'%s' synth --out '%s/meshrel' --mesh '%s' --mesh-size 0.1 --mesh-category "
           "canned_drink --views 1 --texture 64 --map-res 32 --no-calibration --quiet",
           HEARTH_EXE, base, p);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "exit %d: %s", rc, out);
  hearth_mesh gm = {0};
  hearth_glb_read_opts ro = {1, 0, 0};
  snprintf(p, sizeof p, "%s/meshrel/ground_truth/instances/canned_drink_01/mesh.glb", base);
  CHECK_OK(hearth_glb_read(p, &ro, &gm, &err), &err);
  if (gm.n_vertices) {
    double lo[3], hi[3];
    hearth_mesh_bounds(&gm, lo, hi);
    double ext = 0;
    for (int k = 0; k < 3; k++) ext = fmax(ext, hi[k] - lo[k]);
    /* the largest extent is 0.1 m along some axis; a rotated box's side is
     * between that and its diagonal */
    CHECK_MSG(ext > 0.06 && ext < 0.18, "extent %g", ext);
  }
  hearth_mesh_free(&gm);
  snprintf(cmd, sizeof cmd, "'%s' synth --out '%s/meshbad' --mesh '%s/nope.glb' --quiet",
           HEARTH_EXE, base, base);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK(rc == 1 && strstr(out, "nope.glb") != NULL);
  snprintf(p, sizeof p, "%s/meshbad", base);
  CHECK(!hearth_path_exists(p));

  /* --out is required */
  snprintf(cmd, sizeof cmd, "'%s' synth --views 2", HEARTH_EXE);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK(rc == 2 && strstr(out, "--out") != NULL);
  TEST_MAIN_END();
}
