/* hearth demo [DIR]: make a small virtual release, build it, validate it and
 * write a static HTML report. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "cli/cli.h"
#include "hearth/dataset.h"
#include "hearth/release.h"
#include "hearth/synth.h"

static const char *k_about =
    "The main job end to end on the virtual capture rig, in DIR (default out/demo):\n"
    "  1. DIR/release: a small release (cup hot, canned_drink iced, smartphone warm,\n"
    "     each also neutral) with calibration captures and ground truth, and no\n"
    "     reconstruction (hearth synth --recon none);\n"
    "  2. hearth build: detection, calibration, hearth's own reconstruction (turntable\n"
    "     poses, mesh from depth, UV atlas, colour texture), scale, transfer,\n"
    "     refinement, colour baking, temperature maps and overlays;\n"
    "  3. hearth validate against docs/dataset.md;\n"
    "  4. DIR/report/index.html: a static page (open it in any browser) with, per\n"
    "     state, the Turbo thermal texture beside the colour texture, the ground truth,\n"
    "     the error map, a contact picture of the mesh, the before/after overlays and\n"
    "     the error statistics (against the truth through surface correspondence).\n"
    "Re-running reuses DIR/release and rebuilds only what is stale.\n";

int hearth_cmd_demo(int argc, char **argv) {
  /* the paper's 30 views: with fewer, the turntable route's poses of a
     smooth body of revolution (the can) drift apart and its fused mesh
     breaks up */
  int threads = 0, quiet = 0, views = 30;
  size_t R = 256;
  const cli_opt opts[] = {
      CLI_INT("--threads", "N", &threads, 1, 1024, "worker threads",
              .def = "HEARTH_THREADS or all cores"),
      CLI_INT("--views", "N", &views, 1, 30, "views per state, of the 3 x 10 turntable grid"),
      CLI_SIZE("--resolution", "R", &R, 16, 4096, "temperature-map size"),
      CLI_FLAG("--quiet", &quiet, 1, "only the final summary"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth demo",
                           .args = "DIR",
                           .min_args = 0,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *dir = args.n ? args.v[0] : "out/demo";
  double t0 = hearth_now();
  char root[4096], report_dir[4096], path[4096];
  snprintf(root, sizeof root, "%s/release", dir);
  snprintf(report_dir, sizeof report_dir, "%s/report", dir);
  snprintf(path, sizeof path, "%s/release.json", root);
  hearth_err err = {0};
  if (hearth_mkdirs(dir, &err)) return cli_fail("demo", &err);

  /* 1. the release (kept between runs) */
  if (!hearth_path_exists(path)) {
    if (!quiet) printf("demo: 1/4 making a virtual release in %s\n", root);
    fflush(stdout);
    hearth_synth_opts so;
    hearth_synth_opts_default(&so);
    so.out_root = root;
    so.seed = 1; /* every object of it reconstructs on the turntable route */
    so.n_categories = 3;
    so.categories[0] = "cup";
    so.categories[1] = "canned_drink";
    so.categories[2] = "smartphone";
    /* each category's defaults: cup neutral+hot, can neutral+iced, phone neutral+warm */
    so.n_states = 0;
    so.n_views = views;
    so.triangles = 6000;
    so.texture_size = 512;
    so.map_resolution = R;
    so.n_thermal_frames = 12;
    so.n_stereo_pairs = 10;
    so.threads = threads;
    so.quiet = quiet;
    so.no_recon = 1; /* the build reconstructs: hearth's own recon/ */
    if (hearth_synth_release(&so, &err)) return cli_fail("demo", &err);
  } else if (!quiet) {
    printf("demo: 1/4 reusing the release in %s\n", root);
  }

  /* 2. build */
  if (!quiet) printf("demo: 2/4 building (hearth build %s)\n", root);
  fflush(stdout);
  hearth_build_opts bo;
  hearth_build_opts_default(&bo);
  bo.calib_overlays = 0;
  bo.threads = threads;
  bo.resolution = R;
  bo.rgb_resolution = 512;
  /* the rig's effects are on: the fusion that corrects for them
     (docs/virtual-rig.md, "Which fusion") */
  bo.fusion = HEARTH_FUSE_CORRECTED;
  bo.quiet = quiet;
  hearth_build_report br;
  hearth_status s = hearth_build_release(root, &bo, &br, &err);
  if (s && !br.release_failed) return cli_fail("demo", &err);
  hearth_build_report_print(&br, stdout);
  int build_failed = br.release_failed;
  for (size_t i = 0; i < br.n_instances; i++) build_failed |= br.instances[i].failed;
  hearth_build_report_free(&br);
  if (build_failed) {
    fprintf(stderr, "hearth demo: the build failed (see above)\n");
    return 1;
  }

  /* 3. validate */
  if (!quiet) printf("demo: 3/4 validating\n");
  hearth_problems pr = {0};
  size_t nfiles = 0;
  hearth_validate_opts vo;
  hearth_validate_opts_default(&vo);
  vo.threads = threads;
  if (hearth_validate_release(root, &vo, &pr, &nfiles, &err)) return cli_fail("demo", &err);
  size_t cap = 256 + pr.n * 600;
  char *vtext = malloc(cap);
  if (!vtext) {
    hearth_problems_free(&pr);
    return 1;
  }
  size_t off =
      (size_t)snprintf(vtext, cap, "hearth validate: %zu file(s) checked, %zu problem(s)\n", nfiles,
                       pr.n);
  for (size_t i = 0; i < pr.n && off < cap; i++) {
    off += (size_t)snprintf(vtext + off, cap - off, "%s: %s\n", pr.items[i].path, pr.items[i].what);
    fprintf(stderr, "%s: %s\n", pr.items[i].path, pr.items[i].what);
  }
  size_t n_problems = pr.n;
  hearth_problems_free(&pr);

  /* 4. report */
  if (!quiet) printf("demo: 4/4 writing the report\n");
  hearth_report rep;
  s = hearth_report_write(root, report_dir, "hearth demo: virtual rig release", vtext, &rep, &err);
  free(vtext);
  if (s) return cli_fail("demo", &err);
  hearth_release_stats st;
  if (!quiet && !hearth_release_stats_compute(root, &st, &err)) {
    printf("\n");
    hearth_release_stats_print(&st, stdout);
  }
  printf("\n%-18s %-8s %9s %12s %10s %12s %10s %10s %12s %10s\n", "instance", "state", "observed",
         "median|err|", "p95|err|", "med|app|<60", "p95|app|", "corr<60", "med|err|<60",
         "p95|err|");
  for (size_t i = 0; i < rep.n; i++) {
    const hearth_report_entry *e = &rep.entries[i];
    printf("%-18s %-8s %8.1f%% %10.2f C %8.2f C", e->instance, e->state, 100.0 * e->coverage,
           e->median_abs_c, e->p95_abs_c);
    if (e->has_apparent) printf(" %10.2f C %8.2f C", e->app_median_abs_c, e->app_p95_abs_c);
    else printf(" %12s %10s", "", "");
    if (e->has_corr)
      printf(" %9.1f%% %10.2f C %8.2f C", 100.0 * e->corr_share, e->corr_median_abs_c,
             e->corr_p95_abs_c);
    printf("\n");
  }
  hearth_report_free(&rep);
  printf(
      "\ndemo: done in %.0f s. validate: %zu problem(s) in %zu file(s).\n"
      "  release: %s\n  report:  %s/index.html  (open it in a browser; no server needed)\n",
      hearth_now() - t0, n_problems, nfiles, root, report_dir);
  return n_problems ? 1 : 0;
}
