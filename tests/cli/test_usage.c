/* Usage errors of every pipeline command: no ROOT, an unknown option and a
 * second positional argument each exit 2 with a message naming the command
 * and the offending word; --help exits 0 with a usage line. */
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include "test_util.h"

static int run(const char *cmd, char *out, size_t outsz) {
  FILE *p = popen(cmd, "r");
  if (!p) return -1;
  size_t n = fread(out, 1, outsz - 1, p);
  out[n] = 0;
  int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int main(void) {
  const char *cmds[] = {"map", "overlay", "scale", "refine", "transfer", "detect", "calibrate",
                        "build", "validate", "stats"};
  char cmd[1024], out[8192], want[256];
  for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
    const char *c = cmds[i];
    snprintf(cmd, sizeof cmd, "'%s' %s 2>&1", HEARTH_EXE, c);
    CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s without ROOT", c);
    snprintf(want, sizeof want, "hearth %s:", c);
    CHECK_MSG(strstr(out, want) && strstr(out, "ROOT"), "%s: %s", c, out);

    snprintf(cmd, sizeof cmd, "'%s' %s --no-such-option 2>&1", HEARTH_EXE, c);
    CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s --no-such-option", c);
    CHECK_MSG(strstr(out, "--no-such-option"), "%s: %s", c, out);

    snprintf(cmd, sizeof cmd, "'%s' %s /nonexistent/a /nonexistent/b 2>&1", HEARTH_EXE, c);
    CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s with two roots", c);
    CHECK_MSG(strstr(out, "/nonexistent/b"), "%s: %s", c, out);

    snprintf(cmd, sizeof cmd, "'%s' %s --help 2>&1", HEARTH_EXE, c);
    CHECK_MSG(run(cmd, out, sizeof out) == 0, "%s --help", c);
    snprintf(want, sizeof want, "usage: hearth %s", c);
    CHECK_MSG(strstr(out, want), "%s --help: %s", c, out);
  }
  /* a bad value names its option in both spellings, --opt=value and --opt value */
  const char *bad[][2] = {{"detect", "--upsample"}, {"calibrate", "--max-iterations"}};
  for (int k = 0; k < 2; k++)
    for (int joined = 0; joined < 2; joined++) {
      snprintf(cmd, sizeof cmd, "'%s' %s /nonexistent %s%s0 2>&1", HEARTH_EXE, bad[k][0], bad[k][1],
               joined ? "=" : " ");
      CHECK_MSG(run(cmd, out, sizeof out) == 2, "%s", cmd);
      snprintf(want, sizeof want, "bad value '0' for %s\n", bad[k][1]);
      CHECK_MSG(strstr(out, want), "%s: %s", cmd, out);
    }
  TEST_MAIN_END();
}
