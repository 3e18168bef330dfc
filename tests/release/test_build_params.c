/* build.json: a build records the parameters it ran with; a later build
 * without them reuses them (no stage runs), an explicit one wins, and
 * ignore_recorded falls back to the defaults. The document round-trips
 * exactly, and a damaged one stops the build and is named by validate. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hearth/release.h"
#include "hearth/synth.h"
#include "release/release_internal.h"
#include "test_util.h"

static hearth_status build(const char *root, hearth_build_opts *o, hearth_build_report *rep,
                           hearth_err *err) {
  o->quiet = 1;
  o->threads = 2;
  o->jobs = 1;
  return hearth_build_release(root, o, rep, err);
}

static size_t problems_naming(const char *root, const char *suffix) {
  hearth_problems pr = {0};
  hearth_err err = {0};
  size_t hits = 0;
  CHECK_OK(hearth_validate_release(root, NULL, &pr, NULL, &err), &err);
  for (size_t i = 0; i < pr.n; i++) {
    size_t lp = strlen(pr.items[i].path), ls = strlen(suffix);
    if (lp >= ls && !strcmp(pr.items[i].path + lp - ls, suffix)) hits++;
  }
  hearth_problems_free(&pr);
  return hits;
}

int main(void) {
  hearth_err err = {0};
  /* the document: shortest exact reals, strict reading */
  const char *base = test_tmpdir("build_params");
  char path[1200], root[1100], cmd[4096];
  snprintf(path, sizeof path, "%s/build.json", base);
  hb_params p, q;
  hb_params_default(&p);
  p.min_cos = 0.2;
  p.fusion = HEARTH_FUSE_ROBUST;
  p.calib_overlays = 0;
  CHECK_OK(hb_params_write(path, &p, &err), &err);
  CHECK_OK(hb_params_read(path, &q, &err), &err);
  CHECK(hb_params_same(&p, &q));
  uint8_t *text = NULL;
  size_t len = 0;
  CHECK_OK(hearth_read_file(path, 1 << 20, &text, &len, &err), &err);
  CHECK_MSG(text && strstr((char *)text, "\"min_cos\": 0.2,") &&
                strstr((char *)text, "\"fusion\": \"robust\""),
            "%s", text ? (char *)text : "");
  free(text);
  const char *bad[] = {"[]", "{\"resolution\": 1024}",
                       "{\"resolution\": \"1024\", \"fusion\": \"max\"}",
                       "{\"resolution\": 1024, \"resolution\": 1024}"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    err.msg[0] = 0;
    CHECK(hb_params_parse(bad[i], strlen(bad[i]), "build.json", &q, &err) != HEARTH_OK);
    CHECK_MSG(!strncmp(err.msg, "build.json", 10), "%s", err.msg);
  }

  /* a tiny release; the true rig stands in for calibration */
  snprintf(root, sizeof root, "%s/rel", base);
  hearth_synth_opts so;
  hearth_synth_opts_default(&so);
  so.ideal = 1; /* closed-form: the clean rig */
  so.out_root = root;
  so.seed = 3;
  so.n_views = 2;
  so.triangles = 600;
  so.texture_size = 64;
  so.map_resolution = 32;
  so.calibration = 0;
  so.threads = 2;
  so.quiet = 1;
  so.rgb_full_size = 0;
  CHECK_OK(hearth_synth_release(&so, &err), &err);
  snprintf(cmd, sizeof cmd, "cp '%s/ground_truth/rig.json' '%s/calibration/rig.json'", root, root);
  CHECK(system(cmd) == 0);

  /* first build: its parameters land in build.json */
  hearth_build_opts o;
  hearth_build_report rep;
  hearth_build_opts_default(&o);
  o.resolution = 32;
  o.rgb_resolution = 64;
  o.min_cos = 0.1;
  CHECK_OK(build(root, &o, &rep, &err), &err);
  CHECK(rep.stages_run > 0 && rep.n_instances == 1 && !rep.instances[0].failed);
  hearth_build_report_free(&rep);
  snprintf(path, sizeof path, "%s/build.json", root);
  CHECK_OK(hb_params_read(path, &q, &err), &err);
  CHECK(q.resolution == 32 && q.rgb_resolution == 64 && q.min_cos == 0.1 &&
        q.fusion == HEARTH_FUSE_MAX && q.bake_rgb && q.calibrate && q.calib_overlays);
  CHECK(problems_naming(root, "build.json") == 0);

  /* no options: the recorded ones, nothing to do */
  hearth_build_opts_default(&o);
  CHECK_OK(build(root, &o, &rep, &err), &err);
  CHECK_MSG(rep.stages_run == 0, "%zu stage(s) ran", rep.stages_run);
  hearth_build_report_free(&rep);

  /* an explicit option wins and is recorded; the rest stays */
  hearth_build_opts_default(&o);
  o.resolution = 16;
  CHECK_OK(build(root, &o, &rep, &err), &err);
  CHECK(rep.stages_run == rep.instances[0].n_states); /* the maps */
  hearth_build_report_free(&rep);
  CHECK_OK(hb_params_read(path, &q, &err), &err);
  CHECK(q.resolution == 16 && q.rgb_resolution == 64 && q.min_cos == 0.1);

  /* the defaults instead of the record: stages would run, the record stays */
  hearth_build_opts_default(&o);
  o.ignore_recorded = 1;
  o.dry_run = 1;
  CHECK_OK(build(root, &o, &rep, &err), &err);
  CHECK(rep.stages_up_to_date < 4 + 2 * rep.instances[0].n_states);
  hearth_build_report_free(&rep);
  CHECK_OK(hb_params_read(path, &q, &err), &err);
  CHECK(q.resolution == 16);

  /* a damaged record stops the build (naming it) and is a problem for validate */
  FILE *f = fopen(path, "w");
  if (f) {
    fputs("{\"resolution\": 0}\n", f);
    fclose(f);
  }
  hearth_build_opts_default(&o);
  err.msg[0] = 0;
  CHECK(build(root, &o, &rep, &err) != HEARTH_OK);
  CHECK_MSG(strstr(err.msg, "build.json"), "%s", err.msg);
  CHECK(problems_naming(root, "build.json") == 1);
  return g_test_failures != 0;
}
