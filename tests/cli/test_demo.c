/* hearth demo on a reduced setting: it finishes, validates clean, and its
 * report links only files that exist and reports small errors against the
 * ground truth (the rig's object effects are on: against the apparent
 * temperature a normal-incidence view reads, which is what a thermal
 * camera can recover; 12 views, so that each pass has views enough for
 * the cooling correction). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include "hearth/core.h"
#include "test_util.h"

int main(void) {
  static char out[1 << 17];
  char cmd[4096], p[2048];
  const char *base = test_tmpdir("demo_cli");
  snprintf(cmd, sizeof cmd, "'%s' demo --help", HEARTH_EXE);
  CHECK(test_run_capture(cmd, out, sizeof out) == 0 && strstr(out, "usage: hearth demo"));
  snprintf(cmd, sizeof cmd, "'%s' demo '%s/d' --views 12 --resolution 64 --threads 2 --quiet",
           HEARTH_EXE, base);
  int rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0, "demo: exit %d: %s", rc, out);
  CHECK(strstr(out, "0 problem(s)") != NULL);
  CHECK(strstr(out, "report/index.html") != NULL);
  /* every image the page links exists */
  snprintf(p, sizeof p, "%s/d/report/index.html", base);
  uint8_t *html = NULL;
  size_t n = 0;
  hearth_err err = {0};
  CHECK_OK(hearth_read_file(p, 1 << 24, &html, &n, &err), &err);
  size_t links = 0;
  for (const char *s = html ? (const char *)html : ""; (s = strstr(s, "src=\"")); s += 5) {
    const char *e = strchr(s + 5, '"');
    if (!e) break;
    snprintf(p, sizeof p, "%s/d/report/%.*s", base, (int)(e - s - 5), s + 5);
    CHECK_MSG(hearth_path_exists(p), "linked file missing: %s", p);
    links++;
  }
  /* 6 states x (thermal, colour, truth, error, contact picture, overlay) */
  CHECK_MSG(links == 36, "%zu images linked", links);
  CHECK(html && strstr((char *)html, "cup_01") && strstr((char *)html, "canned_drink_01") &&
        strstr((char *)html, "smartphone_01"));
  free(html);
  /* the demo maps on hearth's own reconstruction: the truth is matched
     through the surface. Rows are "instance state observed% median C p95 C
     median-apparent C p95-apparent C compared% median C p95 C", the
     apparent and last figures on texels seen within 60 degrees. Neutral
     states are within 0.5 degC of the true temperature; the others' median
     against the apparent truth (what a camera can recover) stays under 1
     degC for the cup and the can. The flat phone's turntable poses are off
     by about 3 degrees / 16 mm after the best similarity, which smears its
     warm spots: a loose bound there, to tighten as the turntable route
     improves. */
  size_t rows = 0;
  for (const char *s = out; s && *s; s = strchr(s, '\n'), s = s ? s + 1 : NULL) {
    char inst[64], state[32];
    double obs, med, p95, app, app95, share, cmed, cp95;
    if (sscanf(s, "%63s %31s %lf%% %lf C %lf C %lf C %lf C %lf%% %lf C %lf C", inst, state, &obs,
               &med, &p95, &app, &app95, &share, &cmed, &cp95) != 10)
      continue;
    rows++;
    const double bound = strstr(inst, "smartphone") ? 4.0 : 1.0;
    CHECK_MSG(app < bound, "%s %s: median error against the apparent truth %.2f C", inst, state,
              app);
    CHECK_MSG(share > 60, "%s %s: %.1f %% of observed texels compared", inst, state, share);
    if (!strcmp(state, "neutral"))
      CHECK_MSG(med < 0.5 && cmed < 0.5, "%s neutral: median error %.2f C, %.2f C", inst, med,
                cmed);
  }
  CHECK_MSG(rows == 6, "%zu summary rows", rows);
  /* a second run reuses the release and rebuilds nothing */
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK(rc == 0 && strstr(out, " 0 stage(s) run"));
  /* and so does a plain build of its release: the demo's build parameters
     are kept with it */
  snprintf(cmd, sizeof cmd, "'%s' build '%s/d/release' -j2", HEARTH_EXE, base);
  rc = test_run_capture(cmd, out, sizeof out);
  CHECK_MSG(rc == 0 && strstr(out, " 0 stage(s) run"), "build after demo: exit %d: %s", rc, out);
  TEST_MAIN_END();
}
