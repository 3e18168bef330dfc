/* hearth validate ROOT: every problem of a release, one line each. */
#include <stdio.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/release.h"

static const char *k_help =
    "usage: hearth validate ROOT [--raw-only] [--decode] [--threads N] [--quiet]\n"
    "\n"
    "Checks a release against the layout contract (docs/dataset.md) and lists every\n"
    "problem as `PATH: problem`: release.json and its instances, instance.json, each\n"
    "state's manifest and the files it lists (JPEG 1920x1080 RGB, cut-out PNG\n"
    "1920x1080, depth PNG 640x576 16-bit with its intrinsics, thermal CSV 256x192\n"
    "within -50..650 degC), the calibration documents and captures, and derived/:\n"
    "scale.json, mesh.glb, the pose files (rotations, a pose for every view and\n"
    "none for a view that does not exist), and per state the R x R maps (dtypes,\n"
    "mask values in {0,1,2,3}, observed finite where mask = 1, filled finite where\n"
    "mask is 1 or 2), thermal_turbo.png (R x R RGB) and provenance.json (instance,\n"
    "state, source views of that state, resolution).\n"
    "\n"
    "  --raw-only    a capture not yet built: skip calibration/rig.json and derived/\n"
    "  --decode      decode every image fully (default: headers and end markers)\n"
    "  --threads N   worker threads (default: all cores)\n"
    "  --quiet       print problems only, no summary line\n"
    "\n"
    "Exit status: 0 no problem, 1 problems found, 2 usage error.\n";

int hearth_cmd_validate(int argc, char **argv) {
  const char *root = NULL;
  int quiet = 0;
  hearth_validate_opts o;
  hearth_validate_opts_default(&o);
  for (int i = 1; i < argc; i++) {
    const char *v;
    int r;
    long n;
    if (cli_is_help(argv[i])) {
      fputs(k_help, stdout);
      return 0;
    } else if (!strcmp(argv[i], "--raw-only")) {
      o.raw_only = 1;
    } else if (!strcmp(argv[i], "--decode")) {
      o.decode_images = 1;
    } else if (!strcmp(argv[i], "--quiet")) {
      quiet = 1;
    } else if ((r = cli_opt(argc, argv, &i, "--threads", &v))) {
      if (r < 0 || !cli_parse_int(v, 1, 1024, &n)) {
        fprintf(stderr, "hearth validate: option --threads needs an integer 1..1024\n");
        return 2;
      }
      o.threads = (int)n;
    } else if (argv[i][0] == '-') {
      fprintf(stderr, "hearth validate: unknown option '%s'\n%s", argv[i], k_help);
      return 2;
    } else if (!root) {
      root = argv[i];
    } else {
      fprintf(stderr, "hearth validate: unexpected argument '%s'\n", argv[i]);
      return 2;
    }
  }
  if (!root) {
    fprintf(stderr, "hearth validate: missing ROOT\n%s", k_help);
    return 2;
  }
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
  int rc = pr.n ? 1 : 0;
  hearth_problems_free(&pr);
  return rc;
}
