/* hearth build's schedule on a 2-instance release with calibration
 * captures: stages that do not read the calibration (scale) run beside
 * detection and calibration, map and overlay of different states side by
 * side. The bytes must not depend on it: -j 2 gives the tree of -j 1. And
 * when the calibration fails, the build fails naming the capture, every
 * instance's scale is still done (it does not need the calibration) and no
 * stage that reads the calibration has run. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "test_util.h"

static int exists(const char *base, const char *rel) {
  char path[2400];
  struct stat st;
  snprintf(path, sizeof path, "%s/%s", base, rel);
  return stat(path, &st) == 0;
}

int main(void) {
  static char out[1 << 17];
  char cmd[8192], a[1200], b[1200];
  const char *base = test_tmpdir("build_schedule");
  char pristine[1100];
  snprintf(pristine, sizeof pristine, "%s/pristine", base);
  snprintf(cmd, sizeof cmd,
           "'%s' synth --out '%s' --draft-rgb --seed 5 --categories cup,canned_drink --views 2 "
           "--triangles 600 --texture 64 --map-res 32 --thermal-frames 4 --stereo-pairs 2 "
           "--threads 2 --quiet",
           HEARTH_EXE, pristine);
  int rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "synth: %s", out);

  /* -j 2 (two jobs, one thread each, scale beside the calibration) against
     -j 1 (one job, everything in order) */
  const char *jobs[2] = {"-j 2 --threads 2", "-j 1 --threads 1"};
  for (int i = 0; i < 2; i++) {
    snprintf(cmd, sizeof cmd, "cp -a '%s' '%s/j%d' && '%s' build '%s/j%d' --resolution 32 %s",
             pristine, base, i, HEARTH_EXE, base, i, jobs[i]);
    rc = test_run_capture(cmd, out, sizeof out);
    CHECK_MSG(rc == 0 && strstr(out, "2 instance(s): 2 complete, 0 failed; 4/4 state(s) mapped"),
              "build %s: %s", jobs[i], out);
    CHECK_MSG(strstr(out, "build: calibrate: done") && strstr(out, "cup_01 scale: done") &&
                  strstr(out, "canned_drink_01 overlay iced: done"),
              "build %s: %s", jobs[i], out);
  }
  snprintf(a, sizeof a, "%s/hash_j2.txt", base);
  snprintf(b, sizeof b, "%s/hash_j1.txt", base);
  snprintf(cmd, sizeof cmd, "%s/j0", base);
  CHECK(test_tree_hash(cmd, a) == 0);
  snprintf(cmd, sizeof cmd, "%s/j1", base);
  CHECK(test_tree_hash(cmd, b) == 0);
  snprintf(cmd, sizeof cmd, "cmp '%s' '%s'", a, b);
  CHECK_MSG(system(cmd) == 0, "the -j 2 build's bytes differ from the -j 1 build's");

  /* a calibration capture cut short: the release-level stage fails */
  char bad[1200];
  snprintf(bad, sizeof bad, "%s/bad", base);
  snprintf(cmd, sizeof cmd,
           "cp -a '%s' '%s' && f=$(ls '%s'/calibration/captures/thermal/*.csv | head -n 1) && "
           "head -c 300 \"$f\" > '%s/cut.csv' && mv '%s/cut.csv' \"$f\" && basename \"$f\"",
           pristine, bad, bad, base, base);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "spoiling a capture: %s", out);
  char spoiled[256];
  snprintf(spoiled, sizeof spoiled, "%.*s", (int)strcspn(out, "\n"), out);
  snprintf(cmd, sizeof cmd, "'%s' build '%s' --resolution 32 -j 2 --threads 2", HEARTH_EXE, bad);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc != 0 && strstr(out, spoiled) && strstr(out, "detect"), "failed calibration: %s",
            out);
  const char *inst[2] = {"cup_01", "canned_drink_01"};
  for (int i = 0; i < 2; i++) {
    char rel[256];
    snprintf(rel, sizeof rel, "instances/%s/derived/.stamps/scale.json", inst[i]);
    CHECK_MSG(exists(bad, rel), "%s: scale did not run beside the failed calibration", inst[i]);
    static const char *later[] = {"bake.json", "transfer.json", "refine.json", "map-neutral.json",
                                  "overlay-neutral.json"};
    for (size_t k = 0; k < sizeof later / sizeof *later; k++) {
      snprintf(rel, sizeof rel, "instances/%s/derived/.stamps/%s", inst[i], later[k]);
      CHECK_MSG(!exists(bad, rel), "%s ran without a calibration", rel);
    }
    snprintf(rel, sizeof rel, "instances/%s/derived/poses_thermal.json", inst[i]);
    CHECK_MSG(!exists(bad, rel), "%s written without a calibration", rel);
  }
  CHECK(!exists(bad, "calibration/rig.json"));
  TEST_MAIN_END();
}
