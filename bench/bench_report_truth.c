/* The report's figures of a built virtual-rig release, one line per state:
 * texel for texel against the truth (the stand-in's shared UVs, or the truth
 * resampled onto the built layout) and through surface correspondence on
 * texels seen within 60 degrees of the normal (hearth_truth_match_state),
 * with the frame's fit (derived colour poses against the true ones).
 * usage: bench_report_truth ROOT REPORT_DIR */
#include <stdio.h>
#include "hearth/hearth.h"

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: bench_report_truth ROOT REPORT_DIR\n");
    return 2;
  }
  hearth_report rep;
  hearth_err err = {0};
  double t0 = hearth_now();
  if (hearth_report_write(argv[1], argv[2], "bench_report_truth", NULL, &rep, &err)) {
    fprintf(stderr, "bench_report_truth: %s\n", err.msg);
    return 1;
  }
  printf("report in %.1f s\n", hearth_now() - t0);
  printf("%-20s %-8s %5s %9s %9s %9s | %8s %9s %9s %9s %9s %9s %9s\n", "instance", "state", "R",
         "observed", "med|err|", "p95|err|", "corr<60", "med|err|", "p95|err|", "med|app|",
         "p95|app|", "dist med", "dist p95");
  for (size_t i = 0; i < rep.n; i++) {
    const hearth_report_entry *e = &rep.entries[i];
    printf(
        "%-20s %-8s %5zu %8.1f%% %7.3f C %7.3f C | %7.1f%% %7.3f C %7.3f C %7.3f C %7.3f C "
        "%6.2f mm %6.2f mm%s\n",
        e->instance, e->state, e->R, 100 * e->coverage, e->median_abs_c, e->p95_abs_c,
        100 * e->corr_share, e->corr_median_abs_c, e->corr_p95_abs_c, e->corr_app_median_abs_c,
        e->corr_app_p95_abs_c, e->corr_dist_median_mm, e->corr_dist_p95_mm,
        e->same_uvs ? "  (stand-in)" : "");
  }
  hearth_report_free(&rep);
  return 0;
}
