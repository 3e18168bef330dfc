/* Small helpers shared by the commands: failure messages and the choices
 * that several commands offer. */
#include <stdio.h>
#include "cli/cli.h"
#include "hearth/map.h"

const char *const cli_fusion_names[] = {"max", "robust", "corrected", NULL};
const int cli_fusion_values[] = {HEARTH_FUSE_MAX, HEARTH_FUSE_ROBUST, HEARTH_FUSE_CORRECTED};

int cli_fail(const char *cmd, const hearth_err *err) {
  fprintf(stderr, "hearth %s: %s (%s)\n", cmd,
          err->msg[0] ? err->msg : hearth_strerror(err->status), hearth_status_name(err->status));
  return 1;
}
