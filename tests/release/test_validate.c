/* hearth validate: a clean tiny built release has no problem; each planted
 * defect (missing view file, 255x192 CSV, mask value 7, non-rotation pose,
 * provenance naming a view that does not exist) is reported with its path.
 * recon/report.json of hearth's own reconstruction passes, and each damaged
 * copy of it fails with the member named. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/npy.h"
#include "hearth/map.h"
#include "hearth/poses.h"
#include "hearth/recon_geom.h"
#include "hearth/dataset.h"
#include "hearth/release.h"
#include "hearth/synth.h"
#include "test_util.h"

static char g_root[1024];

/* problems of the release at root; returns the count, fills a hit flag for a
 * problem whose path ends with `suffix` and whose text contains `needle` */
static size_t validate_opts(const char *root, int raw_only, const char *suffix, const char *needle,
                            int *hit) {
  hearth_problems pr = {0};
  hearth_err err = {0};
  hearth_validate_opts o;
  hearth_validate_opts_default(&o);
  o.threads = 2;
  o.raw_only = raw_only;
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

static size_t validate(const char *root, const char *suffix, const char *needle, int *hit) {
  return validate_opts(root, 0, suffix, needle, hit);
}

/* a fresh copy of the built release to damage */
static const char *fresh_copy(const char *name) {
  static char dst[1200];
  snprintf(dst, sizeof dst, "%s/../%s", g_root, name);
  test_sh("rm -rf '%s'%s", dst, "");
  test_sh("cp -a '%s' '%s'", g_root, dst);
  return dst;
}

/* recon/report.json as hearth recon writes it (a can, 6 views x 2 states,
 * poses, mesh and atlas): it passes; each copy damaged by one python edit
 * of the JSON (or of the file beside it) fails with exactly one problem
 * naming the report and the member. */
static void test_recon_report(void) {
  const char *base = test_tmpdir("validate_recon");
  hearth_err err = {0};
  char root[1100], p[2048];
  snprintf(root, sizeof root, "%s/rel", base);
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.out_root = root;
  so.n_categories = 1;
  so.categories[0] = "canned_drink";
  so.seed = 1;
  so.n_views = 6;
  so.texture_size = 64;
  so.map_resolution = 32;
  so.calibration = 0;
  so.no_recon = 1;
  so.threads = 2;
  so.quiet = 1;
  so.rgb_full_size = 0;
  CHECK_OK(hearth_synth_release(&so, &err), &err);
  hearth_recon_job job;
  hearth_recon_job_default(&job);
  job.root = root;
  job.instance = "canned_drink_01";
  job.poses.threads = 2;
  job.quiet = 1;
  hearth_recon_summary sum;
  CHECK_OK(hearth_recon_run(&job, &sum, &err), &err);
  hearth_recon_summary_free(&sum);
  int hit;
  size_t n = validate_opts(root, 1, NULL, NULL, NULL);
  CHECK_MSG(n == 0, "hearth's own recon/: %zu problem(s)", n);
  const char *rep = "instances/canned_drink_01/recon/report.json";
  /* each damage: a python statement on d (the report's JSON) or a shell
   * command in the copy, and the problem expected */
  static const struct {
    const char *py, *sh, *want;
    size_t n; /* problems in all (0: one) */
  } cases[] = {
      {NULL, "truncate -s 100 %s", "line "},
      /* and poses_rgb.json's 12 and per_view's 12 */
      {"d['views'] -= 1", NULL, "views: 11, but the manifests list 12", 3},
      {"del d['icp_rms_mm']", NULL, "icp_rms_mm: missing (a number)"},
      {"d['route'] = 'colmap'", NULL, "route: 'colmap', expected 'turntable'"},
      {"d['per_view'][3]['view'] = 'v77'", NULL,
       "per_view[3].view: 'v77' does not exist in neutral's manifest"},
      {"d['per_view'][4]['matches'] = -3", NULL, "per_view[4].matches: expected an integer >= 0"},
      {"d['per_view'].pop()", NULL, "per_view: 11 entries, but views is 12"},
      {"d['aim']['states'][1]['state'] = 'hot'", NULL,
       "aim.states[1].state: 'hot' is not a state of this instance"},
      {"d['aim']['states'][1]['state'] = 'neutral'", NULL,
       "aim.states[1].state: 'neutral' listed twice"},
      {"d['aim']['states'][0]['point_m'][2] = 'x'", NULL,
       "aim.states[0].point_m: expected an array of 3 finite numbers"},
      {"d['aim']['states'][0]['axis_m'][2] = 0.01", NULL, "aim.states[0].axis_m: ("},
      {"d['aim']['states'][1]['sigma_along_mm'] = -2.0", NULL,
       "aim.states[1].sigma_along_mm: -2, expected a number >= 0"},
      {"del d['aim']['states'][0]['sigma_across_mm']", NULL,
       "aim.states[0].sigma_across_mm: missing (a number, or null)"},
      {"d['aim']['axis_direction'] = [0.0, 1.0, 0.0]", NULL, "aim.axis_direction: (0, 1, 0)"},
      {"d['aim']['places'][0]['distance_m'] *= 2", NULL, "aim.places[0].distance_m: "},
      {"d['aim']['places'][0]['views'] = 11", NULL, "aim: the states hold 12 views, the places 11"},
      {"d['aim'] = 0.1", NULL, "aim: expected null (the term off) or an object"},
      {"d['mesh']['triangles'] += 1", NULL, "but mesh_geometry.glb has"},
      {"d['atlas']['charts'] += 1", NULL, "UV islands"},
      {"d['atlas']['packing_efficiency'] = 1.5", NULL, "atlas.packing_efficiency: 1.5"},
      {NULL,
       "python3 -c \"import json; f='instances/canned_drink_01/recon/poses_rgb.json'; "
       "d=json.load(open(f)); d['views'].pop(); json.dump(d, open(f, 'w'))\"",
       "views: 12, but poses_rgb.json has 11", 2 /* and the view without a pose */},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    char d[1200], name[32];
    snprintf(name, sizeof name, "recon%zu", i);
    snprintf(d, sizeof d, "%s/%s", base, name);
    test_sh("rm -rf '%s'%s", d, "");
    test_sh("cp -a '%s' '%s'", root, d);
    snprintf(p, sizeof p, "%s/%s", d, rep);
    if (cases[i].py) {
      char cmd[2048];
      snprintf(cmd, sizeof cmd,
               "python3 -c \"import json,sys; f=sys.argv[1]; d=json.load(open(f)); %s; "
               "json.dump(d, open(f, 'w'))\" '%%s'%%s",
               cases[i].py);
      test_sh(cmd, p, "");
    } else {
      char cmd[2048];
      snprintf(cmd, sizeof cmd, cases[i].sh, rep);
      test_sh("cd '%s' && %s", d, cmd);
    }
    n = validate_opts(d, 1, rep, cases[i].want, &hit);
    CHECK_MSG(hit && n == (cases[i].n ? cases[i].n : 1), "case %zu (%s): hit %d, %zu problem(s)", i,
              cases[i].py ? cases[i].py : cases[i].sh, hit, n);
  }
  /* the term off: aim null is well formed */
  {
    char d[1200];
    snprintf(d, sizeof d, "%s/aim_null", base);
    test_sh("rm -rf '%s'%s", d, "");
    test_sh("cp -a '%s' '%s'", root, d);
    snprintf(p, sizeof p, "%s/%s", d, rep);
    test_sh(
        "python3 -c \"import json,sys; f=sys.argv[1]; d=json.load(open(f)); d['aim'] = None; "
        "json.dump(d, open(f, 'w'))\" '%s'%s",
        p, "");
    n = validate_opts(d, 1, NULL, NULL, NULL);
    CHECK_MSG(n == 0, "aim null: %zu problem(s)", n);
  }
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
  /* 6. recon/, the hand-over a rebuild reads: a view the reconstruction did
     not register is fine; a truncated poses file, a pose of a view that
     does not exist and a truncated mesh are each named (raw-only too) */
  {
    const char *d = fresh_copy("recon");
    snprintf(p, sizeof p, "%s/instances/cup_01/recon/poses_rgb.json", d);
    test_sh(
        "python3 -c \"import json,sys; f=sys.argv[1]; d=json.load(open(f)); "
        "del d['views'][0]; json.dump(d,open(f,'w'))\" '%s'%s",
        p, "");
    n = validate(d, NULL, NULL, NULL);
    CHECK_MSG(n == 0, "recon poses without one view: %zu problem(s)", n);
    test_sh(
        "python3 -c \"import json,sys; f=sys.argv[1]; d=json.load(open(f)); "
        "d['views'][1]['view']='v77'; json.dump(d,open(f,'w'))\" '%s'%s",
        p, "");
    n = validate(d, "recon/poses_rgb.json", "'v77' does not exist", &hit);
    CHECK_MSG(hit && n == 1, "recon pose v77: hit %d, %zu problem(s)", hit, n);
    test_sh("f='%s' && head -c 200 \"$f\" > \"$f.cut\" && mv \"$f.cut\" \"$f\"%s", p, "");
    n = validate_opts(d, 1, "recon/poses_rgb.json", "line", &hit);
    CHECK_MSG(hit && n == 1, "truncated recon poses (raw-only): hit %d, %zu problem(s)", hit, n);
    snprintf(p, sizeof p, "%s/instances/cup_01/recon/mesh.glb", d);
    test_sh("f='%s' && head -c 1000 \"$f\" > \"$f.cut\" && mv \"$f.cut\" \"$f\"%s", p, "");
    n = validate(d, "recon/mesh.glb", "does not match the file size", &hit);
    CHECK_MSG(hit && n == 2, "truncated recon mesh: hit %d, %zu problem(s)", hit, n);
  }
  test_recon_report();
  TEST_MAIN_END();
}
