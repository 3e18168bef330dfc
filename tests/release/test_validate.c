/* hearth validate: a clean tiny built release has no problem; each planted
 * defect (missing view file, 255x192 CSV, mask value 7, non-rotation pose,
 * provenance naming a view that does not exist) is reported with its path. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/npy.h"
#include "hearth/map.h"
#include "hearth/poses.h"
#include "hearth/poses.h"
#include "hearth/dataset.h"
#include "hearth/release.h"
#include "hearth/synth.h"
#include "test_util.h"

static char g_root[1024];

/* problems of the release at root; returns the count, fills a hit flag for a
 * problem whose path ends with `suffix` and whose text contains `needle` */
static size_t validate(const char *root, const char *suffix, const char *needle, int *hit) {
  hearth_problems pr = {0};
  hearth_err err = {0};
  hearth_validate_opts o;
  hearth_validate_opts_default(&o);
  o.threads = 2;
  CHECK_OK(hearth_validate_release(root, &o, &pr, NULL, &err), &err);
  if (hit) *hit = 0;
  for (size_t i = 0; i < pr.n; i++) {
    size_t lp = strlen(pr.items[i].path), ls = suffix ? strlen(suffix) : 0;
    if (hit && suffix && lp >= ls && !strcmp(pr.items[i].path + lp - ls, suffix) &&
        (!needle || strstr(pr.items[i].what, needle)))
      *hit = 1;
    if (hit && !*hit) fprintf(stderr, "  problem: %s: %s\n", pr.items[i].path, pr.items[i].what);
  }
  size_t n = pr.n;
  hearth_problems_free(&pr);
  return n;
}

/* a fresh copy of the built release to damage */
static const char *fresh_copy(const char *name) {
  static char dst[1200];
  snprintf(dst, sizeof dst, "%s/../%s", g_root, name);
  test_sh("rm -rf '%s'%s", dst, "");
  test_sh("cp -a '%s' '%s'", g_root, dst);
  return dst;
}

int main(void) {
  const char *base = test_tmpdir("validate");
  hearth_err err = {0};
  snprintf(g_root, sizeof g_root, "%s/rel", base);
  /* a tiny release built stage by stage with the library */
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.ideal = 1; /* closed-form: the clean rig */
  so.out_root = g_root;
  so.seed = 5;
  so.n_views = 3;
  so.triangles = 800;
  so.texture_size = 64;
  so.map_resolution = 32;
  so.calibration = 0;
  so.threads = 2;
  so.quiet = 1;
  so.rgb_full_size = 0; /* draft colour: these checks do not look at colour */
  CHECK_OK(hearth_synth_release(&so, &err), &err);
  char p[2048], q[2048];
  /* calibration: the true rig stands in (calibration has its own tests) */
  snprintf(p, sizeof p, "%s/ground_truth/rig.json", g_root);
  snprintf(q, sizeof q, "%s/calibration/rig.json", g_root);
  test_sh("cp '%s' '%s'", p, q);
  hearth_scale_job sj = {g_root, "cup_01", NULL, {0}};
  hearth_scale_opts_default(&sj.opts);
  sj.opts.threads = 2;
  CHECK_OK(hearth_scale_run(&sj, NULL, &err), &err);
  hearth_transfer_job tj = {g_root, "cup_01", NULL, NULL, 0};
  CHECK_OK(hearth_transfer_run(&tj, &err), &err);
  const char *states[2] = {"neutral", "hot"};
  for (int k = 0; k < 2; k++) {
    hearth_map_job mj;
    hearth_map_job_default(&mj);
    mj.root = g_root;
    mj.instance = "cup_01";
    mj.state = states[k];
    mj.map.resolution = 32;
    mj.map.threads = 2;
    CHECK_OK(hearth_map_run(&mj, NULL, &err), &err);
  }
  int hit;
  size_t n = validate(g_root, NULL, NULL, NULL);
  CHECK_MSG(n == 0, "clean release: %zu problem(s)", n);

  /* raw-only on a release never built: no derived/ complaints */
  {
    const char *d = fresh_copy("rawonly");
    snprintf(p, sizeof p, "%s/instances/cup_01/derived", d);
    test_sh("rm -rf '%s'%s", p, "");
    n = validate(d, "instances/cup_01/derived", "never built", &hit);
    CHECK(n >= 1 && hit);
    hearth_problems pr = {0};
    hearth_validate_opts o;
    hearth_validate_opts_default(&o);
    o.raw_only = 1;
    CHECK_OK(hearth_validate_release(d, &o, &pr, NULL, &err), &err);
    CHECK_MSG(pr.n == 0, "raw-only: %zu problem(s)", pr.n);
    hearth_problems_free(&pr);
  }

  /* 1. a missing view: its thermal CSV removed */
  {
    const char *d = fresh_copy("missing");
    snprintf(p, sizeof p, "%s/instances/cup_01/raw/hot/thermal/v00.csv", d);
    CHECK(remove(p) == 0);
    n = validate(d, "raw/hot/thermal/v00.csv", "missing", &hit);
    CHECK_MSG(hit, "missing view file not reported");
    /* the whole view gone: all five files */
    snprintf(p, sizeof p, "%s/instances/cup_01/raw/hot", d);
    test_sh("cd '%s' && rm -f rgb/v00.jpg cutout/v00.png depth/v00.png depth/v00.json%s", p, "");
    n = validate(d, "raw/hot/rgb/v00.jpg", "missing", &hit);
    CHECK(hit && n >= 5);
  }
  /* 2. a 255x192 CSV: drop the last column of every line */
  {
    const char *d = fresh_copy("csv255");
    snprintf(p, sizeof p, "%s/instances/cup_01/raw/neutral/thermal/v00.csv", d);
    test_sh("sed -i 's/,[^,]*$//' '%s'%s", p, "");
    n = validate(d, "raw/neutral/thermal/v00.csv", NULL, &hit);
    CHECK_MSG(hit && n == 1, "255x192 CSV: hit %d, %zu problem(s)", hit, n);
  }
  /* 3. a mask value of 7 */
  {
    const char *d = fresh_copy("mask7");
    snprintf(p, sizeof p, "%s/instances/cup_01/derived/hot/mask.npy", d);
    hearth_npy m = {0};
    CHECK_OK(hearth_npy_read(p, &m, &err), &err);
    if (m.data) {
      ((uint8_t *)m.data)[5 * 32 + 9] = 7;
      CHECK_OK(hearth_npy_write(p, HEARTH_NPY_U8, 2, m.shape, m.data, &err), &err);
    }
    hearth_npy_free(&m);
    n = validate(d, "derived/hot/mask.npy", "[5][9] = 7", &hit);
    CHECK_MSG(hit && n == 1, "mask 7: hit %d, %zu problem(s)", hit, n);
  }
  /* 4. a non-rotation pose: scale one rotation entry */
  {
    const char *d = fresh_copy("pose");
    snprintf(p, sizeof p, "%s/instances/cup_01/derived/poses_thermal.json", d);
    hearth_poses ps = {0};
    CHECK_OK(hearth_poses_read(p, &ps, &err), &err);
    /* rewrite the text: the writer refuses a non-rotation, so edit it by hand */
    hearth_poses_free(&ps);
    test_sh(
        "python3 -c \"import json,sys; f=sys.argv[1]; d=json.load(open(f)); "
        "d['views'][1]['T_world_from_cam'][0][0]*=1.5; json.dump(d,open(f,'w'))\" '%s'%s",
        p, "");
    n = validate(d, "derived/poses_thermal.json", "views[1]", &hit);
    CHECK_MSG(hit, "non-rotation pose not reported");
  }
  /* 5. provenance naming a view that does not exist */
  {
    const char *d = fresh_copy("prov");
    snprintf(p, sizeof p, "%s/instances/cup_01/derived/neutral/provenance.json", d);
    test_sh(
        "python3 -c \"import json,sys; f=sys.argv[1]; d=json.load(open(f)); "
        "d['source_views'].append('v77'); json.dump(d,open(f,'w'))\" '%s'%s",
        p, "");
    n = validate(d, "derived/neutral/provenance.json", "'v77' does not exist", &hit);
    CHECK_MSG(hit && n == 1, "provenance v77: hit %d, %zu problem(s)", hit, n);
  }
  /* several defects at once: every one listed */
  {
    const char *d = fresh_copy("many");
    snprintf(p, sizeof p, "%s/instances/cup_01/raw/hot/thermal/v00.csv", d);
    CHECK(remove(p) == 0);
    snprintf(p, sizeof p, "%s/instances/cup_01/raw/neutral/thermal/v00.csv", d);
    test_sh("sed -i '$d' '%s'%s", p, "");
    snprintf(p, sizeof p, "%s/instances/cup_01/derived/hot/thermal_turbo.png", d);
    CHECK(remove(p) == 0);
    n = validate(d, NULL, NULL, NULL);
    CHECK_MSG(n == 3, "three defects: %zu problem(s)", n);
  }
  TEST_MAIN_END();
}
