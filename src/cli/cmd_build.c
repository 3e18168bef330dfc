/* hearth build ROOT: the whole pipeline over a release, incrementally. */
#include <stdio.h>
#include <stdlib.h>
#include "cli/cli.h"
#include "hearth/release.h"

static const char *k_about =
    "Runs every stage of a release: detection and calibration once (when\n"
    "calibration/captures/ exists), then for every instance: recon (only when its\n"
    "recon/ is missing: `hearth recon`'s turntable poses, mesh and atlas, and the\n"
    "colour texture baked into recon/; a recon/ of another tool is never touched),\n"
    "scale (metric mesh and\n"
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
    "The parameters that shape the outputs (resolution, fusion, min-cos, colour\n"
    "texture, baking, overlays) are recorded in ROOT/build.json; a later build\n"
    "without those options reuses them, so a build after `hearth demo` runs no stage.\n";

static const char *k_tail =
    "A progress bar is drawn on a terminal, plain lines otherwise; the summary lists\n"
    "failures with their reasons. Exit status 1 if any instance failed.\n";

int hearth_cmd_build(int argc, char **argv) {
  hearth_build_opts o;
  hearth_build_opts_default(&o);
  int fusion = (int)o.fusion;
  const cli_opt opts[] = {
      CLI_INT(
          "--jobs", "N", &o.jobs, 1, 4096,
          "stages run at once (of different instances or states); the cores are shared among the jobs",
          .alias = "-j", .def = "all cores, at most one per instance"),
      CLI_INT("--threads", "N", &o.threads, 1, 4096, "total worker threads",
              .def = "HEARTH_THREADS or all cores"),
      CLI_SHARD(
          "--shard", "I/N", &o.shard_index, &o.shard_count,
          "build only instances I, I+N, I+2N, ... of release.json (I from 0 to N-1), "
          "e.g. a Slurm array: --shard $SLURM_ARRAY_TASK_ID/N; each shard re-checks calibration "
          "(identical results, atomic)"),
      CLI_STR("--instance", "ID", &o.only_instance, "only this instance"),
      CLI_SIZE("--resolution", "R", &o.resolution, 2, 16384, "temperature-map size R x R",
               .def = "as recorded in build.json, else 1024"),
      CLI_CHOICE("--fusion", &fusion, cli_fusion_names, cli_fusion_values,
                 "fusion across views, as `hearth map --fusion`",
                 .def = "as recorded in build.json, else max"),
      CLI_NUM("--min-cos", "C", &o.min_cos, 0, 1, "most oblique view accepted, as a cosine",
              .flags = CLI_HI_OPEN, .def = "as recorded in build.json, else 0"),
      CLI_SIZE("--rgb-resolution", "N", &o.rgb_resolution, 16, 16384, "baked colour texture size",
               .def = "as recorded in build.json, else 1024"),
      CLI_FLAG("--bake", &o.bake_rgb, 1, "bake the colour texture from the colour views",
               .def = "as recorded in build.json, else on"),
      CLI_FLAG("--no-bake", &o.bake_rgb, 0, "keep the reconstruction's colour texture (no baking)"),
      CLI_FLAG("--overlays", &o.calib_overlays, 1, "calibration detection overlays",
               .def = "as recorded in build.json, else on"),
      CLI_FLAG("--no-overlays", &o.calib_overlays, 0, "no calibration detection overlays"),
      CLI_FLAG("--defaults", &o.ignore_recorded, 1,
               "ignore the parameters recorded in build.json: unset ones take the defaults"),
      CLI_FLAG("--force", &o.force, 1, "redo every stage"),
      CLI_FLAG("--dry-run", &o.dry_run, 1, "say what would run, run nothing"),
      CLI_FLAG("--quiet", &o.quiet, 1, "summary only"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth build",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts,
                           .tail = k_tail};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *root = args.v[0];
  o.fusion = (hearth_fusion)fusion;
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
