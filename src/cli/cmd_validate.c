/* hearth validate ROOT: every problem of a release, one line each. */
#include <stdio.h>
#include "cli/cli.h"
#include "hearth/release.h"

static const char *k_about =
    "Checks a release against the layout contract (docs/dataset.md) and lists every\n"
    "problem as `PATH: problem`: release.json and its instances, instance.json, each\n"
    "state's manifest and the files it lists (JPEG 1920x1080 RGB, cut-out PNG\n"
    "1920x1080, depth PNG 640x576 16-bit with its intrinsics, thermal CSV of the\n"
    "thermal camera's size in rig.json (the paper's: 256x192)\n"
    "within -50..650 degC), recon/report.json when present (hearth recon's members\n"
    "and types, its views, states, mesh and chart counts against the manifests,\n"
    "recon/poses_rgb.json and the meshes), the calibration documents and captures, and derived/:\n"
    "scale.json, mesh.glb, the pose files (rotations, a pose for every view and\n"
    "none for a view that does not exist), and per state the R x R maps (dtypes,\n"
    "mask values in {0,1,2,3}, observed finite where mask = 1, filled finite where\n"
    "mask is 1 or 2), thermal_turbo.png (R x R RGB) and provenance.json (instance,\n"
    "state, source views of that state, resolution).\n";

static const char *k_tail = "Exit status: 0 no problem, 1 problems found, 2 usage error.\n";

int hearth_cmd_validate(int argc, char **argv) {
  int quiet = 0;
  hearth_validate_opts o;
  hearth_validate_opts_default(&o);
  const cli_opt opts[] = {
      CLI_FLAG("--raw-only", &o.raw_only, 1,
               "a capture not yet built: skip calibration/rig.json and derived/"),
      CLI_FLAG("--decode", &o.decode_images, 1,
               "decode every image fully (default: headers and end markers)"),
      CLI_INT("--threads", "N", &o.threads, 1, 1024, "worker threads", .def = "all cores"),
      CLI_FLAG("--quiet", &quiet, 1, "print problems only, no summary line"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth validate",
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
  hearth_problems pr = {0};
  hearth_err err = {0};
  size_t nfiles = 0;
  double t0 = hearth_now();
  if (hearth_validate_release(root, &o, &pr, &nfiles, &err)) {
    hearth_problems_free(&pr);
    return cli_fail("validate", &err);
  }
  for (size_t i = 0; i < pr.n; i++) printf("%s: %s\n", pr.items[i].path, pr.items[i].what);
  if (!quiet)
    fprintf(pr.n ? stderr : stdout, "validate %s: %zu file(s) checked, %zu problem(s) (%.1f s)\n",
            root, nfiles, pr.n, hearth_now() - t0);
  rc = pr.n ? 1 : 0;
  hearth_problems_free(&pr);
  return rc;
}
