/* hearth stats ROOT: the dataset-overview table, as text and/or JSON. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/release.h"

static const char *k_about =
    "Counts what a release holds, like the paper's table \"Object dataset overview\":\n"
    "categories and instances, object states by kind, views per state (elevations x\n"
    "azimuths), RGB-thermal pairs, raw data per view (image sizes), derived assets\n"
    "present (meshes, RGB textures, scales, poses, temperature maps, thermal\n"
    "textures, provenance) and the size on disk.\n";

static const char *const k_formats[] = {"text", "json", NULL};

int hearth_cmd_stats(int argc, char **argv) {
  const char *json_path = NULL;
  int as_json = 0;
  const cli_opt opts[] = {
      CLI_STR("--json", "FILE", &json_path, "also write the table as JSON to FILE (atomically)"),
      CLI_CHOICE("--format", &as_json, k_formats, NULL, "what standard output shows"),
      CLI_END,
  };
  const cli_command cmd = {.name = "hearth stats",
                           .args = "ROOT",
                           .min_args = 1,
                           .max_args = 1,
                           .about = k_about,
                           .opts = opts};
  cli_args args;
  int rc = cli_parse(&cmd, argc, argv, &args);
  if (rc != CLI_RUN) return rc;
  const char *root = args.v[0];
  hearth_release_stats st;
  hearth_err err = {0};
  if (hearth_release_stats_compute(root, &st, &err)) return cli_fail("stats", &err);
  char *js = hearth_release_stats_json(&st);
  if (!js) {
    fprintf(stderr, "hearth stats: out of memory\n");
    return 1;
  }
  rc = 0;
  if (as_json) fputs(js, stdout);
  else hearth_release_stats_print(&st, stdout);
  if (json_path && hearth_write_file_atomic(json_path, js, strlen(js), &err))
    rc = cli_fail("stats", &err);
  free(js);
  return rc;
}
