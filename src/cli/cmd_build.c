/* hearth build ROOT: the whole pipeline over a release, incrementally. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/release.h"

static const char *k_help =
    "usage: hearth build ROOT [-j N] [--shard I/N] [options]\n"
    "\n"
    "Runs every stage of a release: detection and calibration once (when\n"
    "calibration/captures/ exists), then for every instance: scale (metric mesh and\n"
    "poses from depth), transfer (thermal poses through the rig), refine (automatic\n"
    "thermal-pose refinement, when built in), bake (colour texture), and per state\n"
    "map (temperature maps, mask, Turbo texture, provenance) and overlay (before/\n"
    "after outlines, when built in).\n"
    "\n"
    "Incremental: each finished stage leaves a stamp under derived/.stamps/ (release\n"
    "stages: calibration/.stamps/) with a hash of its parameters and of its inputs'\n"
    "sizes and modification times; a stage is redone only when that changes or an\n"
    "output is missing. Outputs are written atomically and stamped last, so an\n"
    "interrupted run simply resumes. Output bytes do not depend on -j.\n"
    "\n"
    "  -j, --jobs N        instances built in parallel (default: all cores, at most one\n"
    "                      per instance); the cores are shared among the jobs\n"
    "  --threads N         total worker threads (default: HEARTH_THREADS or all cores)\n"
    "  --shard I/N         build only instances I, I+N, I+2N, ... of release.json\n"
    "                      (0 <= I < N), e.g. a Slurm array: --shard $SLURM_ARRAY_TASK_ID/N;\n"
    "                      each shard re-checks calibration (identical results, atomic)\n"
    "  --instance ID       only this instance\n"
    "  --resolution R      temperature-map size R x R (default 1024)\n"
    "  --fusion F          max (default) | robust\n"
    "  --min-cos C         most oblique view accepted, as a cosine (default 0)\n"
    "  --rgb-resolution N  baked colour texture size (default 1024)\n"
    "  --no-bake           keep the reconstruction's colour texture (no baking)\n"
    "  --no-overlays       no calibration detection overlays\n"
    "  --force             redo every stage\n"
    "  --dry-run           say what would run, run nothing\n"
    "  --quiet             summary only\n"
    "\n"
    "A progress bar is drawn on a terminal, plain lines otherwise; the summary lists\n"
    "failures with their reasons. Exit status 1 if any instance failed.\n";

int hearth_cmd_build(int argc, char **argv) {
  const char *root = NULL;
  hearth_build_opts o;
  hearth_build_opts_default(&o);
  for (int i = 1; i < argc; i++) {
    const char *v = NULL;
    int r;
    long n;
    double x;
    if (cli_is_help(argv[i])) {
      fputs(k_help, stdout);
      return 0;
    } else if ((r = cli_opt(argc, argv, &i, "-j", &v)) || (r = cli_opt(argc, argv, &i, "--jobs", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 4096, &n)) goto bad;
      o.jobs = (int)n;
    } else if (!strncmp(argv[i], "-j", 2) && argv[i][2]) {
      v = argv[i] + 2;
      if (!cli_parse_int(v, 1, 4096, &n)) goto bad;
      o.jobs = (int)n;
    } else if ((r = cli_opt(argc, argv, &i, "--threads", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 1, 4096, &n)) goto bad;
      o.threads = (int)n;
    } else if ((r = cli_opt(argc, argv, &i, "--shard", &v))) {
      if (r < 0) goto missing;
      int a, b;
      char tail;
      if (sscanf(v, "%d/%d%c", &a, &b, &tail) != 2 || b < 1 || a < 0 || a >= b) goto bad;
      o.shard_index = a;
      o.shard_count = b;
    } else if ((r = cli_opt(argc, argv, &i, "--instance", &v))) {
      if (r < 0) goto missing;
      o.only_instance = v;
    } else if ((r = cli_opt(argc, argv, &i, "--resolution", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 2, 16384, &n)) goto bad;
      o.resolution = (size_t)n;
    } else if ((r = cli_opt(argc, argv, &i, "--rgb-resolution", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_int(v, 16, 16384, &n)) goto bad;
      o.rgb_resolution = (size_t)n;
    } else if ((r = cli_opt(argc, argv, &i, "--fusion", &v))) {
      if (r < 0) goto missing;
      if (!strcmp(v, "max")) o.fusion = HEARTH_FUSE_MAX;
      else if (!strcmp(v, "robust")) o.fusion = HEARTH_FUSE_ROBUST;
      else goto bad;
    } else if ((r = cli_opt(argc, argv, &i, "--min-cos", &v))) {
      if (r < 0) goto missing;
      if (!cli_parse_num(v, &x) || x < 0 || x >= 1) goto bad;
      o.min_cos = x;
    } else if (!strcmp(argv[i], "--no-bake")) {
      o.bake_rgb = 0;
    } else if (!strcmp(argv[i], "--no-overlays")) {
      o.calib_overlays = 0;
    } else if (!strcmp(argv[i], "--force")) {
      o.force = 1;
    } else if (!strcmp(argv[i], "--dry-run")) {
      o.dry_run = 1;
    } else if (!strcmp(argv[i], "--quiet")) {
      o.quiet = 1;
    } else if (argv[i][0] == '-') {
      fprintf(stderr, "hearth build: unknown option '%s'\n%s", argv[i], k_help);
      return 2;
    } else if (!root) {
      root = argv[i];
    } else {
      fprintf(stderr, "hearth build: unexpected argument '%s'\n", argv[i]);
      return 2;
    }
    continue;
  missing:
    fprintf(stderr, "hearth build: option '%s' needs a value\n", argv[i]);
    return 2;
  bad:
    fprintf(stderr, "hearth build: bad value '%s' for option '%s'\n", v ? v : "",
            argv[i - (argv[i][0] != '-')]);
    return 2;
  }
  if (!root) {
    fprintf(stderr, "hearth build: missing ROOT\n%s", k_help);
    return 2;
  }
  hearth_build_report rep;
  hearth_err err = {0};
  hearth_status s = hearth_build_release(root, &o, &rep, &err);
  if (s && !rep.release_failed) return cli_fail("build", &err);
  hearth_build_report_print(&rep, stdout);
  int failed = rep.release_failed;
  for (size_t i = 0; i < rep.n_instances; i++) failed |= rep.instances[i].failed;
  hearth_build_report_free(&rep);
  return failed ? 1 : 0;
}
