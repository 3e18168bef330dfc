/* hearth build on a 10-instance virtual release: a second run does no work;
 * a run killed midway and re-run ends with the same bytes as an
 * uninterrupted build; shards in another directory give the same bytes;
 * the result validates; stats counts it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "test_util.h"

int main(void) {
  static char out[1 << 18];
  char cmd[8192], a[2048], b[2048];
  const char *base = test_tmpdir("build_cli");
  char root[1100], pristine[1100];
  snprintf(root, sizeof root, "%s/rel", base);
  snprintf(pristine, sizeof pristine, "%s/pristine", base);

  snprintf(cmd, sizeof cmd, "'%s' build --help", HEARTH_EXE);
  CHECK(test_run_capture(cmd, out, sizeof out) == 0 && strstr(out, "--shard") && strstr(out, "-j"));
  snprintf(cmd, sizeof cmd, "'%s' build '%s' --shard 3/2", HEARTH_EXE, root);
  CHECK(test_run_capture(cmd, out, sizeof out) == 2 && strstr(out, "--shard"));

  /* 10 instances, 2 views per state, tiny meshes and maps; the true rig
     stands in for calibration (no captures: no release-level stages) */
  snprintf(
      cmd, sizeof cmd,
      "'%s' synth --out '%s' --draft-rgb --seed 11 --categories cup,canned_drink --instances 5 --views 2 "
      "--triangles 600 --texture 64 --map-res 32 --no-calibration --threads 2 --quiet && "
      "cp '%s/ground_truth/rig.json' '%s/calibration/rig.json' && cp -a '%s' '%s'",
      HEARTH_EXE, root, root, root, root, pristine);
  int rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "synth: %s", out);
  const char *opts = "--resolution 32 --no-bake -j 2 --threads 2";

  /* full build */
  snprintf(cmd, sizeof cmd, "'%s' build '%s' %s", HEARTH_EXE, root, opts);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "build: %s", out);
  CHECK_MSG(strstr(out, "10 instance(s): 10 complete, 0 failed; 20/20 state(s) mapped"), "%s", out);
  /* plain lines when not on a terminal */
  CHECK(strstr(out, "build [1/") != NULL);

  /* second run: no work */
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK(rc == 0);
  CHECK_MSG(strstr(out, " 0 stage(s) run") != NULL, "second run did work: %s", out);
  snprintf(a, sizeof a, "%s/hash_full.txt", base);
  CHECK(test_tree_hash(root, a) == 0);

  /* validate and stats of the result */
  snprintf(cmd, sizeof cmd, "'%s' validate '%s'", HEARTH_EXE, root);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "validate: %s", out);
  snprintf(cmd, sizeof cmd, "'%s' stats '%s' --format json", HEARTH_EXE, root);
  CHECK(test_run_capture(cmd, out, sizeof out) == 0);
  CHECK(strstr(out, "\"instances\": 10") && strstr(out, "\"object_states\": 20") &&
        strstr(out, "\"temperature_maps\": 20") && strstr(out, "\"rgb_thermal_pairs\": 40"));

  /* an output removed: exactly its stage re-runs. Temporaries killed
     writers left (dead process ids) go on every run, wherever they are in
     the instance; a running writer's stays, as does a look-alike that is not
     one. */
  const char *d3 = "instances/cup_03/derived";
  pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, NULL, 0);
  long dead = (long)child, live = (long)getpid();
  snprintf(
      cmd, sizeof cmd,
      "cd '%s' && rm %s/hot/mask.npy && mkdir %s/hot.tmp-%ld-Qw3Er5 %s/hot.tmp-%ld-Old000 && "
      "touch %s/hot/mask.npy.tmp-%ld-Ab12Cd %s/hot.tmp-%ld-Qw3Er5/mask.npy %s/hot.tmp-%ld-Old000/mask.npy "
      "%s/.stamps/map-hot.json.tmp-%ld-q9Z0xY %s/notes.tmp-1234567 "
      "%s/overlay/neutral/v00.png.tmp-%ld-Zz9y8X %s/overlay/neutral/v01.png.tmp-%ld-Zz9y8X && "
      "'%s' build '%s' %s",
      root, d3, d3, dead, d3, dead, d3, dead, d3, dead, d3, dead, d3, dead, d3, d3, dead, d3, live,
      HEARTH_EXE, root, opts);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0 && strstr(out, " 1 stage(s) run") && strstr(out, "cup_03 map hot: done"), "%s",
            out);
  CHECK_MSG(strstr(out, "removed 5 temporary file(s)/folder(s)"), "%s", out);
  snprintf(
      cmd, sizeof cmd,
      "cd '%s' && test ! -e %s/hot/mask.npy.tmp-%ld-Ab12Cd && test ! -e %s/.stamps/map-hot.json.tmp-%ld-q9Z0xY "
      "&& test ! -e %s/hot.tmp-%ld-Qw3Er5 && test ! -e %s/hot.tmp-%ld-Old000 "
      "&& test ! -e %s/overlay/neutral/v00.png.tmp-%ld-Zz9y8X "
      "&& test -e %s/notes.tmp-1234567 && test -e %s/overlay/neutral/v01.png.tmp-%ld-Zz9y8X",
      root, d3, dead, d3, dead, d3, dead, d3, dead, d3, dead, d3, d3, live);
  CHECK_MSG(system(cmd) == 0, "stale temporaries: wrong files removed");
  /* validate names the one left (its writer still runs) */
  snprintf(cmd, sizeof cmd, "'%s' validate '%s'", HEARTH_EXE, root);
  rc = test_run_capture(cmd, out, sizeof out);
  char want[256];
  snprintf(want, sizeof want,
           "overlay/neutral/v01.png.tmp-%ld-Zz9y8X: a temporary of process %ld, "
           "which is still writing",
           live, live);
  CHECK_MSG(rc != 0 && strstr(out, want) && !strstr(out, "notes.tmp-1234567"), "validate: %s", out);
  snprintf(cmd, sizeof cmd, "rm '%s/%s/overlay/neutral/v01.png.tmp-%ld-Zz9y8X'", root, d3, live);
  CHECK(system(cmd) == 0);

  /* interrupted: start from the pristine tree, kill -9 after a few stages */
  snprintf(cmd, sizeof cmd,
           "rm -rf '%s' && cp -a '%s' '%s' && ('%s' build '%s' %s > '%s/log' 2>&1 & pid=$!; "
           "for i in $(seq 1 6000); do grep -q 'build \\[12/' '%s/log' && break; sleep 0.05; done; "
           "kill -9 $pid; wait $pid; true)",
           root, pristine, root, HEARTH_EXE, root, opts, base, base);
  CHECK(test_run_capture(cmd, out, sizeof out) == 0);
  snprintf(cmd, sizeof cmd, "'%s' build '%s' %s", HEARTH_EXE, root, opts);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "resume: %s", out);
  CHECK_MSG(strstr(out, "10 complete") && !strstr(out, " 0 up to date"),
            "resume did not reuse finished stages: %s", out);
  snprintf(b, sizeof b, "%s/hash_resumed.txt", base);
  CHECK(test_tree_hash(root, b) == 0);
  snprintf(cmd, sizeof cmd, "cmp '%s' '%s'", a, b);
  CHECK_MSG(system(cmd) == 0, "resumed build differs from the uninterrupted one");

  /* sharding: two shards together do everything, each half; built in
     another directory, so also: no output depends on where the release is */
  char moved[1200];
  snprintf(moved, sizeof moved, "%s/elsewhere/release", base);
  snprintf(
      cmd, sizeof cmd,
      "rm -rf '%s' '%s/elsewhere' && mkdir -p '%s/elsewhere' && cp -a '%s' '%s' && '%s' build '%s' %s --shard 0/2 && "
      "'%s' build '%s' %s --shard 1/2",
      root, base, base, pristine, moved, HEARTH_EXE, moved, opts, HEARTH_EXE, moved, opts);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0 && strstr(out, "5 instance(s): 5 complete"), "shards: %s", out);
  snprintf(b, sizeof b, "%s/hash_shards.txt", base);
  CHECK(test_tree_hash(moved, b) == 0);
  snprintf(cmd, sizeof cmd, "cmp '%s' '%s'", a, b);
  CHECK_MSG(system(cmd) == 0, "sharded build (elsewhere) differs from the single build");
  TEST_MAIN_END();
}
