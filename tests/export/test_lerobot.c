/* `hearth sim export --lerobot` end to end: 3 layouts of H1 collected on a
 * tiny virtual-rig release and a synthetic collection (320-pixel images, an
 * orientation through half a turn, an instruction with quotes and non-ASCII
 * letters) are exported through the CLI, every Parquet file is read back
 * through DuckDB (tests/io/read_parquet.js) and tests/export/check_lerobot.py
 * compares every row with the HDF5 files, every image with what `hearth sim
 * eval` encodes for the same frame (written here as .npy) and the meta files
 * with what LeRobot's writer makes. Also: the bytes do not depend on the
 * thread count, the state's axis-angle stays continuous where the rotation
 * vector flips, a dynamic-temperature collection adds the thermal_state
 * column (its values and region names those of obs/thermal_state; dropped
 * with --no-thermal), and refused exports (non-empty output, mixed image
 * sizes, mixed thermal states, a missing file) say why and leave nothing. */
#include <dirent.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>

#include "export/export_internal.h"
#include "hearth/hearth.h"
#include "hearth/export.h"
#include "test_util.h"
#include "test_sim_release.h"

static char g_dir[1100], g_src[1100];

static int run(const char *cmd) {
  int rc = system(cmd);
  if (rc == -1 || !WIFEXITED(rc)) return -1;
  return WEXITSTATUS(rc);
}

/* the exit status of `hearth sim export ARGS`, its stderr in err_path */
static int export_cli(const char *args, const char *err_path) {
  char cmd[8000];
  snprintf(cmd, sizeof cmd, "'%s' sim export --quiet %s >/dev/null 2>'%s'", HEARTH_EXE, args,
           err_path);
  return run(cmd);
}

static int file_has(const char *path, const char *needle) {
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  char buf[8192];
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[n] = 0;
  return strstr(buf, needle) != NULL;
}

/* what hearth_eval_encode_obs sends for frames 0, T/2 and T-1 of every demo,
 * at the stored size (so the resize is the identity): EVAL_DIR/ep<E>_f<K>_<feature>.npy */
static void write_eval_frames(const char *h5, const char *eval_dir) {
  hearth_err err = {0};
  ex_source s;
  CHECK_OK(ex_source_open(h5, &s, &err), &err);
  for (int64_t k = 0; k < s.num_demos; k++) {
    ex_demo d;
    CHECK_OK(ex_demo_read(&s, k, 1, &d, &err), &err);
    size_t frames[3] = {0, d.T / 2, d.T - 1}, fs = (size_t)s.size * (size_t)s.size * 3;
    for (int j = 0; j < 3 && d.rgb; j++) {
      size_t i = frames[j];
      hearth_sim_obs ob = {s.size, s.size, d.rgb + i * fs, d.thermal + i * fs, d.wrist + i * fs};
      hearth_mp_writer w;
      hearth_mp_writer_init(&w);
      CHECK_OK(hearth_eval_encode_obs(&ob, d.instruction, 1, s.size, &w, &err), &err);
      hearth_mp_doc doc = {0};
      CHECK_OK(hearth_mp_decode(w.buf, w.len, NULL, &doc, &err), &err);
      static const char *keys[3][2] = {{"observation/image", "image"},
                                       {"observation/wrist_image", "wrist_image"},
                                       {"observation/thermal_image", "thermal_image"}};
      for (int v = 0; v < 3 && doc.root; v++) {
        hearth_mp_ndarray a;
        const hearth_mp_value *val = hearth_mp_map_get(doc.root, keys[v][0], HEARTH_MP_STR);
        CHECK_OK(hearth_mp_ndarray_get(val, keys[v][0], &a, &err), &err);
        char path[1400];
        snprintf(path, sizeof path, "%s/ep%lld_f%zu_%s.npy", eval_dir, (long long)k, i, keys[v][1]);
        size_t shape[3] = {(size_t)s.size, (size_t)s.size, 3};
        CHECK(a.count == fs);
        if (a.count == fs)
          CHECK_OK(hearth_npy_write(path, HEARTH_NPY_U8, 3, shape, a.data, &err), &err);
      }
      hearth_mp_doc_free(&doc);
      hearth_mp_writer_free(&w);
    }
    ex_demo_free(&d);
  }
  ex_source_close(&s);
}

/* each reader's dump of DIR's Parquet files (DuckDB; the Arrow Rust reader),
 * then check_lerobot.py on each */
static void check_dataset(const char *ds, const char *eval_dir, const char *flags, const char *h5) {
  static const char *const readers[] = {"read_parquet.js", "read_parquet_arrow.js"};
  for (int k = 0; k < 2; k++) {
    char cmd[8000];
    snprintf(cmd, sizeof cmd,
             "node '%s/tests/io/%s' '%s.dump%d.json' '%s'/data/chunk-000/*.parquet", g_src,
             readers[k], ds, k, ds);
    int rc = run(cmd);
    CHECK_MSG(rc == 0, "%s on %s: exit status %d (1: unreadable, 3: its npm packages missing)",
              readers[k], ds, rc);
    if (rc) continue;
    snprintf(
        cmd, sizeof cmd,
        "/usr/bin/python3 '%s/tests/export/check_lerobot.py' check '%s' '%s.dump%d.json' '%s' %s "
        "'%s'",
        g_src, ds, ds, k, eval_dir, flags, h5);
    CHECK_MSG(run(cmd) == 0, "check_lerobot.py found differences in %s (read by %s)", ds,
              readers[k]);
  }
}

static int no_temp_left(void) {
  DIR *d = opendir(g_dir);
  int ok = 1;
  struct dirent *e;
  while (d && (e = readdir(d)))
    if (strstr(e->d_name, ".tmp-")) ok = 0;
  if (d) closedir(d);
  return ok;
}

static void test_axis_angle(void) {
  /* 3.2 rad about x is the rotation vector -(2 pi - 3.2) x; the continuous form says 3.2 x */
  double out[3], pi = 3.14159265358979323846;
  hearth_lerobot_axis_angle((double[]){-(2 * pi - 3.2), 0, 0}, out);
  CHECK_NEAR(out[0], 3.2, 1e-12);
  CHECK_NEAR(out[1], 0, 1e-12);
  hearth_lerobot_axis_angle((double[]){3.1, 0, 0}, out);
  CHECK_NEAR(out[0], 3.1, 1e-12);
  hearth_lerobot_axis_angle((double[]){0, 0.1, 0}, out);
  CHECK_NEAR(out[1], 0.1, 1e-12);
  hearth_lerobot_axis_angle((double[]){0, 0, 0}, out);
  CHECK(out[0] == 0 && out[1] == 0 && out[2] == 0);
  uint8_t in[2 * 2 * 3] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}, rot[12];
  hearth_lerobot_rotate180(in, 2, 2, rot);
  CHECK(rot[0] == 10 && rot[2] == 12 && rot[9] == 1 && rot[11] == 3);
}

int main(void) {
  const char *src = getenv("HEARTH_SOURCE_DIR");
  snprintf(g_src, sizeof g_src, "%s", src && *src ? src : ".");
  if (run("node --version >/dev/null 2>&1") != 0 ||
      run("/usr/bin/python3 -c 'import numpy, h5py, cv2' 2>/dev/null") != 0) {
    fprintf(
        stderr,
        "FAIL: node and /usr/bin/python3 with numpy, h5py and cv2 are needed; run scripts/setup.sh\n");
    return 1;
  }
  snprintf(g_dir, sizeof g_dir, "%s", test_tmpdir("export_lerobot"));
  test_axis_angle();

  char h1[1200], syn[1200], cmd[8000], errp[1200], eval_dir[1200];
  const char *root = test_sim_release(g_dir);
  snprintf(h1, sizeof h1, "%s/h1.hdf5", g_dir);
  snprintf(syn, sizeof syn, "%s/synthetic.hdf5", g_dir);
  snprintf(errp, sizeof errp, "%s/stderr.txt", g_dir);
  snprintf(eval_dir, sizeof eval_dir, "%s/eval", g_dir);
  hearth_sim_collect_opts c;
  hearth_sim_collect_opts_default(&c);
  c.task = HEARTH_SIM_H1;
  c.release_root = root;
  c.use_ground_truth = 1;
  c.layouts = 3;
  c.image_size = 48;
  c.quiet = 1;
  c.out_path = h1;
  hearth_err err = {0};
  hearth_sim_collect_stats cs;
  CHECK_OK(hearth_sim_collect(&c, &cs, &err), &err);
  CHECK(cs.demos == 6);
  snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s/tests/export/check_lerobot.py' synthetic '%s'",
           g_src, syn);
  CHECK(run(cmd) == 0);
  CHECK_OK(hearth_mkdirs(eval_dir, &err), &err);
  write_eval_frames(h1, eval_dir);

  /* the collected demos */
  char ds[1300], args[4000];
  snprintf(ds, sizeof ds, "%s/ds_h1", g_dir);
  snprintf(args, sizeof args, "--lerobot '%s' '%s'", ds, h1);
  CHECK_MSG(export_cli(args, errp) == 0, "export of %s failed", h1);
  check_dataset(ds, eval_dir, "--expect-flip", h1);

  /* the same bytes on one thread */
  char ds1[1300];
  snprintf(ds1, sizeof ds1, "%s/ds_h1_1thread", g_dir);
  snprintf(args, sizeof args, "--threads 1 --lerobot '%s' '%s'", ds1, h1);
  CHECK(export_cli(args, errp) == 0);
  snprintf(cmd, sizeof cmd, "diff -r '%s' '%s' >/dev/null", ds, ds1);
  CHECK_MSG(run(cmd) == 0, "%s and %s differ", ds, ds1);

  /* dynamic temperatures: obs/thermal_state becomes the thermal_state column */
  char dyn[1200];
  snprintf(dyn, sizeof dyn, "%s/h1_dynamic.hdf5", g_dir);
  c.layouts = 1;
  c.thermal = HEARTH_SIM_THERMAL_DYNAMIC;
  c.thermal_speedup = 60;
  c.out_path = dyn;
  CHECK_OK(hearth_sim_collect(&c, &cs, &err), &err);
  snprintf(ds, sizeof ds, "%s/ds_dyn", g_dir);
  snprintf(args, sizeof args, "--lerobot '%s' '%s'", ds, dyn);
  CHECK_MSG(export_cli(args, errp) == 0, "export of %s failed", dyn);
  char info[1400];
  snprintf(info, sizeof info, "%s/meta/info.json", ds);
  CHECK(file_has(info, "\"thermal_state\"") && file_has(info, "obj0/cup/hot/liquid"));
  check_dataset(ds, "-", "", dyn);
  snprintf(ds, sizeof ds, "%s/ds_dyn_rgb", g_dir);
  snprintf(args, sizeof args, "--no-thermal --lerobot '%s' '%s'", ds, dyn);
  CHECK(export_cli(args, errp) == 0);
  snprintf(info, sizeof info, "%s/meta/info.json", ds);
  CHECK(!file_has(info, "thermal_state"));
  /* one dataset, one set of columns: a static and a dynamic file are refused */
  snprintf(ds, sizeof ds, "%s/ds_mixed_thermal", g_dir);
  snprintf(args, sizeof args, "--lerobot '%s' '%s' '%s'", ds, dyn, h1);
  CHECK(export_cli(args, errp) == 1 && file_has(errp, "thermal_state"));
  CHECK(!hearth_path_exists(ds));

  /* synthetic: downsampled statistics, a short demo, JSON escapes; and without thermal */
  snprintf(ds, sizeof ds, "%s/ds_syn", g_dir);
  snprintf(args, sizeof args, "--lerobot '%s' '%s'", ds, syn);
  CHECK(export_cli(args, errp) == 0);
  check_dataset(ds, "-", "--expect-flip", syn);
  snprintf(ds, sizeof ds, "%s/ds_syn_rgb", g_dir);
  snprintf(args, sizeof args, "--no-thermal --lerobot '%s' '%s'", ds, syn);
  CHECK(export_cli(args, errp) == 0);
  check_dataset(ds, "-", "--no-thermal", syn);

  /* refused: a non-empty output, mixed image sizes, a missing file */
  snprintf(ds, sizeof ds, "%s/ds_h1", g_dir);
  snprintf(args, sizeof args, "--lerobot '%s' '%s'", ds, h1);
  CHECK(export_cli(args, errp) == 1 && file_has(errp, "refusing to overwrite"));
  snprintf(ds, sizeof ds, "%s/ds_mixed", g_dir);
  snprintf(args, sizeof args, "--lerobot '%s' '%s' '%s'", ds, h1, syn);
  CHECK(export_cli(args, errp) == 1 && file_has(errp, "48-pixel") && file_has(errp, "320-pixel"));
  CHECK(!hearth_path_exists(ds));
  snprintf(args, sizeof args, "--lerobot '%s' '%s/missing.hdf5'", ds, g_dir);
  CHECK(export_cli(args, errp) == 1 && file_has(errp, "missing.hdf5"));
  CHECK(!hearth_path_exists(ds));
  CHECK(export_cli("--lerobot x", errp) == 2);
  CHECK(no_temp_left());
  TEST_MAIN_END();
}
