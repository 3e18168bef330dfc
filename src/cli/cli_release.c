/* Iterating the instances and states of a release for pipeline commands. */
#include <stdio.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/release.h"

hearth_status cli_instances(const char *root, const char *only, cli_names *out, hearth_err *err) {
  memset(out, 0, sizeof *out);
  if (only) {
    snprintf(out->names[0], sizeof out->names[0], "%s", only);
    out->n = 1;
    return HEARTH_OK;
  }
  char path[4096];
  snprintf(path, sizeof path, "%s/release.json", root);
  hearth_release_doc doc = {0};
  hearth_status s = hearth_release_read(path, &doc, err);
  if (s) return s;
  for (size_t i = 0; i < doc.n_instances && out->n < CLI_MAX_NAMES; i++)
    snprintf(out->names[out->n++], sizeof out->names[0], "%s", doc.instances[i]);
  hearth_release_free(&doc);
  return HEARTH_OK;
}

hearth_status cli_states(const char *root, const char *instance, const char *only, cli_names *out,
                         hearth_err *err) {
  memset(out, 0, sizeof *out);
  if (only) {
    snprintf(out->names[0], sizeof out->names[0], "%s", only);
    out->n = 1;
    return HEARTH_OK;
  }
  char path[4096];
  snprintf(path, sizeof path, "%s/instances/%s/instance.json", root, instance);
  hearth_instance_doc doc;
  hearth_status s = hearth_instance_read(path, &doc, err);
  if (s) return s;
  for (size_t i = 0; i < doc.n_states && out->n < CLI_MAX_NAMES; i++)
    snprintf(out->names[out->n++], sizeof out->names[0], "%s", doc.states[i]);
  return HEARTH_OK;
}
