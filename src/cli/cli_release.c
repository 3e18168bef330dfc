/* Iterating the instances and states of a release for pipeline commands. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "hearth/dataset.h"

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
  /* read (and its id checked against the directory) even for one named
   * state: an instance.json describing another instance is refused */
  hearth_instance_doc doc;
  hearth_status s = hearth_instance_load(root, instance, &doc, err);
  if (s) return s;
  if (only) {
    snprintf(out->names[0], sizeof out->names[0], "%s", only);
    out->n = 1;
    return HEARTH_OK;
  }
  for (size_t i = 0; i < doc.n_states && out->n < CLI_MAX_NAMES; i++)
    snprintf(out->names[out->n++], sizeof out->names[0], "%s", doc.states[i]);
  return HEARTH_OK;
}

int cli_each_instance(const char *cmd, const char *root, const char *only, cli_instance_fn fn,
                      void *ctx) {
  hearth_err err = {0};
  cli_names *inst = malloc(sizeof *inst);
  if (!inst) {
    fprintf(stderr, "hearth %s: out of memory\n", cmd);
    return 1;
  }
  int rc = 0;
  if (cli_instances(root, only, inst, &err)) {
    rc = cli_fail(cmd, &err);
  } else {
    for (size_t k = 0; k < inst->n; k++)
      if (fn(ctx, inst->names[k], &err)) rc = cli_fail(cmd, &err);
  }
  free(inst);
  return rc;
}

typedef struct each_state_ctx {
  const char *cmd, *root, *only_state;
  cli_state_fn fn;
  void *ctx;
  cli_names *states;
} each_state_ctx;

static hearth_status each_state_of(void *vctx, const char *instance, hearth_err *err) {
  each_state_ctx *c = vctx;
  hearth_status s = cli_states(c->root, instance, c->only_state, c->states, err);
  if (s) return s;
  /* report every state's failure, return the instance's last */
  hearth_status last = HEARTH_OK;
  for (size_t j = 0; j < c->states->n; j++) {
    hearth_status sj = c->fn(c->ctx, instance, c->states->names[j], err);
    if (sj) {
      if (j + 1 < c->states->n) cli_fail(c->cmd, err);
      last = sj;
    }
  }
  return last;
}

int cli_each_state(const char *cmd, const char *root, const char *only_instance,
                   const char *only_state, cli_state_fn fn, void *ctx) {
  each_state_ctx c = {cmd, root, only_state, fn, ctx, malloc(sizeof(cli_names))};
  if (!c.states) {
    fprintf(stderr, "hearth %s: out of memory\n", cmd);
    return 1;
  }
  int rc = cli_each_instance(cmd, root, only_instance, each_state_of, &c);
  free(c.states);
  return rc;
}
