/* hearth recon --poses colmap without COLMAP: a stand-in `colmap` shell
 * script (written here) checks the arguments each step gets, prints the
 * progress lines COLMAP prints and writes a text model in which one view
 * is not registered. Checks the workspace (image links, masks from gray
 * and RGBA cut-outs), the arguments, the import into recon/poses_rgb.json,
 * failed steps (exit status, output tail, which step), a missing program,
 * hearth_exec itself, and the command line of `hearth recon`. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "hearth/image.h"
#include "hearth/recon.h"
#include "recon/colmap_fixture.h"
#include "recon/recon_release.h"
#include "test_util.h"

static char g_dir[1024], g_root[1200], g_fake[1200], g_log[1200];

static char *slurp(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *b = malloc((size_t)n + 1);
  size_t got = fread(b, 1, (size_t)n, f);
  fclose(f);
  b[got] = 0;
  return b;
}

static int run_cmd(const char *cmd, char *out, size_t outsz) {
  FILE *p = popen(cmd, "r");
  if (!p) return -1;
  size_t n = fread(out, 1, outsz - 1, p);
  out[n] = 0;
  int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* the stand-in: logs "<step> <args>" to $FAKE_COLMAP_LOG, checks that every
 * image has its mask, and makes a model of every image but hot/v01 */
static const char k_fake[] =
    "#!/bin/sh\n"
    "step=$1; shift\n"
    "echo \"$step $*\" >> \"$FAKE_COLMAP_LOG\"\n"
    "db=; img=; mask=; out=\n"
    "while [ $# -gt 1 ]; do\n"
    "  case $1 in --database_path) db=$2;; --image_path) img=$2;;\n"
    "    --ImageReader.mask_path) mask=$2;; --output_path) out=$2;; esac\n"
    "  shift 2\n"
    "done\n"
    "case $step in\n"
    "feature_extractor)\n"
    "  n=$(cd \"$img\" && find . -name '*.jpg' | wc -l); i=0\n"
    "  for f in $(cd \"$img\" && find . -name '*.jpg' | sort); do\n"
    "    i=$((i+1)); echo \"Processed file [$i/$n]\"\n"
    "    if [ -n \"$mask\" ] && [ ! -f \"$mask/${f#./}.png\" ]; then echo \"no mask for $f\" >&2; exit 1; fi\n"
    "  done\n"
    "  : > \"$db\";;\n"
    "exhaustive_matcher)\n"
    "  if [ -n \"$FAKE_FAIL_MATCH\" ]; then echo 'reading the database'; echo 'F0101 fake matcher failure' >&2; exit 3; fi\n"
    "  echo 'Matching block [1/1, 1/1] in 0.001s';;\n"
    "mapper)\n"
    "  if [ -n \"$FAKE_NO_PAIR\" ]; then echo '  => No good initial image pair found.'; echo 'ERROR: failed to create sparse model' >&2; exit 1; fi\n"
    "  mkdir -p \"$out/0\"\n"
    "  echo '# cameras' > \"$out/0/cameras.txt\"\n"
    "  echo '1 PINHOLE 64 48 70 71 32.5 24.5' >> \"$out/0/cameras.txt\"\n"
    "  echo '# images' > \"$out/0/images.txt\"\n"
    "  k=0\n"
    "  for f in $(cd \"$img\" && find . -name '*.jpg' | sort); do\n"
    "    name=${f#./}; k=$((k+1))\n"
    "    [ \"$name\" = hot/v01.jpg ] && continue\n"
    "    echo \"Registering image #$k ($k)\"\n"
    "    echo \"$((k*10)) 1 0 0 0 0.$k 0 1 1 $name\" >> \"$out/0/images.txt\"\n"
    "    echo '' >> \"$out/0/images.txt\"\n"
    "  done\n"
    "  echo '# none' > \"$out/0/points3D.txt\";;\n"
    "*) echo \"unknown step $step\" >&2; exit 2;;\n"
    "esac\n";

static void make_release(void) {
  hearth_err err = {0};
  char cmd[4096], path[2048];
  static const char *const states[] = {"neutral", "hot"};
  static const size_t n_views[] = {2, 2};
  rr_write_instance(g_root, "cup_01", "cup", 2, states, n_views);
  snprintf(cmd, sizeof cmd, "mkdir -p '%s/calibration'", g_root);
  CHECK(system(cmd) == 0);
  hearth_factory_calib fac;
  memset(&fac, 0, sizeof fac);
  fac.rgb = (hearth_camera){64, 48, 70, 71, 31.5, 23.25, {0.01, -0.002, 0.0003, 0.0004, 0.005}};
  fac.depth = (hearth_camera){32, 24, 30, 30, 16, 12, {0}};
  hearth_rigid_identity(&fac.T_depth_from_rgb);
  snprintf(path, sizeof path, "%s/calibration/factory.json", g_root);
  CHECK_OK(hearth_factory_write(path, &fac, &err), &err);
  for (int s = 0; s < 2; s++) {
    for (int i = 0; i < 2; i++) {
      hearth_image rgb, cut;
      CHECK_OK(hearth_image_alloc(&rgb, 64, 48, 3, HEARTH_PIX_U8, &err), &err);
      memset(rgb.data, 90 + 40 * i, hearth_image_bytes(&rgb));
      snprintf(path, sizeof path, "%s/instances/cup_01/raw/%s/rgb/v%02d.jpg", g_root, states[s], i);
      CHECK_OK(hearth_jpeg_write(path, &rgb, 90, &err), &err);
      /* neutral: 8-bit mask; hot: RGBA with the object in alpha */
      int ch = s ? 4 : 1;
      CHECK_OK(hearth_image_alloc(&cut, 64, 48, ch, HEARTH_PIX_U8, &err), &err);
      uint8_t *px = cut.data;
      for (size_t y = 0; y < 48; y++)
        for (size_t x = 0; x < 64; x++) {
          int on = x >= 10 && x < 40 && y >= 5 && y < 30;
          for (int c = 0; c < ch; c++)
            px[(y * 64 + x) * (size_t)ch + (size_t)c] =
                ch == 4 ? (c == 3 ? (on ? 200 : 0) : 77) : (on ? 1 : 0);
        }
      snprintf(path, sizeof path, "%s/instances/cup_01/raw/%s/cutout/v%02d.png", g_root, states[s],
               i);
      CHECK_OK(hearth_png_write(path, &cut, &err), &err);
      hearth_image_free(&rgb);
      hearth_image_free(&cut);
    }
  }
}

static void on_line(void *ctx, const char *line) {
  int *n = ctx;
  if (line[0]) (*n)++;
}

static void test_exec(void) {
  hearth_err err = {0};
  CHECK(hearth_program_found("sh") && hearth_program_found("/bin/sh"));
  CHECK(!hearth_program_found("hearth-no-such-program") && !hearth_program_found("/nonexistent/x"));
  char log[1200];
  snprintf(log, sizeof log, "%s/exec.log", g_dir);
  const char *ok[] = {"sh", "-c", "echo one; echo two >&2; printf 'three\\rfour'", NULL};
  int lines = 0;
  CHECK_OK(hearth_exec("sh ok", ok, log, on_line, &lines, &err), &err);
  CHECK(lines == 4);
  const char *bad[] = {"sh", "-c",
                       "echo first; i=0; while [ $i -lt 20 ]; do echo line$i; i=$((i+1)); done; "
                       "echo 'the reason' >&2; exit 3",
                       NULL};
  CHECK(hearth_exec("sh bad", bad, log, NULL, NULL, &err) == HEARTH_E_IO);
  CHECK_MSG(strstr(err.msg, "sh bad failed (exit status 3)") && strstr(err.msg, "the reason") &&
                strstr(err.msg, "line19") && !strstr(err.msg, "first") && strstr(err.msg, log),
            "%s", err.msg);
  char *text = slurp(log);
  CHECK(text && strstr(text, "one\ntwo\nthree\rfour") && strstr(text, "first\nline0"));
  free(text);
  const char *missing[] = {"hearth-no-such-program", NULL};
  CHECK(hearth_exec("step", missing, NULL, NULL, NULL, &err) == HEARTH_E_NOT_FOUND);
  CHECK(strstr(err.msg, "cannot run 'hearth-no-such-program'"));
  const char *killed[] = {"sh", "-c", "kill -9 $$", NULL};
  CHECK(hearth_exec("step", killed, NULL, NULL, NULL, &err) == HEARTH_E_IO);
  CHECK(strstr(err.msg, "killed by signal 9") && strstr(err.msg, "printed nothing"));
}

static void test_run(void) {
  hearth_err err = {0};
  char work[1200], path[2048];
  snprintf(work, sizeof work, "%s/work", g_dir);
  hearth_colmap_job job = {.root = g_root,
                           .instance = "cup_01",
                           .work = work,
                           .colmap = g_fake,
                           .threads = 1,
                           .quiet = 1};
  hearth_colmap_result res;
  remove(g_log);
  CHECK_OK(hearth_colmap_run(&job, &res, &err), &err);
  CHECK(res.n_views == 4 && res.n_registered == 3 && res.n_models == 1 && res.n_points == 0);
  CHECK(!strcmp(res.work, work));
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/poses_rgb.json", g_root);
  CHECK(!strcmp(res.out, path));
  hearth_poses p;
  CHECK_OK(hearth_poses_read(path, &p, &err), &err);
  CHECK(p.n == 3 && hearth_poses_find(&p, "hot", "v00") && !hearth_poses_find(&p, "hot", "v01") &&
        hearth_poses_find(&p, "neutral", "v01"));
  /* image hot/v00 is the first of the sorted names: t_cam_from_world (0.1, 0, 1),
   * identity rotation, so the camera centre is (-0.1, 0, -1) */
  const hearth_view_pose *h0 = hearth_poses_find(&p, "hot", "v00");
  if (h0)
    CHECK(h0->T_world_from_cam.t[0] == -0.1 && h0->T_world_from_cam.t[2] == -1 &&
          h0->T_world_from_cam.R[0] == 1);
  hearth_poses_free(&p);
  snprintf(path, sizeof path, "%s/instances/cup_01/recon/poses_rgb_cameras.json", g_root);
  hearth_recon_cameras cams;
  CHECK_OK(hearth_recon_cameras_read(path, &cams, &err), &err);
  CHECK(cams.n_cameras == 1 && cams.cameras[0].camera.cx == 32 && cams.n_views == 3);
  hearth_recon_cameras_free(&cams);

  /* the workspace: links to the colour images, masks 0/255 from both cut-out kinds */
  struct stat st;
  snprintf(path, sizeof path, "%s/images/neutral/v01.jpg", work);
  CHECK(lstat(path, &st) == 0 && S_ISLNK(st.st_mode));
  for (int s = 0; s < 2; s++) {
    hearth_image m;
    snprintf(path, sizeof path, "%s/masks/%s/v00.jpg.png", work, s ? "hot" : "neutral");
    CHECK_OK(hearth_png_read(path, &m, &err), &err);
    if (m.data) {
      const uint8_t *px = m.data;
      CHECK(m.channels == 1 && m.width == 64 && px[0] == 0 && px[10 * 64 + 20] == 255 &&
            px[35 * 64 + 20] == 0);
    }
    hearth_image_free(&m);
  }
  /* the arguments: CPU SIFT, one camera, the calibrated camera fixed (COLMAP pixels) */
  char *args = slurp(g_log);
  CHECK(args != NULL);
  if (args) {
    CHECK(strstr(args, "--SiftExtraction.use_gpu 0") && strstr(args, "--SiftMatching.use_gpu 0"));
    CHECK(strstr(args, "--ImageReader.single_camera 1"));
    CHECK(strstr(args,
                 "--ImageReader.camera_model FULL_OPENCV --ImageReader.camera_params "
                 "70.0,71.0,32.0,23.75,0.01,-0.002,0.0003,0.0004,0.005,0.0,0.0,0.0"));
    CHECK(strstr(args, "--ImageReader.mask_path"));
    CHECK(strstr(args, "--Mapper.ba_refine_focal_length 0"));
    CHECK(strstr(args, "--SiftExtraction.num_threads 1"));
  }
  free(args);
  snprintf(path, sizeof path, "%s/logs/mapper.log", work);
  CHECK(hearth_path_exists(path));

  /* an existing poses file needs --force */
  CHECK(hearth_colmap_run(&job, &res, &err) == HEARTH_E_ARG);
  CHECK(strstr(err.msg, "--force"));
  job.force = 1;
  /* estimated intrinsics, no masks */
  remove(g_log);
  job.intrinsics = HEARTH_COLMAP_INTR_ESTIMATE;
  job.no_masks = 1;
  CHECK_OK(hearth_colmap_run(&job, &res, &err), &err);
  args = slurp(g_log);
  CHECK(args && strstr(args, "--ImageReader.camera_model SIMPLE_RADIAL") &&
        !strstr(args, "camera_params") && !strstr(args, "mask_path") &&
        !strstr(args, "ba_refine_focal_length"));
  free(args);
  job.intrinsics = HEARTH_COLMAP_INTR_CALIBRATION;
  job.no_masks = 0;

  /* a failed step: which one, its exit status and its last lines */
  setenv("FAKE_FAIL_MATCH", "1", 1);
  CHECK(hearth_colmap_run(&job, &res, &err) == HEARTH_E_IO);
  CHECK_MSG(strstr(err.msg, "cup_01: colmap exhaustive_matcher failed (exit status 3)") &&
                strstr(err.msg, "F0101 fake matcher failure") &&
                strstr(err.msg, "exhaustive_matcher.log"),
            "%s", err.msg);
  unsetenv("FAKE_FAIL_MATCH");
  setenv("FAKE_NO_PAIR", "1", 1);
  CHECK(hearth_colmap_run(&job, &res, &err) == HEARTH_E_NUMERIC);
  CHECK_MSG(strstr(err.msg, "colmap mapper made no model"), "%s", err.msg);
  unsetenv("FAKE_NO_PAIR");
  /* a temporary workspace goes after success */
  job.work = NULL;
  CHECK_OK(hearth_colmap_run(&job, &res, &err), &err);
  CHECK(res.work[0] == 0);
  /* no program */
  job.colmap = "/nonexistent/colmap";
  CHECK(hearth_colmap_run(&job, &res, &err) == HEARTH_E_NOT_FOUND);
  CHECK(strstr(err.msg, "'/nonexistent/colmap' not found") &&
        strstr(err.msg, "apt-get install colmap"));
  job.colmap = "hearth-no-such-colmap";
  CHECK(hearth_colmap_run(&job, &res, &err) == HEARTH_E_NOT_FOUND);
  CHECK(strstr(err.msg, "not found on PATH"));
}

static void test_cli(void) {
  char cmd[4096], out[8192], work[1200];
  snprintf(work, sizeof work, "%s/cli_work", g_dir);
  snprintf(cmd, sizeof cmd,
           "'%s' recon '%s' --instance cup_01 --poses colmap --colmap '%s' "
           "--work '%s' --force --threads 1 2>&1",
           HEARTH_EXE, g_root, g_fake, work);
  CHECK(run_cmd(cmd, out, sizeof out) == 0);
  CHECK_MSG(strstr(out, "recon cup_01: 3 of 4 views registered (75%)") &&
                strstr(out, "colmap feature_extractor") && strstr(out, "4/4"),
            "%s", out);
  snprintf(cmd, sizeof cmd,
           "'%s' recon import-colmap '%s/sparse/0' --root '%s' --instance cup_01 "
           "--force 2>&1",
           HEARTH_EXE, work, g_root);
  CHECK(run_cmd(cmd, out, sizeof out) == 0);
  CHECK_MSG(strstr(out, "(text): 1 camera(s), 3 image(s), 0 point(s)") &&
                strstr(out, "cup_01: 3 of 4 views have a pose; without: hot/v01"),
            "%s", out);
  snprintf(cmd, sizeof cmd,
           "'%s' recon import-colmap '%s/sparse/0' --root '%s' --instance cup_01 2>&1", HEARTH_EXE,
           work, g_root);
  CHECK(run_cmd(cmd, out, sizeof out) == 1 && strstr(out, "--force"));
  snprintf(cmd, sizeof cmd,
           "'%s' recon import-colmap '%s/sparse/0' --out '%s/x/p.json' --state hot 2>&1",
           HEARTH_EXE, work, g_dir);
  CHECK(run_cmd(cmd, out, sizeof out) == 0);
  snprintf(cmd, sizeof cmd, "%s/x/p_cameras.json", g_dir);
  CHECK(hearth_path_exists(cmd));
  /* usage errors exit 2 and name the problem */
  static const struct {
    const char *args, *want;
  } k_usage[] = {
      {"recon", "ROOT"},
      {"recon /nonexistent --poses colmap", "--instance"},
      {"recon /nonexistent --instance cup_01 --work /w", "--poses colmap"},
      {"recon /nonexistent --instance cup_01 --poses sfm", "sfm"},
      {"recon /a /b --instance cup_01 --poses colmap", "/b"},
      {"recon /a --instance cup_01 --poses colmap --threads 0", "--threads"},
      {"recon import-colmap", "MODEL_DIR"},
      {"recon import-colmap /m", "--out"},
      {"recon import-colmap /m --root /r", "--root and --instance"},
      {"recon import-colmap /m --out f.json --state frozen", "frozen"},
      {"recon import-colmap /m --no-such-option", "--no-such-option"},
  };
  for (size_t i = 0; i < sizeof k_usage / sizeof k_usage[0]; i++) {
    snprintf(cmd, sizeof cmd, "'%s' %s 2>&1", HEARTH_EXE, k_usage[i].args);
    int rc = run_cmd(cmd, out, sizeof out);
    CHECK_MSG(rc == 2 && strstr(out, k_usage[i].want), "%s: rc %d: %s", k_usage[i].args, rc, out);
  }
  /* failures exit 1 */
  snprintf(cmd, sizeof cmd, "'%s' recon import-colmap /nonexistent/model --out '%s/y.json' 2>&1",
           HEARTH_EXE, g_dir);
  CHECK(run_cmd(cmd, out, sizeof out) == 1 && strstr(out, "no such folder"));
  snprintf(cmd, sizeof cmd,
           "'%s' recon '%s' --instance cup_01 --poses colmap --colmap /nonexistent/colmap "
           "--force 2>&1",
           HEARTH_EXE, g_root);
  CHECK(run_cmd(cmd, out, sizeof out) == 1 && strstr(out, "not found"));
  for (int h = 0; h < 2; h++) {
    snprintf(cmd, sizeof cmd, "'%s' recon %s--help 2>&1", HEARTH_EXE, h ? "import-colmap " : "");
    CHECK(run_cmd(cmd, out, sizeof out) == 0);
    CHECK(strstr(out,
                 h ? "usage: hearth recon import-colmap MODEL_DIR" : "usage: hearth recon ROOT"));
  }
}

/* with COLMAP installed: its own writer's binary and text forms of the
 * fixture import to the same bytes, and to the fixture's poses (COLMAP
 * renormalises the quaternions, so up to rounding) */
static void test_real_colmap(void) {
  if (!hearth_program_found("colmap")) {
    printf("colmap not on PATH: its model_converter check skipped\n");
    return;
  }
  hearth_err err = {0};
  char fx[1200], bin[1200], txt[1200], cmd[4096];
  snprintf(fx, sizeof fx, "%s/real_fixture", g_dir);
  snprintf(bin, sizeof bin, "%s/real_bin", g_dir);
  snprintf(txt, sizeof txt, "%s/real_txt", g_dir);
  snprintf(cmd, sizeof cmd, "mkdir -p '%s' '%s' '%s'", fx, bin, txt);
  CHECK(system(cmd) == 0);
  CHECK(fx_write_text_as(fx, 0) == 0);
  const char *to_bin[] = {"colmap", "model_converter", "--input_path", fx,  "--output_path",
                          bin,      "--output_type",   "BIN",          NULL};
  const char *to_txt[] = {"colmap", "model_converter", "--input_path", bin, "--output_path",
                          txt,      "--output_type",   "TXT",          NULL};
  CHECK_OK(hearth_exec("colmap model_converter", to_bin, NULL, NULL, NULL, &err), &err);
  CHECK_OK(hearth_exec("colmap model_converter", to_txt, NULL, NULL, NULL, &err), &err);
  const char *dirs[3] = {fx, bin, txt};
  hearth_poses p[3];
  hearth_recon_cameras c[3];
  char out[3][1300], cams[3][1300];
  for (int k = 0; k < 3; k++) {
    hearth_colmap_model m;
    CHECK_OK(hearth_colmap_read(dirs[k], &m, &err), &err);
    CHECK(m.format == (k == 1 ? HEARTH_COLMAP_BINARY : HEARTH_COLMAP_TEXT));
    CHECK(m.n_cameras == 3 && m.n_images == 4 && m.n_points == 3);
    CHECK_OK(hearth_colmap_to_poses(&m, "neutral", &p[k], &c[k], &err), &err);
    snprintf(out[k], sizeof out[k], "%s/real_%d.json", g_dir, k);
    CHECK(hearth_recon_cameras_path(out[k], cams[k], sizeof cams[k]) == HEARTH_OK);
    CHECK_OK(hearth_poses_write(out[k], &p[k], &err), &err);
    CHECK_OK(hearth_recon_cameras_write(cams[k], &c[k], &err), &err);
    hearth_colmap_model_free(&m);
  }
  char *a = slurp(out[1]), *b = slurp(out[2]), *ca = slurp(cams[0]), *cb = slurp(cams[1]);
  CHECK(a && b && !strcmp(a, b));
  CHECK(ca && cb && !strcmp(ca, cb));
  free(a);
  free(b);
  free(ca);
  free(cb);
  CHECK(p[0].n == 4 && p[1].n == 4);
  for (size_t i = 0; i < p[0].n && i < p[1].n; i++) {
    CHECK(!strcmp(p[0].views[i].view, p[1].views[i].view));
    for (int k = 0; k < 9; k++)
      CHECK_NEAR(p[0].views[i].T_world_from_cam.R[k], p[1].views[i].T_world_from_cam.R[k], 1e-14);
    for (int k = 0; k < 3; k++)
      CHECK_NEAR(p[0].views[i].T_world_from_cam.t[k], p[1].views[i].T_world_from_cam.t[k], 1e-14);
  }
  for (int k = 0; k < 3; k++) {
    hearth_poses_free(&p[k]);
    hearth_recon_cameras_free(&c[k]);
  }
}

int main(void) {
  snprintf(g_dir, sizeof g_dir, "%s", test_tmpdir("recon_colmap_run"));
  snprintf(g_root, sizeof g_root, "%s/release", g_dir);
  snprintf(g_fake, sizeof g_fake, "%s/fake-colmap", g_dir);
  snprintf(g_log, sizeof g_log, "%s/fake-colmap.log", g_dir);
  FILE *f = fopen(g_fake, "w");
  CHECK(f != NULL);
  if (!f) TEST_MAIN_END();
  fputs(k_fake, f);
  fclose(f);
  chmod(g_fake, 0755);
  setenv("FAKE_COLMAP_LOG", g_log, 1);
  make_release();
  test_exec();
  test_run();
  test_cli();
  test_real_colmap();
  TEST_MAIN_END();
}
