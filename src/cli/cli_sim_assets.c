/* The asset release the hearth-sim commands use: a given release, or a
 * small virtual-rig release made in a temporary directory. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/cli_sim.h"
#include "hearth/sim.h"
#include "hearth/synth.h"

/* assets: a release root given, or a tiny virtual-rig release in a temp dir */
int sim_cli_assets(const char *release, int gt, char *root, size_t rootsz, char *tmpdir, size_t tsz,
                   int *use_gt, int quiet) {
  tmpdir[0] = 0;
  if (release) {
    snprintf(root, rootsz, "%s", release);
    *use_gt = gt;
    return 0;
  }
  const char *t = getenv("TMPDIR");
  snprintf(tmpdir, tsz, "%s/hearth_sim_assets_XXXXXX", t && *t ? t : "/tmp");
  if (!mkdtemp(tmpdir)) {
    fprintf(stderr, "hearth sim: cannot create a temporary directory %s\n", tmpdir);
    tmpdir[0] = 0;
    return 1;
  }
  snprintf(root, rootsz, "%s/release", tmpdir);
  hearth_synth_opts so;
  hearth_synth_opts_sim_assets(&so);
  so.out_root = root;
  if (!quiet) fprintf(stderr, "hearth sim: making assets with the virtual rig...\n");
  hearth_err err = {0};
  if (hearth_synth_release(&so, &err)) {
    /* nothing half-made is left behind */
    hearth_remove_tree(tmpdir, NULL);
    tmpdir[0] = 0;
    return cli_fail("sim", &err);
  }
  *use_gt = 1;
  return 0;
}

void sim_cli_drop_assets(const char *tmpdir) {
  if (tmpdir[0]) hearth_remove_tree(tmpdir, NULL);
}

int sim_cli_parse_tasks(void *dst, const char *value, char *why, size_t whysz) {
  unsigned bits = 0;
  const char *p = value;
  while (1) {
    const char *q = strchr(p, ',');
    size_t n = q ? (size_t)(q - p) : strlen(p);
    char item[16];
    /* a bad item: the parser's "expected <expect>, found '<value>'" */
    if (n == 0 || n >= sizeof item) return 1;
    memcpy(item, p, n);
    item[n] = 0;
    if (strcasecmp(item, "all") == 0) bits |= SIM_CLI_ALL_TASKS;
    else {
      hearth_sim_task t = hearth_sim_task_parse(item);
      if (!t) return 1;
      bits |= 1u << t;
    }
    if (!q) break;
    p = q + 1;
  }
  *(unsigned *)dst = bits;
  return 0;
}
