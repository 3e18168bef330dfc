/* hearth stats ROOT: the dataset-overview table, as text and/or JSON. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/release.h"

static const char *k_help =
    "usage: hearth stats ROOT [--json FILE] [--format text|json]\n"
    "\n"
    "Counts what a release holds, like the paper's table \"Object dataset overview\":\n"
    "categories and instances, object states by kind, views per state (elevations x\n"
    "azimuths), RGB-thermal pairs, raw data per view (image sizes), derived assets\n"
    "present (meshes, RGB textures, scales, poses, temperature maps, thermal\n"
    "textures, provenance) and the size on disk.\n"
    "\n"
    "  --json FILE        also write the table as JSON to FILE (atomically)\n"
    "  --format F         text (default) or json on standard output\n";

int hearth_cmd_stats(int argc, char **argv) {
  const char *root = NULL, *json_path = NULL;
  int as_json = 0;
  for (int i = 1; i < argc; i++) {
    const char *v;
    int r;
    if (cli_is_help(argv[i])) {
      fputs(k_help, stdout);
      return 0;
    } else if ((r = cli_opt(argc, argv, &i, "--json", &v))) {
      if (r < 0) {
        fprintf(stderr, "hearth stats: option --json needs a value\n");
        return 2;
      }
      json_path = v;
    } else if ((r = cli_opt(argc, argv, &i, "--format", &v))) {
      if (r < 0 || (strcmp(v, "text") && strcmp(v, "json"))) {
        fprintf(stderr, "hearth stats: option --format needs text or json\n");
        return 2;
      }
      as_json = !strcmp(v, "json");
    } else if (argv[i][0] == '-') {
      fprintf(stderr, "hearth stats: unknown option '%s'\n%s", argv[i], k_help);
      return 2;
    } else if (!root) {
      root = argv[i];
    } else {
      fprintf(stderr, "hearth stats: unexpected argument '%s'\n", argv[i]);
      return 2;
    }
  }
  if (!root) {
    fprintf(stderr, "hearth stats: missing ROOT\n%s", k_help);
    return 2;
  }
  hearth_release_stats st;
  hearth_err err = {0};
  if (hearth_release_stats_compute(root, &st, &err)) return cli_fail("stats", &err);
  char *js = hearth_release_stats_json(&st);
  if (!js) {
    fprintf(stderr, "hearth stats: out of memory\n");
    return 1;
  }
  int rc = 0;
  if (as_json) fputs(js, stdout);
  else hearth_release_stats_print(&st, stdout);
  if (json_path && hearth_write_file_atomic(json_path, js, strlen(js), &err)) rc = cli_fail("stats", &err);
  free(js);
  return rc;
}
